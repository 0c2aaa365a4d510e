// Participating media (docs/volumes.md): the Henyey-Greenstein phase function's sampling
// (chi-square, pdf mass), free-flight sampling's expectations per channel, and pt end to end
// against exact values: an absorbing slab (Beer-Lambert), an emitting absorbing box (the
// emission integral), a point light through absorbing world fog (next-event transmittance),
// and the furnace: a scattering medium of albedo 1 in a white world stays at the world's value.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "backend/cpu/embree_loader.h"
#include "core/rng.h"
#include "integrator/session.h"
#include "scene/medium.h"
#include "test_bsdf_helpers.h"

using namespace lantern;
using lantern::test::chi2_sphere;
using lantern::test::MeanSe;
using lantern::test::mean_matches;

// ---- Henyey-Greenstein ----

TEST(Medium, HenyeyGreensteinChiSquareAndMass) {
    const Vec3 d = normalize(vec3(0.3f, -0.5f, 0.8f));  // a travel direction off the axes
    for (float g : {-0.7f, 0.0f, 0.3f, 0.9f}) {
        bool pdf_ok = true;
        auto r = chi2_sphere(
            [&](Vec2 u, float, Vec3* wi) {
                float pdf = 0.0f;
                *wi = hg_sample(g, d, u, &pdf);
                const float want = hg_phase(g, dot(d, *wi));
                if (std::fabs(pdf - want) > 1e-4f * want + 1e-6f) pdf_ok = false;
                return pdf > 0.0f;
            },
            [&](Vec3 w) { return double(hg_phase(g, dot(d, w))); }, 200000, 7);
        EXPECT_TRUE(pdf_ok) << "g " << g << ": the sample's pdf is not the phase function";
        EXPECT_GT(r.p_value, 1e-3) << "g " << g << ": chi2 " << r.chi2 << " dof " << r.dof;
        lantern::test::expect_pdf_mass(r, "hg g " + std::to_string(g));
        EXPECT_NEAR(r.pdf_mass, 1.0, 1e-3) << "g " << g;
    }
    // negative control: sampling g = 0.3 is told apart from g = 0.35's phase function
    auto bad = chi2_sphere(
        [&](Vec2 u, float, Vec3* wi) {
            float pdf;
            *wi = hg_sample(0.3f, d, u, &pdf);
            return true;
        },
        [&](Vec3 w) { return double(hg_phase(0.35f, dot(d, w))); }, 200000, 7);
    EXPECT_LT(bad.p_value, 1e-3);
}

// ---- Free flights: E[weight | passed] = T(L), E[weight | scattered] = sigma_s / sigma_t (1 - T)
// per channel, whatever the channel probabilities ----
TEST(Medium, FreeFlightExpectationsPerChannel) {
    Medium m{};
    m.sigma_s = vec3(0.3f, 0.9f, 1.6f);
    m.sigma_a = vec3(0.2f, 0.1f, 0.4f);
    m.sigma_t = m.sigma_s + m.sigma_a;
    m.scatters = 1;
    const float len = 1.3f;
    const Vec3 pmf = medium_channel_pmf(vec3(0.2f, 0.5f, 1.0f));
    MeanSe pass[3], scat[3];
    Pcg32 rng = Pcg32::for_path(3, 0, 0);
    for (int k = 0; k < 4000000; ++k) {
        const float uc = rng.uniform(), ud = rng.uniform();
        const MediumStep st = medium_sample_distance(m, len, pmf, uc, ud);
        const float w[3] = {st.weight.x, st.weight.y, st.weight.z};
        for (int c = 0; c < 3; ++c) {
            pass[c].add(st.scattered ? 0.0 : w[c]);
            scat[c].add(st.scattered ? w[c] : 0.0);
        }
    }
    const float st_[3] = {m.sigma_t.x, m.sigma_t.y, m.sigma_t.z};
    const float ss[3] = {m.sigma_s.x, m.sigma_s.y, m.sigma_s.z};
    const double z = lantern::test::z_bonferroni(6);
    for (int c = 0; c < 3; ++c) {
        const double tr = std::exp(-double(st_[c]) * len);
        auto a = mean_matches(pass[c], tr, z);
        auto b = mean_matches(scat[c], ss[c] / st_[c] * (1.0 - tr), z);
        std::printf("channel %d: pass %s; scatter %s\n", c, a.message(), b.message());
        EXPECT_TRUE(a) << "channel " << c;
        EXPECT_TRUE(b) << "channel " << c;
    }
}

