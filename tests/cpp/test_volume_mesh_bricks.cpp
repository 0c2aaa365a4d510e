// Majorant bricks for mesh volumes (volleft; scene/medium_hetero_build.cpp,
// scene/medium_majorant.h): a unit cube whose density program is a thin slab across x
// (peak 30, zero elsewhere) gets 16^3 bricks of interval-bound majorants. Every piece the walk
// hands out along 800 random rays bounds the extinction at 17 points inside it (exact:
// tracking stays unbiased); ratio and spectral tracking through the slab agree with
// Beer-Lambert of its integral (3 % / 6 % controls); the expected tentative collisions of a ray
// across the cube (the majorant's integral) fall against the one majorant; and
// LANTERN_MAJORANT_BRICKS=0 keeps the one majorant.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "core/rng.h"
#include "program_bound_cases.h"
#include "scene/medium_hetero.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;

namespace {

constexpr float kMbC = 0.3f, kMbW = 40.0f, kMbPeak = 30.0f;

// Math op `mode` of registers a, b (copied to a block at `at`, its third operand 0): out at+3
int mb_math(std::vector<uint32_t>& code, int mode, int a, int b, int at) {
    pbc::instr(code, kOpCopy, 0, 0, 1, a, at);
    pbc::instr(code, kOpCopy, 0, 0, 1, b, at + 1);
    pbc::instr(code, kOpCopy, 0, 0, 1, 3, at + 2);
    pbc::instr(code, kOpMath, mode, 0, 0, at, at + 3);
    return at + 3;
}

// density kMbPeak x max(1 - kMbW |x - kMbC|, 0) in the unit cube
SceneInput mb_scene() {
    SceneInput in;
    std::vector<float> c = {kMbC, kMbW, 1.0f, 0.0f, kMbPeak, 0.0f, 0.0f, 0.0f};
    std::vector<uint32_t> code;
    pbc::instr(code, kOpInput, 0, 0, 0, 0, 16);  // position 16..18
    int r = mb_math(code, 1, 16, 0, 30);         // x - c
    r = mb_math(code, 9, r, 3, 34);              // |x - c|
    r = mb_math(code, 2, r, 1, 38);              // w |x - c|
    r = mb_math(code, 1, 2, r, 42);              // 1 - w |x - c|
    r = mb_math(code, 12, r, 3, 46);             // max(., 0)
    r = mb_math(code, 2, r, 4, 50);              // peak x tent
    for (int k = 0; k < 3; ++k) pbc::instr(code, kOpCopy, 0, 0, 1, r, 60 + k);
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()), uint32_t(kTargetDensity),
                   60u};
    MediumInput med;
    med.name = "slab";
    med.sigma_a = vec3(0.15f, 0.3f, 0.5f);
    med.sigma_s = vec3(0.25f, 0.2f, 0.1f);
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "slab";
    mat.medium = 0;
    mat.volume_only = true;
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    in.meshes.push_back(lantern::test::box_mesh(vec3(0.0f), vec3(1.0f), 0));
    return in;
}

// the majorant's integral along o + d t, t in [0, t_end] (the expected tentative collisions)
double mb_majorant_integral(const SceneView& s, const Medium& m, Vec3 o, Vec3 d, float t_end) {
    MajorantWalk w = medium_majorant_walk(s, m, o, d, t_end);
    MajorantSeg seg;
    double sum = 0.0;
    while (majorant_next(w, &seg)) sum += double(seg.mu) * double(seg.t1 - seg.t0);
    return sum;
}

}  // namespace

TEST(VolumeMeshBricks, PiecesBoundTheExtinction) {
    HostScene scene(mb_scene());
    const SceneView& s = scene.view();
    const int32_t mi = s.material_medium[0];
    ASSERT_GE(mi, 0);
    const Medium& m = s.media[mi];
    ASSERT_GE(m.majorant_grid, 0);
    std::mt19937 rng(61);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int pieces = 0, zero = 0, failures = 0;
    for (int ray = 0; ray < 800; ++ray) {
        const Vec3 o{-0.2f + 1.4f * u(rng), -0.2f + 1.4f * u(rng), -0.2f + 1.4f * u(rng)};
        const float ct = 2.0f * u(rng) - 1.0f, ph = 2.0f * kPi * u(rng);
        const float st = std::sqrt(std::max(0.0f, 1.0f - ct * ct));
        const Vec3 d{st * std::cos(ph), st * std::sin(ph), ct};
        MajorantWalk w = medium_majorant_walk(s, m, o, d, 2.0f);
        MajorantSeg seg;
        while (majorant_next(w, &seg)) {
            ++pieces;
            zero += seg.mu == 0.0f;
            for (int k = 0; k <= 16; ++k) {
                const float t = seg.t0 + (seg.t1 - seg.t0) * float(k) / 16.0f;
                const MediumCoeffs c = medium_coeffs_at(s, m, mi, o + d * t, d);
                const float ext = max_component(c.sigma_a + c.sigma_s);
                if (!(ext <= seg.mu * (1.0f + 1e-5f)) && ++failures <= 3)
                    ADD_FAILURE() << "extinction " << ext << " above the piece's majorant "
                                  << seg.mu << " at t " << t;
            }
        }
    }
    // across the cube through the slab: the majorant's integral against the one majorant's
    const Vec3 o{0.0f, 0.43f, 0.61f}, d{1, 0, 0};
    const double bricks = mb_majorant_integral(s, m, o, d, 1.0f);
    Medium one = m;
    one.majorant_grid = -1;
    const double single = mb_majorant_integral(s, one, o, d, 1.0f);
    std::printf(
        "%d pieces (%d of majorant 0); expected tentative collisions across the cube "
        "%.2f with bricks, %.2f with one majorant\n",
        pieces, zero, bricks, single);
    EXPECT_GT(zero, pieces / 4);  // the bricks away from the slab are empty
    EXPECT_LT(bricks, 0.25 * single);
    EXPECT_GE(bricks, double(kMbPeak) * 0.5 / kMbW * 2.0 * 0.5);  // at least the slab's depth
}

