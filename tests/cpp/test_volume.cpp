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
#include "scene/medium_equiangular.h"
#include "test_bsdf_helpers.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;
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

// ---- Equiangular sampling (scene/medium_equiangular.h): the histogram of 400,000 distances
// in 64 bins against the pdf integrated over each bin by the midpoint rule (not the sampler's
// inverse CDF), chi-square with merged sparse bins; the pdf's mass over a finite segment; an
// endless segment's tail beyond the last bin as one more bin. The negative control: the pdf of
// a point 10 % farther from the line and moved along it by a quarter of the range (at most 1)
// must fail. ----
namespace {

struct Chi2_1d {
    double chi2 = 0.0, p_value = 0.0, mass = 0.0;
    int dof = 0;
};

// samples of s in [0, len] (len finite, or kInf: bins on [0, span] and a tail bin)
Chi2_1d equiangular_chi2(const Equiangular& e, const Equiangular& e_pdf, float len, float span,
                         int n = 400000, int bins = 64) {
    std::vector<double> obs(bins + 1, 0.0), expd(bins + 1, 0.0);
    Pcg32 rng = Pcg32::for_path(11, 0, 0);
    for (int k = 0; k < n; ++k) {
        const float s = equiangular_sample(e, rng.uniform());
        const int b = s >= span ? bins : std::min(bins - 1, int(s / span * bins));
        obs[b] += 1.0;
    }
    const int sub = 4000;
    double mass = 0.0;
    for (int b = 0; b < bins; ++b) {
        double acc = 0.0;
        const double w = double(span) / bins;
        for (int j = 0; j < sub; ++j)
            acc += equiangular_pdf(e_pdf, float(w * (b + (j + 0.5) / sub)));
        expd[b] = acc * w / sub;
        mass += expd[b];
    }
    expd[bins] = std::max(0.0, 1.0 - mass);  // the tail (empty for a finite segment)
    Chi2_1d r;
    r.mass = mass;
    double pool_e = 0.0, pool_o = 0.0;
    int cells = 0;
    for (int b = 0; b <= bins; ++b) {
        pool_e += expd[b] * n;
        pool_o += obs[b];
        if (pool_e < 5.0 && b < bins) continue;
        if (pool_e > 0.0) {
            r.chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            ++cells;
        }
        pool_e = pool_o = 0.0;
    }
    r.dof = std::max(1, cells - 1);
    r.p_value = lantern::test::chi2_upper_tail(r.chi2, r.dof);
    return r;
}

}  // namespace

