// Node programs reading Volume object grids (kOpGrid) as a medium's density, and their bound
// (scene/program_bound.h, docs/volumes.md "Node graphs on volume inputs"): the interval bound
// holds every value the program gives inside random boxes, sampled densely (the bound of a
// box shrunk to its middle tenth as the control, which those samples must catch); every
// majorant brick of such a medium bounds the extinction along random rays; ratio and
// spectral tracking through it against Beer-Lambert of the density integrated by quadrature
// (a 3 % control); a program without a bound (a Noise node; exp(exp(.)) overflowing) warns
// and keeps a finite majorant and density.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/rng.h"
#include "scene/medium_hetero.h"
#include "scene/program_bound.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;

namespace {

constexpr int kProgNx = 37, kProgNy = 29, kProgNz = 23;

std::vector<float> blob_voxels(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> v(size_t(kProgNx) * kProgNy * kProgNz, 0.0f);
    for (int k = 0; k < kProgNz; ++k)
        for (int j = 0; j < kProgNy; ++j)
            for (int i = 0; i < kProgNx; ++i) {
                const bool a = i >= 4 && i < 13 && j >= 6 && j < 15 && k >= 3 && k < 12;
                const bool b = i >= 24 && i < 30 && j >= 17 && j < 26 && k >= 14 && k < 20;
                if (a || b) v[(size_t(k) * kProgNy + size_t(j)) * kProgNx + size_t(i)] = (a ? 5.0f : 2.0f) * u(rng);
            }
    return v;
}

// One instruction word block (material_program_ops.h NodeInstr's encoding).
void instr(std::vector<uint32_t>& code, int op, int mode, int flags, int dim, int in, int out,
           int aux = 0, int aux2 = 0) {
    code.insert(code.end(), {uint32_t(op | (mode << 8) | (flags << 16) | (dim << 24)),
                             uint32_t(in | (out << 16)), uint32_t(aux), uint32_t(aux2)});
}

enum class Prog { kMapTimesFlame, kTwiceDensity, kNoise, kOverflow };

// A Volume object's scene: grid 0 "density" (two blobs), grid 1 "flame" (a smooth field on a
// transform of its own); the material's density a program of them.
//   kMapTimesFlame: Map Range (0..4 -> 0.5..3, clamped) of the density x the flame's Fac;
//   kTwiceDensity:  2 x the density (Math Multiply), scale the factor;
//   kNoise:         the density x a Noise texture's Fac (Multifractal of a Detail that
//                   varies: no interval rule, unbounded);
//   kOverflow:      exp(exp(100 x the density)) (infinite where the density is > 0.06).
SceneInput grid_program_scene(const float* m16, Prog prog, float scale = 2.0f) {
    SceneInput in;
    GridInput gi;
    gi.name = "density";
    gi.dims[0] = kProgNx;
    gi.dims[1] = kProgNy;
    gi.dims[2] = kProgNz;
    std::copy(m16, m16 + 16, gi.index_to_world);
    gi.voxels = blob_voxels(7);
    in.grids.push_back(gi);
    GridInput f;
    f.name = "flame";
    f.dims[0] = 20;
    f.dims[1] = 18;
    f.dims[2] = 16;
    // over the density's block, on a map of its own: flame index -> density index (sheared,
    // scaled, moved) -> the world
    const float fi[3][4] = {{1.9f, 0, 0, -0.5f}, {0, 1.6f, 0.1f, 0.3f}, {0, 0, 1.45f, -0.2f}};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
            float v = c == 3 ? m16[4 * r + 3] : 0.0f;
            for (int k = 0; k < 3; ++k) v += m16[4 * r + k] * fi[k][c];
            f.index_to_world[4 * r + c] = v;
        }
    for (int k = 0; k < 16; ++k)
        for (int j = 0; j < 18; ++j)
            for (int i = 0; i < 20; ++i)
                f.voxels.push_back(0.6f + 0.5f * std::sin(0.4f * float(i) + 0.3f * float(j * k)));
    in.grids.push_back(f);
    // registers: constants 0..7, then temporaries from 16
    std::vector<float> c = {0.0f, 4.0f, 0.5f, 3.0f, 4.0f, scale, 1.0f, 0.0f};
    std::vector<uint32_t> code;
    if (prog == Prog::kMapTimesFlame) {
        instr(code, kOpGrid, 0, 0, 0, 0, 16, 0);       // density: 16..19
        instr(code, kOpGrid, 0, 0, 0, 0, 20, 1);       // flame: 20..23
        instr(code, kOpCopy, 0, 0, 1, 19, 24);         // value (the Fac)
        instr(code, kOpCopy, 0, 0, 3, 0, 25);          // from 0..4, to_min 0.5
        instr(code, kOpCopy, 0, 0, 2, 3, 28);          // to_max 3, steps 4
        instr(code, kOpMapRange, 0, 1, 1, 24, 30);     // linear, clamped
        instr(code, kOpCopy, 0, 0, 1, 30, 31);
        instr(code, kOpCopy, 0, 0, 1, 23, 32);
        instr(code, kOpCopy, 0, 0, 1, 7, 33);
        instr(code, kOpMath, 2, 0, 0, 31, 34);         // multiply
    } else if (prog == Prog::kTwiceDensity) {
        instr(code, kOpGrid, 0, 0, 0, 0, 16, 0);
        instr(code, kOpCopy, 0, 0, 1, 19, 31);
        instr(code, kOpCopy, 0, 0, 1, 5, 32);
        instr(code, kOpCopy, 0, 0, 1, 7, 33);
        instr(code, kOpMath, 2, 0, 0, 31, 34);
    } else if (prog == Prog::kOverflow) {
        c[6] = 100.0f;
        instr(code, kOpGrid, 0, 0, 0, 0, 16, 0);
        instr(code, kOpCopy, 0, 0, 1, 19, 31);
        instr(code, kOpCopy, 0, 0, 1, 6, 32);
        instr(code, kOpCopy, 0, 0, 1, 7, 33);
        instr(code, kOpMath, 2, 0, 0, 31, 35);         // multiply
        instr(code, kOpCopy, 0, 0, 1, 35, 36);
        instr(code, kOpMath, 10, 0, 0, 36, 37);        // exponent
        instr(code, kOpMath, 10, 0, 0, 37, 34);        // exponent
    } else {
        // noise: vector(3) w scale detail roughness lacunarity offset gain distortion
        instr(code, kOpInput, 0, 0, 0, 0, 40);         // position 40..42
        c.insert(c.end(), {0.0f, 3.0f, 2.0f, 0.5f, 2.0f, 0.0f, 1.0f, 0.0f});  // consts 8..15
        instr(code, kOpCopy, 0, 0, 3, 8, 43);
        instr(code, kOpCopy, 0, 0, 3, 11, 46);
        instr(code, kOpCopy, 0, 0, 2, 14, 49);
        instr(code, kOpCopy, 0, 0, 1, 40, 45);         // detail = x: not constant
        instr(code, kOpNoise, 0, 1, 3, 40, 52);        // multifractal, 3D: fac at 52
        instr(code, kOpGrid, 0, 0, 0, 0, 16, 0);
        instr(code, kOpCopy, 0, 0, 1, 19, 31);
        instr(code, kOpCopy, 0, 0, 1, 52, 32);
        instr(code, kOpCopy, 0, 0, 1, 7, 33);
        instr(code, kOpMath, 2, 0, 0, 31, 34);
    }
    instr(code, kOpCopy, 0, 0, 1, 34, 60);
    instr(code, kOpCopy, 0, 0, 1, 34, 61);
    instr(code, kOpCopy, 0, 0, 1, 34, 62);
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()), uint32_t(kTargetDensity),
                   60u};
    MediumInput med;
    med.name = "smoke";
    med.sigma_a = vec3(0.15f, 0.3f, 0.5f);
    med.sigma_s = vec3(0.25f, 0.2f, 0.1f);
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "smoke";
    mat.medium = 0;
    mat.volume_only = true;
    mat.density_grid = 0;
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    const Transform tf{{{m16[0], m16[1], m16[2], m16[3]},
                        {m16[4], m16[5], m16[6], m16[7]},
                        {m16[8], m16[9], m16[10], m16[11]}}};
    Vec3 lo = vec3(kInf), hi = vec3(-kInf);
    for (int k = 0; k < 8; ++k) {
        const Vec3 p = tf.point(Vec3{k & 1 ? float(kProgNx) : -1.0f, k & 2 ? float(kProgNy) : -1.0f,
                                     k & 4 ? float(kProgNz) : -1.0f});
        lo = Vec3{std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = Vec3{std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    in.meshes.push_back(box_mesh(lo, hi, 0));
    return in;
}

const float kGridAxis[16] = {0.1f, 0, 0, -1, 0, 0.1f, 0, 0.5f, 0, 0, 0.1f, 2, 0, 0, 0, 1};
const float kGridRotated[16] = {0, -0.07f, 0, 1, 0.05f, 0, 0, 2, 0, 0, 0.09f, -3, 0, 0, 0, 1};

float density_at(const SceneView& s, const Medium& m, int32_t med, Vec3 p) {
    return medium_density(s, m, med, p, Vec3{1, 0, 0});
}

}  // namespace

TEST(GridProgram, IntervalBoundHoldsInsideRandomBoxes) {
    HostScene scene(grid_program_scene(kGridRotated, Prog::kMapTimesFlame));
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    const Medium& m = s.media[med];
    ASSERT_GE(m.density_prog, 0);
    const MaterialProgram& p = s.programs[m.density_prog];
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const Transform i2w{{{kGridRotated[0], kGridRotated[1], kGridRotated[2], kGridRotated[3]},
                         {kGridRotated[4], kGridRotated[5], kGridRotated[6], kGridRotated[7]},
                         {kGridRotated[8], kGridRotated[9], kGridRotated[10], kGridRotated[11]}}};
    int samples = 0, caught = 0, tight = 0;
    for (int b = 0; b < 300; ++b) {
        const Vec3 c = i2w.point(Vec3{-3.0f + u(rng) * (kProgNx + 6), -3.0f + u(rng) * (kProgNy + 6),
                                      -3.0f + u(rng) * (kProgNz + 6)});
        const Vec3 h{0.05f + 0.4f * u(rng), 0.05f + 0.4f * u(rng), 0.05f + 0.4f * u(rng)};
        const Vec3 lo = c - h, hi = c + h;
        Interval iv[3], shrunk[3];
        ASSERT_TRUE(program_bound(s, p, med, lo, hi, iv)) << "box " << b;
        ASSERT_TRUE(program_bound(s, p, med, lo + h * 0.9f, hi - h * 0.9f, shrunk));
        float vmax = -kInf;
        bool out_of_shrunk = false;
        constexpr int N = 12;
        for (int z = 0; z <= N; ++z)
            for (int y = 0; y <= N; ++y)
                for (int x = 0; x <= N; ++x) {
                    const Vec3 q = lo + (hi - lo) * Vec3{float(x) / N, float(y) / N, float(z) / N};
                    const float v = program_run(s, p, medium_shade_point(med, q, Vec3{1, 0, 0})).x;
                    ASSERT_GE(v, iv[0].lo) << "box " << b;
                    ASSERT_LE(v, iv[0].hi) << "box " << b;
                    out_of_shrunk = out_of_shrunk || v > shrunk[0].hi || v < shrunk[0].lo;
                    vmax = std::max(vmax, v);
                    ++samples;
                }
        caught += out_of_shrunk;
        tight += vmax > 0.5f * iv[0].hi;
    }
    std::printf("%d samples in 300 boxes; the shrunk box's bound caught in %d boxes; the "
                "bound within 2x of the samples' largest in %d\n", samples, caught, tight);
    EXPECT_GT(caught, 30) << "the control: the bound of the box's middle tenth must miss samples";
    EXPECT_GT(tight, 150) << "the bound should not be loose everywhere";
}

TEST(GridProgram, EveryBrickBoundsTheExtinctionAlongRays) {
    for (const float* tf : {kGridAxis, kGridRotated}) {
        HostScene scene(grid_program_scene(tf, Prog::kMapTimesFlame));
        const SceneView& s = scene.view();
        const int32_t med = s.material_medium[0];
        const Medium& m = s.media[med];
        ASSERT_GE(m.majorant_grid, 0);
        const Transform i2w{{{tf[0], tf[1], tf[2], tf[3]},
                             {tf[4], tf[5], tf[6], tf[7]},
                             {tf[8], tf[9], tf[10], tf[11]}}};
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        int checked = 0;
        float mu_min = kInf;
        for (int r = 0; r < 400; ++r) {
            const Vec3 o = i2w.point(Vec3{-4.0f + u(rng) * (kProgNx + 8), -4.0f + u(rng) * (kProgNy + 8),
                                          -4.0f + u(rng) * (kProgNz + 8)});
            const float ct = 1.0f - 2.0f * u(rng), ph = 2.0f * kPi * u(rng);
            const float st = std::sqrt(std::max(0.0f, 1.0f - ct * ct));
            Vec3 d{st * std::cos(ph), st * std::sin(ph), ct};
            if (r % 7 == 0) d = Vec3{1, 0, 0};
            const float t_end = 0.5f + 4.0f * u(rng);
            MajorantWalk walk = medium_majorant_walk(s, m, o, d, t_end);
            MajorantSeg seg;
            while (majorant_next(walk, &seg)) {
                for (int k = 0; k <= 16; ++k) {
                    const float x = seg.t0 + (seg.t1 - seg.t0) * (float(k) + 0.5f) / 17.0f;
                    // the medium is inside its box (the block's support) only
                    const Vec3 q = s.grids[0].world_to_index.point(o + d * x);
                    if (!(q.x > -1.0f && q.y > -1.0f && q.z > -1.0f && q.x < float(kProgNx) &&
                          q.y < float(kProgNy) && q.z < float(kProgNz)))
                        continue;
                    const MediumCoeffs c = medium_coeffs_at(s, m, med, o + d * x, d);
                    ASSERT_LE(max_component(c.sigma_a + c.sigma_s), seg.mu * (1.0f + 1e-5f) + 1e-6f)
                        << "ray " << r << " at " << x;
                    ++checked;
                }
                mu_min = std::min(mu_min, seg.mu);
            }
        }
        EXPECT_GT(checked, 10000);
        // the bricks follow the program: where the flame is small the bound drops below the
        // medium's one majorant
        EXPECT_LT(mu_min, 0.9f * m.majorant);
    }
}

TEST(GridProgram, TrackingIsBeerLambertOfTheProgramsDensity) {
    HostScene scene(grid_program_scene(kGridAxis, Prog::kTwiceDensity));
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    const Medium& m = s.media[med];
    ASSERT_GE(m.majorant_grid, 0);
    ASSERT_EQ(m.density_prog >= 0, true);
    // a ray along +x through both blobs' rows; the depth of the grid itself (x 2) by a fine
    // midpoint rule of its lookup (piecewise linear along x: exact to float sums)
    const Vec3 q0{-1.5f, 10.3f, 7.6f};
    const float h = 0.1f, L = 3.8f;
    const Vec3 o{-1.0f + h * q0.x, 0.5f + h * q0.y, 2.0f + h * q0.z}, d{1, 0, 0};
    double depth = 0.0;
    const int steps = 200000;
    for (int k = 0; k < steps; ++k)
        depth += grid_lookup(s.grids[0], s.grid_voxels, o + d * (L * (float(k) + 0.5f) / steps));
    depth *= 2.0 * L / steps;
    ASSERT_GT(depth, 0.5);
    // the program's density is 2 x the grid's (and not the grid times it: 2 x grid^2)
    EXPECT_NEAR(density_at(s, m, med, o + d * 0.8f),
                2.0f * grid_lookup(s.grids[0], s.grid_voxels, o + d * 0.8f), 1e-5f);
    const double sa[3] = {0.15, 0.3, 0.5}, ss[3] = {0.25, 0.2, 0.1};
    const int n = 100000;
    double tr[3] = {}, tr2[3] = {}, sc[3] = {}, sc2[3] = {};
    for (int k = 0; k < n; ++k) {
        Rng path = Rng::for_path(91, 0, uint64_t(k));
        Rng r1 = medium_tracking_rng(path, 1), r0 = medium_tracking_rng(path, 0);
        const Vec3 t = medium_ratio_tracking(s, m, med, o, d, L, r1);
        const HeteroStep st = medium_track(s, m, med, o, d, L, vec3(1.0f), r0,
                                           [](float, Vec3, float) {}, [](float, float, Vec3) {});
        const double tv[3] = {t.x, t.y, t.z}, wv[3] = {st.weight.x, st.weight.y, st.weight.z};
        for (int c = 0; c < 3; ++c) {
            tr[c] += tv[c];
            tr2[c] += tv[c] * tv[c];
            if (st.scattered) {
                sc[c] += wv[c];
                sc2[c] += wv[c] * wv[c];
            }
        }
    }
    for (int c = 0; c < 3; ++c) {
        const double st = sa[c] + ss[c], T = std::exp(-st * depth), S = ss[c] / st * (1.0 - T);
        auto check = [&](double sum, double sum2, double want, const char* what) {
            const double mean = sum / n;
            const double se = std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / (n - 1)) + 1e-9;
            std::printf("%s channel %d: %.5f want %.5f se %.2g\n", what, c, mean, want, se);
            EXPECT_LT(std::fabs(mean - want), 4.5 * se) << what << " channel " << c;
            EXPECT_GT(std::fabs(mean - 1.03 * want), 4.5 * se) << what << " control " << c;
        };
        check(tr[c], tr2[c], T, "ratio");
        check(sc[c], sc2[c], S, "scatter");
    }
}