// Ratio and spectral tracking through the bricks along +x against Beer-Lambert of the slab's
// integral (peak / w per unit extinction); the controls: 3 % (ratio) and 6 % (the scattering
// weight) more or less depth are told apart. (At 600,000 paths: every channel within 0.3 se.)
TEST(VolumeMeshBricks, TrackingMatchesBeerLambert) {
    HostScene scene(mb_scene());
    const SceneView& s = scene.view();
    const int32_t mi = s.material_medium[0];
    const Medium& m = s.media[mi];
    ASSERT_GE(m.majorant_grid, 0);
    const Vec3 o{0.0f, 0.43f, 0.61f}, d{1, 0, 0};
    const double depth = double(kMbPeak) / kMbW;
    const double sa[3] = {0.15, 0.3, 0.5}, ss[3] = {0.25, 0.2, 0.1};
    const int n = 100000;
    double sum[2][3] = {}, sum2[2][3] = {};
    for (int k = 0; k < n; ++k) {
        Rng path = Rng::for_path(59, 0, uint64_t(k));
        Rng r1 = medium_tracking_rng(path, 1), r0 = medium_tracking_rng(path, 0);
        const Vec3 t = medium_ratio_tracking(s, m, mi, o, d, 1.0f, r1);
        const HeteroStep st = medium_track(
            s, m, mi, o, d, 1.0f, vec3(1.0f), r0, [](float, Vec3, float) {},
            [](float, float, Vec3) {});
        const Vec3 w = st.scattered ? st.weight : vec3(0.0f);
        const double v[2][3] = {{t.x, t.y, t.z}, {w.x, w.y, w.z}};
        for (int e = 0; e < 2; ++e)
            for (int c = 0; c < 3; ++c) sum[e][c] += v[e][c], sum2[e][c] += v[e][c] * v[e][c];
    }
    // the transmittance exp(-st depth); the scattering weight's mean ss / st (1 - T)
    for (int e = 0; e < 2; ++e)
        for (int c = 0; c < 3; ++c) {
            const double stc = sa[c] + ss[c];
            auto want = [&](double f) {
                const double T = std::exp(-stc * depth * f);
                return e ? ss[c] / stc * (1.0 - T) : T;
            };
            const double mean = sum[e][c] / n;
            const double se =
                std::sqrt(std::max(sum2[e][c] / n - mean * mean, 0.0) / (n - 1)) + 1e-9;
            std::printf("%s channel %d: %.4f +- %.4f, Beer-Lambert %.4f\n", e ? "scatter" : "ratio",
                        c, mean, se, want(1.0));
            EXPECT_LT(std::fabs(mean - want(1.0)), 4.5 * se) << e << c;
            // the controls: 3 % of the depth (the transmittance), 6 % (the scattering, noisier)
            for (double f : {e ? 0.94 : 0.97, e ? 1.06 : 1.03})
                EXPECT_GT(std::fabs(mean - want(f)), 4.5 * se) << e << c << " control " << f;
        }
}

TEST(VolumeMeshBricks, OffKeepsOneMajorant) {
    setenv("LANTERN_MAJORANT_BRICKS", "0", 1);
    HostScene off(mb_scene());
    unsetenv("LANTERN_MAJORANT_BRICKS");
    HostScene on(mb_scene());
    const Medium& a = off.view().media[off.view().material_medium[0]];
    const Medium& b = on.view().media[on.view().material_medium[0]];
    EXPECT_LT(a.majorant_grid, 0);
    EXPECT_GE(b.majorant_grid, 0);
    EXPECT_EQ(a.majorant, b.majorant);  // the medium's own bound is the same
}