// ---- pt end to end ----
namespace {

// An axis-aligned box with outward-facing (counter-clockwise) triangles, material mat.
MeshInput box(Vec3 lo, Vec3 hi, uint32_t mat, const char* name = "box") {
    MeshInput m;
    m.name = name;
    const Vec3 c = (lo + hi) * 0.5f;
    auto quad = [&](Vec3 a, Vec3 b, Vec3 cc, Vec3 d) {
        const uint32_t base = uint32_t(m.positions.size() / 3);
        for (Vec3 p : {a, b, cc, d}) m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
        const Vec3 n = cross(b - a, cc - a), out = (a + cc) * 0.5f - c;
        if (dot(n, out) >= 0.0f) {
            m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        } else {
            m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
        }
        m.material_ids.insert(m.material_ids.end(), {mat, mat});
    };
    const float x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
    quad({x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0});
    quad({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});
    quad({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});
    quad({x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1});
    quad({x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, {x0, y0, z1});
    quad({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});
    return m;
}

MaterialInput volume_material(int medium) {
    MaterialInput m;
    m.name = "volume";
    m.medium = medium;
    m.volume_only = true;
    return m;
}

// A camera at the origin looking down -Z: orthographic over a tiny window (every ray the same
// chord) or perspective.
SceneInput base_scene(bool ortho, float half) {
    SceneInput in;
    in.width = 8;
    in.height = 8;
    in.orthographic = ortho;
    in.screen[0] = -half; in.screen[1] = half; in.screen[2] = -half; in.screen[3] = half;
    in.clip_start = 0.0f;
    return in;
}

std::vector<float> render(const SceneInput& in, int max_depth, int spp, uint64_t seed,
                          const std::string& integ = "pt",
                          std::vector<std::string>* warnings = nullptr) {
    SessionSettings st;
    st.integrator = integ;
    st.spp_per_iteration = spp;
    st.max_depth = max_depth;
    st.seed = seed;
    st.threads = 1;
    Session s(in, st);
    EXPECT_TRUE(s.step());
    EXPECT_EQ(s.stats().nonfinite_dropped, 0);
    if (warnings) *warnings = s.warnings();
    return s.image();
}

Vec3 mean_rgb(const std::vector<float>& img) {
    double c[3] = {0, 0, 0};
    for (size_t i = 0; i < img.size(); ++i) c[i % 3] += img[i];
    const double n = double(img.size() / 3);
    return vec3(float(c[0] / n), float(c[1] / n), float(c[2] / n));
}

}  // namespace

TEST(MediumPt, AbsorbingSlabIsBeerLambert) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(true, 0.1f);
    in.world_color = vec3(1.0f);
    MediumInput med;
    med.name = "slab";
    med.sigma_a = vec3(0.2f, 0.5f, 1.0f);
    in.media.push_back(med);
    in.materials.push_back(volume_material(0));
    in.meshes.push_back(box({-1, -1, -3}, {1, 1, -2}, 0));  // 1 m thick across the view
    const Vec3 got = mean_rgb(render(in, 1, 4, 1));
    const float want[3] = {std::exp(-0.2f), std::exp(-0.5f), std::exp(-1.0f)};
    const float g[3] = {got.x, got.y, got.z};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(g[c], want[c], 1e-4f * want[c]) << "channel " << c;
}

TEST(MediumPt, EmittingAbsorbingBoxIsTheEmissionIntegral) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(true, 0.1f);
    MediumInput med;
    med.name = "glow";
    med.sigma_a = vec3(0.5f, 1.0f, 2.0f);
    med.emission = vec3(1.0f, 2.0f, 3.0f);
    in.media.push_back(med);
    in.materials.push_back(volume_material(0));
    in.meshes.push_back(box({-1, -1, -4}, {1, 1, -2}, 0));  // a chord of 2 m
    const Vec3 got = mean_rgb(render(in, 1, 4, 1));
    const float s[3] = {0.5f, 1.0f, 2.0f}, e[3] = {1.0f, 2.0f, 3.0f}, g[3] = {got.x, got.y, got.z};
    for (int c = 0; c < 3; ++c) {
        const float want = e[c] * (1.0f - std::exp(-2.0f * s[c])) / s[c];
        EXPECT_NEAR(g[c], want, 1e-4f * want) << "channel " << c;
    }
}

