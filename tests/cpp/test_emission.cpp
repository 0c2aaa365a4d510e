// Emission sampling for light tracing (integrator/light_path.h): for every light type the
// returned pdfs equal emission_pdf() of the same ray, the direction pdf integrates to one, and
// the mean flux le * cos / pdf_emit equals the light's power. Also: connect_camera (lt.h) is
// the inverse of camera.h's camera_ray, and where integrator "lt" refuses soft-falloff lights.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/rng.h"
#include "integrator/light_path.h"
#include "integrator/bdpt.h"
#include "integrator/lt.h"
#include "integrator/session.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// A 2 m box of two triangles (its extent sets the scene radius) plus one light.
SceneInput scene_with(const LightInput* light, Vec3 tri_emission = vec3(0.0f)) {
    SceneInput in;
    MaterialInput m;
    m.emission = tri_emission;
    in.materials.push_back(m);
    MeshInput mesh;
    mesh.name = "tri";
    mesh.positions = {-1, -1, -1, 1, -1, 0, 0, 1, 1};
    mesh.indices = {0, 1, 2};
    mesh.material_ids = {0};
    in.meshes.push_back(mesh);
    if (light) in.lights.push_back(*light);
    return in;
}

struct Case {
    std::string name;
    SceneInput in;
    double power;  // expected mean flux (channel x)
};

double spot_fraction(float size, float blend) {  // integral of the cone over the sphere / 4 pi
    double cos_half = std::cos(0.5 * size), smooth = (1.0 - cos_half) * blend;
    const int n = 200000;
    double acc = 0.0;
    for (int k = 0; k < n; ++k) {
        double c = cos_half + (1.0 - cos_half) * (k + 0.5) / n;
        double t = smooth > 0 ? std::min(1.0, (c - cos_half) / smooth) : 1.0;
        acc += t * t * (3 - 2 * t);
    }
    return 0.5 * acc * (1.0 - cos_half) / n;  // 2 pi / 4 pi
}

std::vector<Case> cases() {
    std::vector<Case> out;
    LightInput l;
    l.power = {10, 10, 10};
    {
        LightInput a = l;
        a.type = "area";
        a.shape = "rectangle";
        a.size_x = 1.0f;
        a.size_y = 0.5f;
        a.to_world[3] = 0.3f;
        out.push_back({"area rectangle", scene_with(&a), 10.0});
        a.shape = "disk";
        out.push_back({"area disk", scene_with(&a), 10.0});
    }
    {
        LightInput p = l;
        p.type = "point";
        p.radius = 0.0f;  // delta position (soft_falloff is moot at radius 0)
        out.push_back({"point", scene_with(&p), 10.0});
        p.radius = 0.2f;
        p.soft_falloff = false;
        out.push_back({"sphere", scene_with(&p), 10.0});
    }
    {
        LightInput s = l;
        s.type = "spot";
        s.spot_size = 1.0f;
        s.spot_blend = 0.5f;
        out.push_back({"spot", scene_with(&s), 10.0 * spot_fraction(1.0f, 0.5f)});
        s.radius = 0.1f;
        s.soft_falloff = false;  // sphere spot: cosine directions, cone in le
        out.push_back({"sphere spot", scene_with(&s), 10.0 * spot_fraction(1.0f, 0.5f)});
    }
    {
        SceneInput in = scene_with(nullptr, vec3(2.0f));
        // |cross((2,0,1),(1,2,2))| = |(-2,-3,4)| = sqrt(29)
        double area = 0.5 * std::sqrt(29.0);
        out.push_back({"emissive triangle", in, 2.0 * area * 2.0 * kPi});
    }
    {
        HostScene probe(scene_with(nullptr));
        double r = probe.view().scene_radius, disk = kPi * r * r;
        LightInput s;
        s.type = "sun";
        s.direction = {0.3f, -0.2f, -1.0f};
        s.strength = {3, 3, 3};
        out.push_back({"sun", scene_with(&s), 3.0 * disk});
        s.angle = 0.5f;
        double c = std::cos(0.25), le = 3.0 / (kPi * (1 - c * c));
        out.push_back({"sun disk", scene_with(&s), le * disk * 2 * kPi * (1 - c)});
        SceneInput w = scene_with(nullptr);
        w.world_color = {0.5f, 0.5f, 0.5f};
        out.push_back({"world", w, 0.5 * disk * 4 * kPi});
    }
    return out;
}

const Light& the_light(const SceneView& v) {
    return v.lights[v.num_lights - 1];  // the only light (a world entry comes last)
}

}  // namespace