TEST(Medium, EquiangularChiSquareAndMass) {
    struct Case {
        Vec3 x;     // the light point; the ray starts at the origin along +X
        float len;  // the segment (kInf: endless)
        float span; // the histogram's range
    };
    const Case cases[] = {
        {{1.0f, 0.3f, 0.0f}, 3.0f, 3.0f},    // the foot inside the segment, close to the line
        {{1.5f, 0.02f, 0.1f}, 4.0f, 4.0f},   // very close: a sharp peak
        {{-1.0f, 0.5f, 0.0f}, 2.0f, 2.0f},   // behind the start
        {{6.0f, 1.0f, 0.0f}, 2.0f, 2.0f},    // beyond the end
        {{2.0f, 0.4f, 0.0f}, kInf, 40.0f},   // an endless segment
    };
    const Vec3 o = vec3(0.0f), d = vec3(1.0f, 0.0f, 0.0f);
    {  // a sub-interval [0.8, 2.1] of the segment (a spot's cone)
        const Equiangular e = equiangular_setup(o, d, 0.8f, 2.1f, vec3(1.5f, 0.1f, 0.0f));
        ASSERT_TRUE(e.ok);
        const Chi2_1d r = equiangular_chi2(e, e, 3.0f, 3.0f);
        std::printf("equiangular on [0.8, 2.1]: chi2 %.1f dof %d p %.3g mass %.5f\n", r.chi2,
                    r.dof, r.p_value, r.mass);
        EXPECT_GT(r.p_value, 1e-3);
        EXPECT_NEAR(r.mass, 1.0, 1e-3);
        const Equiangular wrong = equiangular_setup(o, d, 0.8f, 2.2f, vec3(1.5f, 0.1f, 0.0f));
        EXPECT_LT(equiangular_chi2(e, wrong, 3.0f, 3.0f).p_value, 1e-6);
    }
    {  // softened by a light's radius 0.1, the point on the line itself
        const Equiangular e = equiangular_setup(o, d, 3.0f, vec3(1.5f, 0.0f, 0.0f), 0.1f);
        ASSERT_TRUE(e.ok);
        const Chi2_1d r = equiangular_chi2(e, e, 3.0f, 3.0f);
        std::printf("equiangular softened by 0.1: chi2 %.1f dof %d p %.3g mass %.5f\n", r.chi2,
                    r.dof, r.p_value, r.mass);
        EXPECT_GT(r.p_value, 1e-3);
        EXPECT_NEAR(r.mass, 1.0, 1e-3);
        const Equiangular wrong = equiangular_setup(o, d, 3.0f, vec3(1.5f, 0.0f, 0.0f), 0.08f);
        EXPECT_LT(equiangular_chi2(e, wrong, 3.0f, 3.0f).p_value, 1e-6);
    }
    for (const Case& c : cases) {
        const Equiangular e = equiangular_setup(o, d, c.len, c.x);
        ASSERT_TRUE(e.ok);
        const Chi2_1d r = equiangular_chi2(e, e, c.len, c.span);
        std::printf("equiangular x (%g %g %g) len %g: chi2 %.1f dof %d p %.3g mass %.5f\n", c.x.x,
                    c.x.y, c.x.z, c.len, r.chi2, r.dof, r.p_value, r.mass);
        EXPECT_GT(r.p_value, 1e-3) << "x " << c.x.x << " " << c.x.y;
        if (c.len < kInf) EXPECT_NEAR(r.mass, 1.0, 1e-3);
        // negative control: the pdf of a point 10 % farther from the line
        const Vec3 x_bad =
            vec3(c.x.x + 0.25f * std::min(c.span, 4.0f), c.x.y * 1.1f, c.x.z * 1.1f);
        const Equiangular wrong = equiangular_setup(o, d, c.len, x_bad);
        const Chi2_1d bad = equiangular_chi2(e, wrong, c.len, c.span);
        EXPECT_LT(bad.p_value, 1e-6) << "control x " << c.x.x << " " << c.x.y;
    }
    // on the line: no sampling (the density is a delta)
    EXPECT_FALSE(equiangular_setup(o, d, 2.0f, vec3(1.0f, 0.0f, 0.0f)).ok);
    EXPECT_FALSE(equiangular_setup(o, d, 0.0f, vec3(1.0f, 1.0f, 0.0f)).ok);
}

// The part of a ray inside a spot's cone, against points along the ray tested one by one:
// 2,000 random rays and cones, 400 points each, inside the interval exactly where inside the
// cone (but within 1e-3 of the interval's ends, float rounding), endless segments too.
TEST(Medium, SpotConeIntervalIsWhereTheConeIs) {
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    auto dir = [&](Vec2 u) {
        const float z = 1.0f - 2.0f * u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        return vec3(r * std::cos(2.0f * kPi * u.y), r * std::sin(2.0f * kPi * u.y), z);
    };
    int mismatches = 0, hits = 0;
    for (int k = 0; k < 2000; ++k) {
        const Vec3 apex = (vec3(rng.uniform(), rng.uniform(), rng.uniform()) - vec3(0.5f)) * 4.0f;
        const Vec3 axis = dir(rng.uniform2()), d = dir(rng.uniform2());
        const Vec3 o = (vec3(rng.uniform(), rng.uniform(), rng.uniform()) - vec3(0.5f)) * 4.0f;
        const float cos_half = std::cos(rng.uniform() * 1.5f);
        const float len = k % 4 == 0 ? kInf : 0.5f + 6.0f * rng.uniform();
        float t0 = 0.0f, t1 = 0.0f;
        const bool any = spot_cone_interval(apex, axis, cos_half, o, d, len, &t0, &t1);
        hits += any;
        const float span = len < kInf ? len : 50.0f;
        for (int j = 0; j < 400; ++j) {
            const float t = span * (j + 0.5f) / 400.0f;
            const Vec3 w = o + d * t - apex;
            const bool inside = dot(w, axis) >= cos_half * length(w);
            const bool in_interval = any && t >= t0 && t <= t1;
            const float edge = any ? std::min(std::fabs(t - t0), std::fabs(t - t1)) : kInf;
            if (inside != in_interval && edge > 1e-3f * std::max(1.0f, t)) ++mismatches;
        }
    }
    std::printf("spot cone intervals: %d of 2000 rays meet their cone, %d points misplaced\n",
                hits, mismatches);
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(hits, 200);
    EXPECT_LT(hits, 1900);
}