// A diffuse floor under a point light, all in absorbing world fog: next-event estimation's
// shadow ray carries exp(-sigma h), the camera ray exp(-sigma d); against the same scene
// without fog (the light's units cancel).
TEST(MediumPt, PointLightThroughWorldFog) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(true, 0.002f);
    in.camera_to_world[3] = 0.0f;
    in.camera_to_world[7] = 0.0f;
    in.camera_to_world[11] = 3.0f;  // at z = 3, looking down at the floor z = 0
    MaterialInput floor;
    floor.base_color = vec3(0.5f);
    in.materials.push_back(floor);
    in.meshes.push_back(box({-5, -5, -1}, {5, 5, 0}, 0, "floor"));
    LightInput l;
    l.type = "point";
    l.position = vec3(0.0f, 0.0f, 2.0f);
    l.power = vec3(100.0f);
    l.soft_falloff = false;
    in.lights.push_back(l);
    const Vec3 clear = mean_rgb(render(in, 2, 2, 1));
    MediumInput fog;
    fog.name = "fog";
    fog.sigma_a = vec3(0.05f, 0.2f, 0.4f);
    in.media.push_back(fog);
    in.world_medium = 0;
    const Vec3 foggy = mean_rgb(render(in, 2, 2, 1));
    const float s[3] = {0.05f, 0.2f, 0.4f}, c[3] = {clear.x, clear.y, clear.z},
                f[3] = {foggy.x, foggy.y, foggy.z};
    ASSERT_GT(c[0], 0.0f);
    for (int k = 0; k < 3; ++k) {
        const float want = c[k] * std::exp(-s[k] * (2.0f + 3.0f));
        EXPECT_NEAR(f[k], want, 2e-4f * want) << "channel " << k;
    }
}

// The furnace: a closed volume boundary holding a chromatic, anisotropic scattering medium of
// albedo 1 in a white world: every pixel stays 1, seen from outside and from inside (the
// camera's medium). 16 seeds of 32 spp on 16 x 16 pixels, their image means against 1 with
// +-1 % controls.
TEST(MediumPt, ScatteringFurnaceStaysAtTheWorld) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    for (bool inside : {false, true}) {
        SceneInput in = base_scene(false, 0.3f);
        in.width = in.height = 16;
        in.world_color = vec3(1.0f);
        MediumInput med;
        med.name = "cloud";
        med.sigma_s = vec3(3.0f, 1.5f, 0.5f);
        med.g = 0.6f;
        in.media.push_back(med);
        in.materials.push_back(volume_material(0));
        in.meshes.push_back(inside ? box({-1, -1, -1}, {1, 1, 1}, 0)
                                   : box({-1, -1, -4}, {1, 1, -2}, 0));
        MeanSe m;
        for (int k = 0; k < 16; ++k) {
            const Vec3 c = mean_rgb(render(in, 256, 32, 100 + k));
            m.add((c.x + c.y + c.z) / 3.0);
        }
        // Student t quantile for alpha 1e-3 over 2 comparisons, 15 dof
        auto r = mean_matches(m, 1.0, 4.4166);
        std::printf("furnace (camera %s): %s\n", inside ? "inside" : "outside", r.message());
        EXPECT_TRUE(r) << (inside ? "inside" : "outside");
    }
}

// Integrators without medium vertices hand a scene with media to pt, and say so.
TEST(MediumPt, OtherIntegratorsHandOverToPt) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(false, 0.3f);
    in.world_color = vec3(1.0f);
    MediumInput med;
    med.name = "cloud";
    med.sigma_s = vec3(1.0f);
    in.media.push_back(med);
    in.materials.push_back(volume_material(0));
    in.meshes.push_back(box({-1, -1, -4}, {1, 1, -2}, 0));
    const std::vector<float> pt = render(in, 16, 2, 5);
    for (const char* integ : {"bdpt", "lvc", "cis", "lt"}) {
        std::vector<std::string> w;
        const std::vector<float> img = render(in, 16, 2, 5, integ, &w);
        bool said = false;
        for (const std::string& x : w) said = said || x.find("rendering with pt") != std::string::npos;
        EXPECT_TRUE(said) << integ;
        EXPECT_EQ(img, pt) << integ;
    }
}
