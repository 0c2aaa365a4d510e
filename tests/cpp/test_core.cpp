// Host tests of the host+device basics: warps and their pdfs, random streams, camera rays,
// light units, ray offsets.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/offset.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "integrator/camera.h"
#include "scene/lights.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// Monte Carlo estimate of the integral of pdf(w) over the sphere, with uniform directions.
template <typename Pdf>
double integrate_over_sphere(Pdf pdf, int n = 400000) {
    Pcg32 rng = Pcg32::for_path(1, 2, 3);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        float p;
        Vec3 w = sample_uniform_sphere(rng.uniform2(), &p);
        sum += pdf(w) / p;
    }
    return sum / n;
}

}  // namespace

TEST(Sampling, CosinePdfIntegratesToOne) {
    EXPECT_NEAR(integrate_over_sphere([](Vec3 w) { return pdf_cosine_hemisphere(w.z); }), 1.0, 0.01);
}

TEST(Sampling, ConePdfIntegratesToOne) {
    const float cos_max = 0.8f;
    double v = integrate_over_sphere(
        [&](Vec3 w) { return w.z >= cos_max ? pdf_uniform_cone(cos_max) : 0.0f; });
    EXPECT_NEAR(v, 1.0, 0.02);
}

TEST(Sampling, CosineSamplesMatchTheirPdf) {
    // histogram of cos(theta) in 10 bins against the exact mass: P(z in [a,b]) = b^2 - a^2
    Pcg32 rng = Pcg32::for_path(7, 0, 0);
    const int n = 200000, bins = 10;
    int hist[bins] = {};
    for (int i = 0; i < n; ++i) {
        float pdf;
        Vec3 w = sample_cosine_hemisphere(rng.uniform2(), &pdf);
        ASSERT_GE(w.z, 0.0f);
        ASSERT_NEAR(pdf, w.z * kInvPi, 1e-5f);
        hist[std::min(bins - 1, int(w.z * bins))]++;
    }
    double chi2 = 0.0;
    for (int b = 0; b < bins; ++b) {
        double lo = double(b) / bins, hi = double(b + 1) / bins;
        double expected = n * (hi * hi - lo * lo);
        chi2 += (hist[b] - expected) * (hist[b] - expected) / expected;
    }
    EXPECT_LT(chi2, 27.9);  // chi-square, 9 dof, p = 0.001
}

TEST(Sampling, TriangleSamplesAreInside) {
    Pcg32 rng = Pcg32::for_path(3, 0, 0);
    for (int i = 0; i < 10000; ++i) {
        Vec2 b = sample_triangle(rng.uniform2());
        ASSERT_GE(b.x, 0.0f);
        ASSERT_GE(b.y, 0.0f);
        ASSERT_LE(b.x + b.y, 1.0f + 1e-6f);
    }
}

TEST(Rng, SameStreamSameNumbers) {
    Rng a = Rng::for_path(5, 9, 11), b = Rng::for_path(5, 9, 11), c = Rng::for_path(5, 9, 12);
    int differ = 0;
    for (int i = 0; i < 100; ++i) {
        float x = a.uniform(), y = b.uniform(), z = c.uniform();
        EXPECT_EQ(x, y);
        EXPECT_GE(x, 0.0f);
        EXPECT_LT(x, 1.0f);
        differ += x != z;
    }
    EXPECT_GT(differ, 95);
}

TEST(Camera, CentreRayLooksDownMinusZ) {
    SceneInput in;
    in.width = 65;
    in.height = 33;
    in.screen[0] = -0.4f; in.screen[1] = 0.4f; in.screen[2] = -0.2f; in.screen[3] = 0.2f;
    HostScene s(in);
    Ray r = camera_ray(s.view().camera, 32.5f, 16.5f);
    EXPECT_NEAR(r.d.z, -1.0f, 1e-6f);
    Ray corner = camera_ray(s.view().camera, 0.0f, 0.0f);  // top left
    EXPECT_LT(corner.d.x, 0.0f);
    EXPECT_GT(corner.d.y, 0.0f);
    EXPECT_NEAR(corner.d.x / -corner.d.z, -0.4f, 1e-5f);
    EXPECT_NEAR(r.tmin, in.clip_start, 1e-6f);
}