// ---- pt end to end ----
namespace {

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
    in.meshes.push_back(box_mesh({-1, -1, -3}, {1, 1, -2}, 0));  // 1 m thick across the view
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
    in.meshes.push_back(box_mesh({-1, -1, -4}, {1, 1, -2}, 0));  // a chord of 2 m
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
    in.meshes.push_back(box_mesh({-5, -5, -1}, {5, 5, 0}, 0, "floor"));
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

// Single scattering from a point light in scattering world fog, against the integral along
// the camera ray: max_depth 2 keeps one scattering (distance and equiangular sampling of the
// next-event distance, combined by MIS), an orthographic camera over a tiny window makes every
// ray the same line (along -Z from the origin), the light 0.25 from it (where distance
// sampling alone is noisy), Henyey-Greenstein g 0.4.
//   L = int_0^inf sigma_s T(s) hg(cos) I exp(-sigma_t r(s)) / r(s)^2 ds, I = P / (4 pi),
// the integral by the midpoint rule on 400,000 points. 16 seeds, +-1 % controls.
TEST(MediumPt, SingleScatteringFromAPointLightIsTheLineIntegral) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(true, 0.001f);
    in.clip_end = 1.0e4f;
    MaterialInput black;
    black.base_color = vec3(0.0f);
    in.materials.push_back(black);
    in.meshes.push_back(box_mesh({40, 40, -1}, {41, 41, 0}, 0, "aside"));  // out of every path's way
    LightInput l;
    l.type = "point";
    l.position = vec3(0.25f, 0.0f, -2.0f);
    l.power = vec3(40.0f, 60.0f, 80.0f);
    l.soft_falloff = false;
    in.lights.push_back(l);
    MediumInput fog;
    fog.name = "fog";
    fog.sigma_s = vec3(0.3f, 0.5f, 0.8f);
    fog.sigma_a = vec3(0.1f, 0.05f, 0.2f);
    fog.g = 0.4f;
    in.media.push_back(fog);
    in.world_medium = 0;
    const double ss[3] = {0.3, 0.5, 0.8}, sa[3] = {0.1, 0.05, 0.2}, P[3] = {40, 60, 80};
    const double g = 0.4;
    double want[3] = {0, 0, 0};
    const int n = 400000;
    const double s_max = 200.0, ds = s_max / n;
    for (int k = 0; k < n; ++k) {
        const double s = (k + 0.5) * ds;  // the point (0, 0, -s)
        const double lx = 0.25, lz = -2.0 + s;  // light minus point
        const double r2 = lx * lx + lz * lz, r = std::sqrt(r2);
        const double cos_t = -lz / r;  // travelled -Z, scattered towards the light
        const double denom = 1.0 + g * g - 2.0 * g * cos_t;
        const double hg = (1.0 - g * g) / (4.0 * M_PI * denom * std::sqrt(denom));
        for (int c = 0; c < 3; ++c) {
            const double st = ss[c] + sa[c];
            want[c] += ss[c] * std::exp(-st * (s + r)) * hg * P[c] / (4.0 * M_PI) / r2 * ds;
        }
    }
    MeanSe m[3];
    for (int k = 0; k < 16; ++k) {
        const Vec3 c = mean_rgb(render(in, 2, 64, 300 + k));
        m[0].add(c.x);
        m[1].add(c.y);
        m[2].add(c.z);
    }
    // Student t quantile for alpha 1e-3 over 3 comparisons, 15 dof
    for (int c = 0; c < 3; ++c) {
        auto r = mean_matches(m[c], want[c], 4.6202);
        std::printf("single scattering channel %d: %s\n", c, r.message());
        EXPECT_TRUE(r) << "channel " << c;
    }
}

