// Soft-falloff light paths (integrator/soft_light_path.h): the bookkeeping of the light path's
// density of its first vertex x1 (p(w) |cos| / |x1 - c|^2 V(c, x1), pick and 1 / (pi r^2)
// included), the y0 -> x1 sample on the disk facing x1 (its cos_light against the disk's
// analytic irradiance) and the visibility tests, with a stand-in for the executor's rays.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "integrator/soft_light_path.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// The stage's rays: every segment blocked, or none; which kinds were asked.
struct FakeRays {
    bool block_shadow = false, block_indirect = false, no_centre_test = false;
    mutable int asked_shadow = 0, asked_indirect = 0;
    bool blocked(const Ray&, bool shadow) const {
        (shadow ? asked_shadow : asked_indirect)++;
        return shadow ? block_shadow : block_indirect;
    }
};

SceneInput scene_with(const LightInput& light) {
    SceneInput in;
    in.materials.push_back(MaterialInput{});
    MeshInput mesh;
    mesh.name = "tri";
    mesh.positions = {-1, -1, -1, 1, -1, 0, 0, 1, 1};
    mesh.indices = {0, 1, 2};
    mesh.material_ids = {0};
    in.meshes.push_back(mesh);
    in.lights.push_back(light);
    return in;
}

LightInput soft_point(float radius) {
    LightInput l;
    l.type = "point";
    l.power = {10, 10, 10};
    l.position = {0.2f, 0.1f, 0.3f};
    l.radius = radius;
    l.soft_falloff = true;
    return l;
}

}  // namespace

TEST(SoftLightPath, LightPathsStartOnSoftLights) {
    HostScene hs(scene_with(soft_point(0.1f)));
    const Light& l = hs.view().lights[0];
    EXPECT_TRUE(light_receiver_dependent(l));
    EXPECT_FLOAT_EQ(l.emit_pick_pdf, 1.0f);  // the only light: picked by power again
    EmissionSample es = sample_soft_emission(l, {0.3f, 0.7f});
    ASSERT_TRUE(es.valid);
    EXPECT_FLOAT_EQ(es.pdf_direct, 1.0f / (kPi * 0.01f));
    EXPECT_FLOAT_EQ(es.pdf_emit, es.pdf_direct * 0.25f * kInvPi);
    EXPECT_EQ(es.p.x, l.position.x);
    // next-event estimation samples D(x) by its cone: the ratio to 1 / (pi r^2) is the cone's
    // area density there, zero for a direction away from the disk
    const Vec3 x = l.position + vec3(0.0f, 0.0f, -2.0f);
    EXPECT_NEAR(direct_pdf_receiver_ratio(l, x, vec3(0, 0, 1), 2.0f, vec3(0, 0, -1)),
                soft_cone_area_pdf(l, x, vec3(0, 0, 1)) * kPi * 0.01f, 1e-6f);
    EXPECT_GT(direct_pdf_receiver_ratio(l, x, vec3(0, 0, 1), 2.0f, vec3(0, 0, -1)), 0.0f);
    EXPECT_EQ(direct_pdf_receiver_ratio(l, x, vec3(0, 0, -1), 2.0f, vec3(0, 0, -1)), 0.0f);
}

TEST(SoftLightPath, FirstVertexDensityAndVisibility) {
    HostScene hs(scene_with(soft_point(0.1f)));
    const SceneView& v = hs.view();
    const Light& l = v.lights[0];
    const Vec3 x = l.position + vec3(0.3f, -0.4f, 1.2f);
    const Vec3 ng = normalize(vec3(0.2f, 0.1f, -1.0f));
    const Vec3 w = normalize(x - l.position);
    const float d2 = length_sq(x - l.position);
    const float expect = 1.0f * (0.25f * kInvPi) / (kPi * 0.01f) * fabsf(dot(w, ng)) / d2;
    FakeRays open;
    EXPECT_NEAR(soft_light_path_pdf_a(v, open, l, x, ng), expect, 1e-6f * expect);
    EXPECT_EQ(open.asked_indirect, 1);  // V(c, x): one ray, of the light pass's kind
    EXPECT_EQ(open.asked_shadow, 0);
    FakeRays wall;
    wall.block_indirect = true;
    EXPECT_EQ(soft_light_path_pdf_a(v, wall, l, x, ng), 0.0f);  // hidden centre: no light path
    wall.no_centre_test = true;  // the negative control (tests only) claims it anyway
    EXPECT_NEAR(soft_light_path_pdf_a(v, wall, l, x, ng), expect, 1e-6f * expect);
}