TEST(Camera, FilterOffsetsStayInsideTheWidth) {
    SceneInput in;  // filter_width 1.5: Cycles' Blackman-Harris window spans [-1.5, 1.5]
    HostScene s(in);
    const CameraView& c = s.view().camera;
    double mean = 0.0;
    for (int i = 0; i <= 1000; ++i) {
        float x = filter_offset(c, i / 1000.0f);
        EXPECT_GE(x, -1.5f - 1e-5f);
        EXPECT_LE(x, 1.5f + 1e-5f);
        mean += x;
    }
    EXPECT_NEAR(mean / 1001.0, 0.0, 1e-3);
}

TEST(Lights, AreaRadianceIsPowerOverPiArea) {
    SceneInput in;
    LightInput l;
    l.type = "area";
    l.shape = "rectangle";
    l.size_x = 2.0f;
    l.size_y = 0.5f;
    l.power = {kPi, kPi, kPi};
    in.lights.push_back(l);
    HostScene s(in);
    ASSERT_EQ(s.view().num_lights, 1);
    EXPECT_NEAR(s.view().lights[0].radiance.x, 1.0f, 1e-6f);  // pi W over 1 m^2
}

TEST(Lights, PointIrradianceFallsOffWithDistanceSquared) {
    SceneInput in;
    LightInput l;
    l.type = "point";
    l.position = {0, 0, 3};
    l.power = {100, 100, 100};
    in.lights.push_back(l);
    HostScene s(in);
    const SceneView& v = s.view();
    Pcg32 rng = Pcg32::for_path(0, 0, 0);
    LightSample ls = sample_light(v, v.lights[0], vec3(0, 0, 1), rng.uniform2(), 0.0f);
    ASSERT_TRUE(ls.valid);
    EXPECT_TRUE(ls.delta);
    EXPECT_NEAR(ls.le.x, 100.0f / (4.0f * kPi * 4.0f), 1e-5f);  // P / (4 pi d^2)
}

TEST(Lights, SphereLightMatchesPointLightFarAway) {
    // a small sphere light's irradiance at distance d approaches P/(4 pi d^2)
    SceneInput in;
    LightInput l;
    l.type = "point";
    l.position = {0, 0, 10};
    l.radius = 0.1f;
    l.power = {100, 100, 100};
    in.lights.push_back(l);
    HostScene s(in);
    const SceneView& v = s.view();
    Pcg32 rng = Pcg32::for_path(0, 0, 0);
    double e = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        LightSample ls = sample_light(v, v.lights[0], vec3(0, 0, 0), rng.uniform2(), 0.0f);
        ASSERT_TRUE(ls.valid);
        e += ls.le.x * ls.wi.z / ls.pdf_w;
    }
    EXPECT_NEAR(e / n, 100.0 / (4.0 * kPi * 100.0), 1e-3 * 100.0 / (4.0 * kPi * 100.0) * 5);
}

TEST(Offset, LeavesTheSurfaceAtEveryScale) {
    for (float scale : {1e-3f, 1.0f, 1e4f}) {
        Vec3 p = vec3(0.37f, -1.3f, 2.9f) * scale;
        Vec3 n = normalize(vec3(0.2f, 0.3f, 0.9f));
        Vec3 q = offset_ray_origin(p, n, n);
        EXPECT_GT(dot(q - p, n), 0.0f) << scale;
        Vec3 r = offset_ray_origin(p, n, -n);
        EXPECT_LT(dot(r - p, n), 0.0f) << scale;
        EXPECT_LT(length(q - p), 1e-3f * std::max(1.0f, scale)) << scale;
    }
}