// The same with a spot light beside the camera ray, aimed across it (-X from (0.5, 0, -2), a
// cone of 60 degrees, blend 0.3): equiangular sampling over the part of the ray inside the cone
// (spot_cone_interval), the free flight alone elsewhere. The integrand carries Cycles' spot
// attenuation, smoothstep((cos - cos_half) / ((1 - cos_half) blend)), written out here.
TEST(MediumPt, SingleScatteringFromASpotIsTheLineIntegral) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(true, 0.001f);
    in.clip_end = 1.0e4f;
    MaterialInput black;
    black.base_color = vec3(0.0f);
    in.materials.push_back(black);
    in.meshes.push_back(box_mesh({40, 40, -1}, {41, 41, 0}, 0, "aside"));
    LightInput l;
    l.type = "spot";
    // local -Z (the spot's axis) to world -X; local X, Y to world Y, Z; at (0.5, 0, -2)
    const float m[16] = {0, 0, 1, 0.5f, 1, 0, 0, 0, 0, 1, 0, -2.0f, 0, 0, 0, 1};
    std::copy(m, m + 16, l.to_world);
    l.power = vec3(40.0f, 60.0f, 80.0f);
    l.spot_size = float(M_PI / 3.0);
    l.spot_blend = 0.3f;
    l.soft_falloff = false;
    in.lights.push_back(l);
    MediumInput fog;
    fog.name = "fog";
    fog.sigma_s = vec3(0.3f, 0.5f, 0.8f);
    fog.sigma_a = vec3(0.1f, 0.05f, 0.2f);
    fog.g = -0.3f;
    in.media.push_back(fog);
    in.world_medium = 0;
    const double ss[3] = {0.3, 0.5, 0.8}, sa[3] = {0.1, 0.05, 0.2}, P[3] = {40, 60, 80};
    const double g = -0.3, cos_half = std::cos(M_PI / 6.0), smooth = (1.0 - cos_half) * 0.3;
    double want[3] = {0, 0, 0};
    const int n = 400000;
    const double s_max = 6.0, ds = s_max / n;  // the cone meets the ray near s = 2 only
    for (int k = 0; k < n; ++k) {
        const double s = (k + 0.5) * ds;        // the point (0, 0, -s)
        const double lx = 0.5, lz = -2.0 + s;   // light minus point
        const double r2 = lx * lx + lz * lz, r = std::sqrt(r2);
        const double c = lx / r;                // cosine between the spot's axis (-X) and the
                                                // direction from the light to the point
        double atten = 0.0;
        if (c > cos_half) {
            const double t = std::min(1.0, (c - cos_half) / smooth);
            atten = t * t * (3.0 - 2.0 * t);
        }
        const double cos_t = -lz / r;
        const double denom = 1.0 + g * g - 2.0 * g * cos_t;
        const double hg = (1.0 - g * g) / (4.0 * M_PI * denom * std::sqrt(denom));
        for (int ch = 0; ch < 3; ++ch) {
            const double st = ss[ch] + sa[ch];
            want[ch] += ss[ch] * std::exp(-st * (s + r)) * hg * atten * P[ch] / (4.0 * M_PI) /
                        r2 * ds;
        }
    }
    MeanSe mse[3];
    for (int k = 0; k < 16; ++k) {
        const Vec3 c = mean_rgb(render(in, 2, 64, 500 + k));
        mse[0].add(c.x);
        mse[1].add(c.y);
        mse[2].add(c.z);
    }
    for (int ch = 0; ch < 3; ++ch) {  // Student t, alpha 1e-3 over 3 comparisons, 15 dof
        auto r = mean_matches(mse[ch], want[ch], 4.6202);
        std::printf("spot single scattering channel %d: %s\n", ch, r.message());
        EXPECT_TRUE(r) << "channel " << ch;
    }
}