TEST(Emission, PdfsMatchEvaluationAndFluxIsPower) {
    for (const Case& c : cases()) {
        HostScene hs(c.in);
        const SceneView& v = hs.view();
        ASSERT_GE(v.num_lights, 1) << c.name;
        const Light& l = the_light(v);
        Pcg32 rng = Pcg32::for_path(11, 0, 0);
        const int n = 400000;
        double flux = 0.0, flux2 = 0.0;
        int checked = 0;
        for (int k = 0; k < n; ++k) {
            Vec2 up = rng.uniform2(), ud = rng.uniform2();
            EmissionSample es = sample_emission(v, l, up, ud, 0.0f);
            double f = 0.0;
            if (es.valid) {
                f = emission_weight(es).x;
                if (k % 97 == 0) {
                    EmissionPdf p = emission_pdf(v, l, es.n, es.d, 0.0f);
                    EXPECT_NEAR(p.pdf_emit / es.pdf_emit, 1.0, 1e-4) << c.name;
                    EXPECT_NEAR(p.pdf_direct / es.pdf_direct, 1.0, 1e-4) << c.name;
                    ++checked;
                }
                EXPECT_EQ(es.delta_pos, l.type <= kLightSpot && l.radius <= 0.0f) << c.name;
                EXPECT_EQ(es.finite, l.type != kLightSun && l.type != kLightWorld) << c.name;
            }
            flux += f;
            flux2 += f * f;
        }
        double mean = flux / n, se = std::sqrt(std::max(0.0, flux2 / n - mean * mean) / n);
        EXPECT_GT(checked, 100) << c.name;
        // within 5 standard errors, which must be small
        EXPECT_LT(se, 0.01 * c.power) << c.name;
        EXPECT_NEAR(mean, c.power, 5.0 * se + 1e-6 * c.power) << c.name;
    }
}

TEST(Emission, DirectionPdfIntegratesToOne) {
    for (const Case& c : cases()) {
        HostScene hs(c.in);
        const SceneView& v = hs.view();
        const Light& l = the_light(v);
        if (l.type == kLightSun && l.cos_sun >= 1.0f) continue;  // delta direction
        Pcg32 rng = Pcg32::for_path(5, 0, 0);
        EmissionSample ref{};
        for (int k = 0; k < 1000 && !ref.valid; ++k)  // a surface normal to evaluate at
            ref = sample_emission(v, l, rng.uniform2(), rng.uniform2(), 0.0f);
        ASSERT_TRUE(ref.valid) << c.name;
        const int n = 400000;
        double acc = 0.0, acc2 = 0.0;
        for (int k = 0; k < n; ++k) {
            Vec3 d = sample_uniform_sphere(rng.uniform2(), nullptr);
            EmissionPdf p = emission_pdf(v, l, ref.n, d, 0.0f);
            // the direction's pdf: pdf_emit over the point's (finite) or the disk's density
            double pdf_dir = ref.finite ? (p.pdf_direct > 0 ? p.pdf_emit / p.pdf_direct : 0.0)
                                        : p.pdf_emit * kPi * v.scene_radius * v.scene_radius;
            acc += pdf_dir * 4.0 * kPi;
            acc2 += sqr(float(pdf_dir * 4.0 * kPi));
        }
        double se = std::sqrt(std::max(0.0, acc2 / n - sqr(float(acc / n))) / n);
        EXPECT_LT(se, 0.02) << c.name;
        EXPECT_NEAR(acc / n, 1.0, 5.0 * se + 1e-4) << c.name;
    }
}

// Soft-falloff lights have no emission sample of their own (soft_light_path.h builds their
// paths); lt traces them unless a triangle lies within their radius (its lines would miss light
// there) or the scene has media. The triangle lies 0.186 m from the origin.
TEST(Emission, SoftFalloffIsRefusedWhereLtCannotTraceIt) {
    LightInput p;
    p.type = "point";
    p.power = {1, 1, 1};
    p.radius = 0.1f;
    p.soft_falloff = true;
    HostScene hs(scene_with(&p));
    EmissionSample es =
        sample_emission(hs.view(), the_light(hs.view()), {0.5f, 0.5f}, {0.5f, 0.5f}, 0.0f);
    EXPECT_FALSE(es.valid);
    EXPECT_NO_THROW(check_light_tracing(scene_with(&p)));
    p.radius = 0.2f;  // the triangle inside the light's ball
    try {
        check_light_tracing(scene_with(&p));
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("scene.lights[0]"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("mesh 'tri'"), std::string::npos) << e.what();
    }
    p.radius = 0.0f;  // a true point: fine
    EXPECT_NO_THROW(check_light_tracing(scene_with(&p)));
}