TEST(SoftLightPath, SpotConeBoundsTheDensity) {
    LightInput s = soft_point(0.1f);
    s.type = "spot";
    s.spot_size = 1.0f;  // the cone's half angle 0.5 rad about local -Z (world -Z here)
    s.spot_blend = 0.2f;
    HostScene hs(scene_with(s));
    const Light& l = hs.view().lights[0];
    FakeRays open;
    const Vec3 c = l.position, ng = vec3(0, 0, 1);
    EXPECT_GT(soft_light_path_pdf_a(hs.view(), open, l, c + vec3(0.1f, 0.0f, -1.0f), ng), 0.0f);
    EXPECT_EQ(soft_light_path_pdf_a(hs.view(), open, l, c + vec3(1.0f, 0.0f, -1.0f), ng), 0.0f);
    EXPECT_FLOAT_EQ(soft_light_dir_pdf(l, vec3(0, 0, -1)), pdf_uniform_cone(l.cos_half_spot));
    Rng rng = Rng::for_path(7, 0, 0);
    for (int k = 0; k < 1000; ++k) {  // every sampled direction lies in the cone it evaluates
        EmissionSample es = sample_soft_emission(l, rng.uniform2());
        ASSERT_TRUE(es.valid);
        EXPECT_FLOAT_EQ(es.pdf_emit, soft_light_dir_pdf(l, es.d) * es.pdf_direct);
    }
}

// For a receiver x1 facing the centre at distance d, y0 uniform on the disk facing it: the mean
// of cos_light cos_x1 (cos_light = cos_y0 d^2 / |y0 - x1|^2) is the disk's irradiance over
// L pi r^2 / d^2, i.e. d^2 / (d^2 + r^2) (the on-axis disk: E = pi L r^2 / (d^2 + r^2)).
TEST(SoftLightPath, FirstHitMatchesDiskIrradiance) {
    for (float d : {0.05f, 0.3f, 2.0f}) {
        HostScene hs(scene_with(soft_point(0.1f)));
        const SceneView& v = hs.view();
        const Light& l = v.lights[0];
        const Vec3 axis = normalize(vec3(0.3f, -0.2f, 0.9f));
        const Vec3 x = l.position + axis * d, ng = -axis;
        FakeRays open;
        Rng rng = Rng::for_path(11, 0, 0);
        const int n = 200000;
        double acc = 0.0, acc2 = 0.0;
        for (int k = 0; k < n; ++k) {
            const SoftFirstHit sf = soft_light_first_hit(v, open, l, x, ng, rng.uniform2());
            ASSERT_TRUE(sf.valid);
            EXPECT_EQ(sf.atten, 1.0f);
            const double c = double(sf.cos_light) * fabs(dot(sf.wi, ng));
            acc += c;
            acc2 += c * c;
        }
        EXPECT_EQ(open.asked_shadow, n);  // y0 -> x1: one shadow ray each
        const double mean = acc / n, se = std::sqrt((acc2 / n - mean * mean) / n);
        const double expect = double(d) * d / (double(d) * d + 0.01);
        EXPECT_NEAR(mean, expect, 5.0 * se + 1e-5) << "d = " << d;
        FakeRays shut;
        shut.block_shadow = true;  // y0 hidden from x1: no path
        EXPECT_FALSE(soft_light_first_hit(v, shut, l, x, ng, {0.5f, 0.5f}).valid);
    }
}

// lt's lines through the ball (sample_soft_line, soft_line_hit_valid): the flux that lands on
// a small patch of a plane at distance d below the light, facing it, over the patch's area is
// the disk's on-axis irradiance pi L r^2 / (d^2 + r^2); every line carries L pi r^2 / p(w).
TEST(SoftLightPath, LinesThroughTheBallGiveTheDiskIrradiance) {
    HostScene hs(scene_with(soft_point(0.1f)));
    const Light& l = hs.view().lights[0];
    const Vec3 c = l.position;
    for (float d : {0.3f, 1.0f}) {
        const float rho = 0.05f * d, area = kPi * rho * rho;
        Rng rng = Rng::for_path(13, 0, 0);
        const int n = 2000000;
        double acc = 0.0, acc2 = 0.0;
        int valid = 0, landed = 0;
        for (int k = 0; k < n; ++k) {
            const Vec2 u_pos = rng.uniform2(), u_dir = rng.uniform2();
            const EmissionSample es = sample_soft_line(l, u_pos, u_dir);
            ASSERT_TRUE(es.valid);
            if (!(es.d.z < 0.0f)) continue;
            const float t = (c.z - d - es.p.z) / es.d.z;
            const Vec3 x = es.p + es.d * t;
            if (!(t > 0.0f) || length_sq(vec3(x.x - c.x, x.y - c.y, 0.0f)) > rho * rho) continue;
            ++landed;
            if (!soft_line_hit_valid(l, es.p, es.d, t)) continue;
            ++valid;
            const double f = double(emission_weight(es).x) / area;
            acc += f;
            acc2 += f * f;
        }
        const double mean = acc / n, se = std::sqrt((acc2 / n - mean * mean) / n);
        const double r2 = double(l.radius) * l.radius;
        const double expect = kPi * double(l.radiance.x) * r2 / (double(d) * d + r2);
        EXPECT_GT(valid, 1000);
        EXPECT_LT(valid, landed);  // some lines' y0 fall outside the disk facing the patch
        EXPECT_NEAR(mean, expect, 5.0 * se + 0.005 * expect) << "d = " << d;
    }
}