TEST(GridProgram, UnboundedProgramWarnsAndKeepsAFiniteMajorant) {
    for (Prog prog : {Prog::kNoise, Prog::kOverflow}) {
        HostScene scene(grid_program_scene(kGridAxis, prog));
        const SceneView& s = scene.view();
        const int32_t med = s.material_medium[0];
        const Medium& m = s.media[med];
        bool warned = false;
        for (const std::string& w : scene.warnings())
            warned = warned || (w.find("smoke") != std::string::npos &&
                                w.find("no bound") != std::string::npos);
        EXPECT_TRUE(warned);
        EXPECT_TRUE(std::isfinite(m.majorant));
        EXPECT_GT(m.majorant, 0.0f);
        // every brick finite; the density finite everywhere (infinities are 0, as NaN)
        const MajorantGrid& g = s.majorant_grids[m.majorant_grid];
        for (size_t k = 0; k < size_t(g.nx) * g.ny * g.nz; ++k)
            ASSERT_TRUE(std::isfinite(s.majorant_values[g.offset + k]));
        for (int k = 0; k < 1000; ++k) {
            const Vec3 p{-1.0f + 3.7f * float(k) / 1000.0f, 1.5f, 3.0f};
            ASSERT_TRUE(std::isfinite(density_at(s, m, med, p)));
        }
    }
    // the bounded program of the same grids warns nothing of the kind
    HostScene ok(grid_program_scene(kGridAxis, Prog::kMapTimesFlame));
    for (const std::string& w : ok.warnings()) EXPECT_EQ(w.find("no bound"), std::string::npos) << w;
}