TEST(Camera, FilterOffsetsFollowBlackmanHarris) {
    // The inverted-CDF table must reproduce the filter's mass in every bin, tails included
    // (a coarse table once put 3x the true mass beyond 1.2 px, visible at sharp edges).
    SceneInput in;  // filter_width 1.5: window [-1.5, 1.5]
    HostScene s(in);
    const CameraView& c = s.view().camera;
    const int n = 1 << 20, bins = 30;
    const double lo = -1.5, width = 3.0;
    std::vector<double> hist(bins, 0.0);
    for (int k = 0; k < n; ++k) {  // stratified u: the histogram is the table's own mass
        float x = filter_offset(c, (float(k) + 0.5f) / float(n));
        int b = std::min(bins - 1, std::max(0, int((x - lo) / width * bins)));
        hist[b] += 1.0 / n;
    }
    // analytic mass per bin by fine midpoint integration of the window
    const int fine = 20000;
    std::vector<double> mass(bins, 0.0);
    double total = 0.0;
    for (int j = 0; j < fine; ++j) {
        double x = lo + width * (j + 0.5) / fine;
        double f = std::max(0.0f, blackman_harris(float(x), 3.0f));
        mass[std::min(bins - 1, int((x - lo) / width * bins))] += f;
        total += f;
    }
    for (int b = 0; b < bins; ++b) {
        EXPECT_NEAR(hist[b], mass[b] / total, 2e-4) << "bin " << b;
    }
}

// SceneView::material_bits: what the per-hit fast paths of a diffuse-only scene rely on
// (material_at, pt_surface skip the per-material checks when a bit is clear), and the coat's
// own-normal flag the scene sets (a Coat Normal map, or a mapped base under a coat).
TEST(SceneView, MaterialBitsSayWhatTheMaterialsNeed) {
    auto scene_bits = [](const std::vector<MaterialInput>& ms, Material* last = nullptr) {
        SceneInput in;
        in.materials = ms;
        TextureInput t;
        t.width = t.height = 1;
        t.bytes = {128, 128, 255, 255};
        in.textures.push_back(t);
        HostScene s(in);
        if (last) *last = s.view().materials[ms.size() - 1];
        return s.view().material_bits;
    };
    MaterialInput diffuse;
    EXPECT_EQ(scene_bits({diffuse, diffuse}), 0u);
    MaterialInput aniso;
    aniso.type = "conductor";
    aniso.anisotropy = 0.5f;
    EXPECT_EQ(scene_bits({diffuse, aniso}), uint32_t(kSceneFrames));
    MaterialInput textured = diffuse;
    textured.tex_base_color = 0;
    EXPECT_EQ(scene_bits({diffuse, textured}), uint32_t(kSceneResolve));
    MaterialInput mix;
    mix.type = "mix";
    mix.mix_children = {0};
    mix.mix_weights = {1.0f};
    EXPECT_EQ(scene_bits({diffuse, mix}), uint32_t(kSceneResolve));
    MaterialInput coat;
    coat.type = "principled";
    coat.coat_weight = 1.0f;
    Material m;
    EXPECT_EQ(scene_bits({diffuse, coat}, &m), 0u);   // the coat shares the base's normal
    EXPECT_FALSE(m.tex_flags & kCoatNormal);
    coat.tex_normal = 0;                                // mapped base: the coat stays smooth
    EXPECT_EQ(scene_bits({diffuse, coat}, &m), uint32_t(kSceneFrames));
    EXPECT_TRUE(m.tex_flags & kCoatNormal);
    EXPECT_EQ(m.tex_coat_normal, -1);
    coat.tex_normal = -1;
    coat.tex_coat_normal = 0;                           // its own map
    coat.coat_normal_strength = NAN;
    EXPECT_EQ(scene_bits({diffuse, coat}, &m), uint32_t(kSceneFrames));
    EXPECT_EQ(m.tex_coat_normal, 0);
    EXPECT_EQ(m.coat_normal_strength, 1.0f);
    coat.coat_weight = 0.0f;                            // no coat: nothing to shade
    EXPECT_EQ(scene_bits({diffuse, coat}, &m), 0u);
}