// Bad coefficients through equiangular sampling: an enormous scattering (1e12 / m, taken as
// 1e9 with a warning) and a NaN absorption (taken as 0), in the world and in a box, lit by a
// point light and a spot: every pixel finite, nothing dropped (render() checks), warnings said,
// and the world fog that is a wall leaves the image black but for the box's own light.
TEST(MediumPt, EnormousAndNonFiniteDensitiesGiveAFiniteImage) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    for (bool world : {true, false}) {
        SceneInput in = base_scene(false, 0.5f);
        MaterialInput floor;
        floor.base_color = vec3(0.5f);
        in.materials.push_back(floor);
        in.meshes.push_back(box_mesh({-5, -5, -6}, {5, 5, -5}, 0, "floor"));
        LightInput l;
        l.type = "point";
        l.position = vec3(0.2f, 0.0f, -2.0f);
        l.power = vec3(100.0f);
        l.soft_falloff = false;
        in.lights.push_back(l);
        LightInput sp = l;
        sp.type = "spot";
        sp.position = vec3(0.0f, 0.5f, -1.0f);
        in.lights.push_back(sp);
        MediumInput bad;
        bad.name = "wall";
        bad.sigma_s = vec3(1e12f, 0.5f, 1e12f);
        bad.sigma_a = vec3(std::nanf(""), 0.1f, 0.0f);
        in.media.push_back(bad);
        if (world) {
            in.world_medium = 0;
        } else {
            in.materials.push_back(volume_material(0));
            in.meshes.push_back(box_mesh({-1, -1, -4}, {1, 1, -1.5f}, 1, "cloud"));
        }
        std::vector<std::string> warnings;
        const std::vector<float> img = render(in, 6, 8, 7, "pt", &warnings);
        bool finite = true;
        for (float x : img) finite = finite && std::isfinite(x) && x >= 0.0f;
        EXPECT_TRUE(finite) << (world ? "world" : "box");
        bool said_huge = false, said_bad = false;
        for (const std::string& w : warnings) {
            said_huge = said_huge || w.find("above 1e9") != std::string::npos;
            said_bad = said_bad || w.find("non-finite or negative") != std::string::npos;
        }
        EXPECT_TRUE(said_huge && said_bad) << (world ? "world" : "box");
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
        in.meshes.push_back(inside ? box_mesh({-1, -1, -1}, {1, 1, 1}, 0)
                                   : box_mesh({-1, -1, -4}, {1, 1, -2}, 0));
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

// A scene with an emissive medium: lt, whose light paths cannot start in it and which has no
// camera gather, hands it to pt and says so; bdpt, lvc and cis render it themselves (their
// camera paths gather the emission: bdpt_medium_stages.h; tests/python/test_volume_hetero_bdpt.py
// checks their images against pt's).
TEST(MediumPt, LightTracerHandsEmissiveMediaToPt) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    SceneInput in = base_scene(false, 0.3f);
    in.world_color = vec3(1.0f);
    MediumInput med;
    med.name = "cloud";
    med.sigma_s = vec3(1.0f);
    med.emission = vec3(0.2f);
    in.media.push_back(med);
    in.materials.push_back(volume_material(0));
    in.meshes.push_back(box_mesh({-1, -1, -4}, {1, 1, -2}, 0));
    const std::vector<float> pt = render(in, 16, 2, 5);
    for (const char* integ : {"bdpt", "lvc", "cis", "lt"}) {
        std::vector<std::string> w;
        const std::vector<float> img = render(in, 16, 2, 5, integ, &w);
        bool said = false;
        for (const std::string& x : w) said = said || x.find("rendering with pt") != std::string::npos;
        const bool lt = std::string(integ) == "lt";
        EXPECT_EQ(said, lt) << integ;
        if (lt)
            EXPECT_EQ(img, pt) << integ;
        else  // (control: its own render, not pt's bits)
            EXPECT_NE(img, pt) << integ;
    }
}