TEST(Emission, CameraConnectionInvertsCameraRay) {
    for (int ortho = 0; ortho < 2; ++ortho) {
        SceneInput in = scene_with(nullptr);
        in.width = 40;
        in.height = 30;
        in.orthographic = ortho != 0;
        const float rows[16] = {0.8f, 0, 0.6f, 1, 0.6f, 0, -0.8f, -2, 0, 1, 0, 0.5f, 0, 0, 0, 1};
        for (int k = 0; k < 16; ++k) in.camera_to_world[k] = rows[k];
        in.screen[0] = -0.6f, in.screen[1] = 0.4f, in.screen[2] = -0.3f, in.screen[3] = 0.45f;
        HostScene hs(in);
        const CameraView& cam = hs.view().camera;
        Pcg32 rng = Pcg32::for_path(1, 2, 3);
        for (int k = 0; k < 200; ++k) {
            float x = 40.0f * rng.uniform(), y = 30.0f * rng.uniform();
            Ray r = camera_ray(cam, x, y);
            float t = r.tmin + (2.0f + 5.0f * rng.uniform());
            CameraConnection cc = connect_camera(cam, r.o + r.d * t, 1.5f);
            ASSERT_TRUE(cc.valid);
            EXPECT_NEAR(cc.raster_x, x, 2e-3f);
            EXPECT_NEAR(cc.raster_y, y, 2e-3f);
            EXPECT_NEAR(dot(cc.wc, r.d), -1.0f, 1e-5f);
        }
    }
}

// With a thin lens (depth of field): the connection through the same lens point lands on the
// raster position of the camera ray, its direction is the ray's, and its importance is the
// pinhole's about that lens point (camera_pdf's cos^3 law).
TEST(Emission, CameraConnectionThroughTheLensInvertsCameraRay) {
    SceneInput in = scene_with(nullptr);
    in.width = 40;
    in.height = 30;
    const float rows[16] = {0.8f, 0, 0.6f, 1, 0.6f, 0, -0.8f, -2, 0, 1, 0, 0.5f, 0, 0, 0, 1};
    for (int k = 0; k < 16; ++k) in.camera_to_world[k] = rows[k];
    in.lens_radius = 0.3f;
    in.focus_distance = 3.0f;
    for (int blades : {0, 6}) {
        in.aperture_blades = blades;
        in.aperture_ratio = blades ? 2.0f : 1.0f;
        HostScene hs(in);
        const CameraView& cam = hs.view().camera;
        Pcg32 rng = Pcg32::for_path(4, 5, 6);
        for (int k = 0; k < 200; ++k) {
            float x = 40.0f * rng.uniform(), y = 30.0f * rng.uniform();
            Vec2 lens = sample_aperture(cam, rng.uniform2());
            ASSERT_LE(lens.x * lens.x * 4.0f + lens.y * lens.y, 0.3f * 0.3f * 4.0f + 1e-5f);
            Ray r = camera_ray(cam, x, y, lens);
            float t = r.tmin + (0.5f + 6.0f * rng.uniform());
            CameraConnection cc = connect_camera(cam, r.o + r.d * t, 1.5f, lens);
            ASSERT_TRUE(cc.valid);
            EXPECT_NEAR(cc.raster_x, x, 2e-3f);
            EXPECT_NEAR(cc.raster_y, y, 2e-3f);
            EXPECT_NEAR(dot(cc.wc, r.d), -1.0f, 1e-5f);
            float cos_c = -dot(r.d, cam.to_world.axis(2));
            float sw = cam.screen[1] - cam.screen[0], sh = cam.screen[3] - cam.screen[2];
            float a_pix = sw * sh / (40.0f * 30.0f);
            EXPECT_NEAR(cc.importance * a_pix * cos_c * cos_c * cos_c * t * t, 1.0f, 1e-3f);
        }
    }
}

// Panoramic equirectangular: connect_camera inverts camera_ray (inside the range), and its
// importance is bdpt's camera_pdf of the direction over the squared distance.
TEST(Emission, PanoramaConnectionInvertsCameraRay) {
    SceneInput in = scene_with(nullptr);
    in.width = 64;
    in.height = 32;
    in.panoramic = true;
    const float rows[16] = {0.8f, 0, 0.6f, 1, 0.6f, 0, -0.8f, -2, 0, 1, 0, 0.5f, 0, 0, 0, 1};
    for (int k = 0; k < 16; ++k) in.camera_to_world[k] = rows[k];
    for (int partial = 0; partial < 2; ++partial) {
        if (partial) {
            const float r[4] = {-2.0f, 1.0f, -0.7f, 1.2f};
            for (int k = 0; k < 4; ++k) in.pano_range[k] = r[k];
        }
        HostScene hs(in);
        const CameraView& cam = hs.view().camera;
        ASSERT_EQ(cam.panoramic, 1);
        Pcg32 rng = Pcg32::for_path(7, 8, 9);
        for (int k = 0; k < 300; ++k) {
            float x = 1.0f + 62.0f * rng.uniform(), y = 1.0f + 30.0f * rng.uniform();
            Ray r = camera_ray(cam, x, y);
            float t = 0.5f + 5.0f * rng.uniform();
            CameraConnection cc = connect_camera(cam, r.o + r.d * t, 1.5f);
            ASSERT_TRUE(cc.valid);
            EXPECT_NEAR(cc.raster_x, x, 2e-3f);
            EXPECT_NEAR(cc.raster_y, y, 2e-3f);
            EXPECT_NEAR(dot(cc.wc, r.d), -1.0f, 1e-5f);
            EXPECT_NEAR(cc.importance * t * t / camera_pdf(cam, r.d), 1.0f, 1e-3f);
        }
    }
}
