// A mesh volume's density program bounded by interval arithmetic (scene/program_bound.h,
// docs/volumes.md "Node graphs on volume inputs"): a thin slab of density whose peak lies
// between the points of the 25^3 lattice that bounded it before. With the interval bound the
// majorant holds the peak, and spectral and ratio tracking through the slab agree with
// Beer-Lambert of the density's integral (3 % and 5 % controls). The old majorant (lattice
// x 1.5) put back: over a base of 0.2 (old majorant 0.3 x sigma_t, peak 30.2) the trackings'
// negative null weights stay unbiased but their standard errors grow 10-20x; with no base the
// lattice reads 0, the old majorant is 0 and the slab vanished (transmittance 1: biased, the
// test's negative control). A program through a Noise node of a type without a rule keeps the
// lattice and warns by name (mode 0 of kOpNoise, Multifractal, whose rule needs a constant
// Detail: here the position's x).
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

// the slab: 0.2 + kSlabPeak x max(1 - kSlabW |x - kSlabC|, 0), its centre between lattice
// points k / 24 and its half-width 1/60 below their half-spacing 1/48
constexpr float kSlabC = 12.5f / 24.0f, kSlabW = 60.0f, kSlabPeak = 30.0f, kSlabBase = 0.2f;

void slab_instr(std::vector<uint32_t>& code, int op, int mode, int dim, int in, int out) {
    code.insert(code.end(), {uint32_t(op | (mode << 8) | (dim << 24)), uint32_t(in | (out << 16)),
                             0u, 0u});
}

// Math op `mode` of registers a, b (copied to a block at `at`, its third operand 0): out at+3
int slab_math(std::vector<uint32_t>& code, int mode, int a, int b, int at) {
    slab_instr(code, kOpCopy, 0, 1, a, at);
    slab_instr(code, kOpCopy, 0, 1, b, at + 1);
    slab_instr(code, kOpCopy, 0, 1, 3, at + 2);
    slab_instr(code, kOpMath, mode, 0, at, at + 3);
    return at + 3;
}

// A unit cube of volume-only material whose density is the slab along x; with `noise`, the
// slab's base is a Noise texture's Fac x 0.2 (Multifractal of a Detail that varies: no rule).
SceneInput slab_scene(bool noise, float base_density = kSlabBase) {
    SceneInput in;
    std::vector<float> c = {kSlabC, kSlabW, 1.0f, 0.0f, kSlabPeak, base_density, 0.0f, 0.0f};
    std::vector<uint32_t> code;
    slab_instr(code, kOpInput, 0, 0, 0, 16);                // position 16..18
    int r = slab_math(code, 1, 16, 0, 30);                  // x - c
    r = slab_math(code, 9, r, 3, 34);                       // |x - c|
    r = slab_math(code, 2, r, 1, 38);                       // w |x - c|
    r = slab_math(code, 1, 2, r, 42);                       // 1 - w |x - c|
    r = slab_math(code, 12, r, 3, 46);                      // max(., 0)
    r = slab_math(code, 2, r, 4, 50);                       // peak x tent
    int base = 5;
    if (noise) {
        // noise: vector(3) w scale detail roughness lacunarity offset gain distortion
        c.insert(c.end(), {0.0f, 3.0f, 2.0f, 0.5f, 2.0f, 0.0f, 1.0f, 0.0f});  // consts 8..15
        slab_instr(code, kOpCopy, 0, 3, 16, 70);
        slab_instr(code, kOpCopy, 0, 3, 8, 73);
        slab_instr(code, kOpCopy, 0, 3, 11, 76);
        slab_instr(code, kOpCopy, 0, 2, 14, 79);
        slab_instr(code, kOpCopy, 0, 1, 16, 75);  // detail = x: not constant
        code.insert(code.end(), {uint32_t(kOpNoise | (0 << 8) | (1 << 16) | (3 << 24)),
                                 uint32_t(70 | (82 << 16)), 0u, 0u});  // fBm, normalised: 82
        base = slab_math(code, 2, 82, 5, 90);
    }
    r = slab_math(code, 0, r, base, 54);                    // + base
    for (int k = 0; k < 3; ++k) slab_instr(code, kOpCopy, 0, 1, r, 60 + k);
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
    in.meshes.push_back(box_mesh(vec3(0.0f), vec3(1.0f), 0));
    return in;
}

// A procedural texture's rule (scene/program_bound.cpp): a cube of volume-only material whose
// density program is texture `op` of the position (its other inputs the constants `in`), the
// result (output 0, output 1, output 3): a Fac and colour channels.
struct TexCase {
    const char* name;
    int op, mode, flags, dim, aux, aux2;
    std::vector<float> in;
};
SceneInput texture_scene(const TexCase& t) {
    SceneInput in = slab_scene(false);
    std::vector<float> c = {0, 0, 0, 0, 0, 0, 0, 0};
    c.insert(c.end(), t.in.begin(), t.in.end());  // from 8
    std::vector<uint32_t> code;
    slab_instr(code, kOpInput, 0, 0, 0, 16);
    slab_instr(code, kOpCopy, 0, 3, 16, 30);
    for (size_t k = 0; k < t.in.size(); k += 3)
        slab_instr(code, kOpCopy, 0, int(std::min<size_t>(3, t.in.size() - k)), 8 + int(k),
                   33 + int(k));
    code.insert(code.end(), {uint32_t(t.op | (t.mode << 8) | (t.flags << 16) | (t.dim << 24)),
                             uint32_t(30 | (50 << 16)), uint32_t(t.aux), uint32_t(t.aux2)});
    slab_instr(code, kOpCopy, 0, 1, 50, 60);
    slab_instr(code, kOpCopy, 0, 1, 51, 61);
    slab_instr(code, kOpCopy, 0, 1, 53, 62);
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()), uint32_t(kTargetDensity),
                   60u};
    in.meshes[0] = box_mesh(vec3(-2.3f), vec3(3.1f), 0);
    return in;
}

// Spectral and ratio tracking along +x at (., 0.43, 0.61) through medium mm of the slab scene
// (base density `base`): per channel the mean and standard error of the transmittance and of
// the scattering weight, against Beer-Lambert (the depth base + peak / w, exact for the tent).
struct SlabEstimate {
    double mean[2][3], se[2][3], want[2][3];
};
SlabEstimate track_slab(const SceneView& s, const Medium& mm, int32_t med, float base) {
    const Vec3 o{0.0f, 0.43f, 0.61f}, d{1, 0, 0};
    const double depth = base + double(kSlabPeak) / kSlabW;
    const double sa[3] = {0.15, 0.3, 0.5}, ss[3] = {0.25, 0.2, 0.1};
    const int n = 100000;
    double sum[2][3] = {}, sum2[2][3] = {};
    for (int k = 0; k < n; ++k) {
        Rng path = Rng::for_path(57, 0, uint64_t(k));
        Rng r1 = medium_tracking_rng(path, 1), r0 = medium_tracking_rng(path, 0);
        const Vec3 t = medium_ratio_tracking(s, mm, med, o, d, 1.0f, r1);
        const HeteroStep st = medium_track(s, mm, med, o, d, 1.0f, vec3(1.0f), r0,
                                           [](float, Vec3, float) {}, [](float, float, Vec3) {});
        const double v[2][3] = {{t.x, t.y, t.z},
                                {st.scattered ? st.weight.x : 0.0f, st.scattered ? st.weight.y : 0.0f,
                                 st.scattered ? st.weight.z : 0.0f}};
        for (int e = 0; e < 2; ++e)
            for (int c = 0; c < 3; ++c) {
                sum[e][c] += v[e][c];
                sum2[e][c] += v[e][c] * v[e][c];
            }
    }
    SlabEstimate r{};
    for (int c = 0; c < 3; ++c) {
        const double stc = sa[c] + ss[c], T = std::exp(-stc * depth);
        r.want[0][c] = T;
        r.want[1][c] = ss[c] / stc * (1.0 - T);
        for (int e = 0; e < 2; ++e) {
            r.mean[e][c] = sum[e][c] / n;
            r.se[e][c] = std::sqrt(std::max(sum2[e][c] / n - r.mean[e][c] * r.mean[e][c], 0.0) /
                                   (n - 1)) + 1e-9;
        }
    }
    return r;
}

}  // namespace

TEST(MeshDensityBound, SlabBetweenLatticePointsIsBoundedAndTrackedUnbiased) {
    const char* what[2] = {"ratio", "scatter"};
    for (float base : {kSlabBase, 0.0f}) {
        HostScene scene(slab_scene(false, base));
        const SceneView& s = scene.view();
        const int32_t med = s.material_medium[0];
        ASSERT_GE(med, 0);
        const Medium& m = s.media[med];
        ASSERT_GE(m.density_prog, 0);
        for (const std::string& w : scene.warnings())
            EXPECT_EQ(w.find("no bound"), std::string::npos) << w;
        // the peak, and the lattice (what bounded it before) that misses it
        const Vec3 d{1, 0, 0};
        const float peak = medium_density(s, m, med, Vec3{kSlabC, 0.5f, 0.5f}, d);
        EXPECT_NEAR(peak, kSlabPeak + base, 1e-3f);
        float lattice = 0.0f;
        for (int x = 0; x <= 24; ++x)
            lattice = std::max(lattice,
                               medium_density(s, m, med, Vec3{float(x) / 24.0f, 0.5f, 0.5f}, d));
        EXPECT_LT(lattice * 1.5f, 0.05f * peak);
        EXPECT_GE(m.density_max, peak);
        EXPECT_LT(m.density_max, 1.1f * peak);  // 16^3 sub-boxes: tight here
        // the interval bound as the one majorant (the bricks over the same bound:
        // test_volume_mesh_bricks.cpp)
        Medium one = m;
        one.majorant_grid = -1;
        const SlabEstimate now = track_slab(s, one, med, base);
        Medium old = m;
        old.majorant_grid = -1;  // the one majorant (not the bricks, volleft)
        old.majorant = max_component(m.sigma_a + m.sigma_s) * lattice * 1.5f;
        old.density_max = lattice * 1.5f;
        const SlabEstimate before = track_slab(s, old, med, base);
        int biased = 0;
        for (int e = 0; e < 2; ++e)
            for (int c = 0; c < 3; ++c) {
                const double want = now.want[e][c];
                std::printf("base %.1f %s channel %d: bound %.5f (se %.2g), lattice %.5f (se %.2g), "
                            "want %.5f\n", base, what[e], c, now.mean[e][c], now.se[e][c],
                            before.mean[e][c], before.se[e][c], want);
                EXPECT_LT(std::fabs(now.mean[e][c] - want), 4.5 * now.se[e][c]) << what[e] << c;
                // the control: 3 % off (the transmittance), 5 % (the scattering, noisier)
                EXPECT_GT(std::fabs(now.mean[e][c] - (e ? 1.05 : 1.03) * want), 4.5 * now.se[e][c])
                    << what[e] << " control " << c;
                biased += std::fabs(before.mean[e][c] - want) > 4.5 * before.se[e][c];
                if (base > 0.0f)  // the lattice's majorant: negative null weights, noisier
                    EXPECT_GT(before.se[e][c], 4.0 * now.se[e][c]) << what[e] << c;
            }
        // with nothing on the lattice the old majorant was 0: the slab was not there at all
        if (base == 0.0f) EXPECT_EQ(biased, 6);
    }
}

TEST(MeshDensityBound, ProgramWithoutRuleKeepsTheLatticeAndWarns) {
    HostScene scene(slab_scene(true));
    const SceneView& s = scene.view();
    const Medium& m = s.media[s.material_medium[0]];
    bool warned = false;
    for (const std::string& w : scene.warnings())
        warned = warned || (w.find("slab") != std::string::npos && w.find("no bound") != std::string::npos);
    EXPECT_TRUE(warned);
    EXPECT_TRUE(std::isfinite(m.majorant));
    EXPECT_GT(m.majorant, 0.0f);
    EXPECT_LT(m.density_max, 3.0f);  // the lattice x 1.5 of a base <= 0.2: the slab missed
}

TEST(MeshDensityBound, TextureRulesHoldInsideRandomBoxes) {
    // noise inputs: w scale detail roughness lacunarity offset gain distortion
    const TexCase cases[] = {
        {"gradient linear", kOpGradient, 0, 0, 0, 0, 0, {}},
        {"gradient spherical", kOpGradient, 6, 0, 0, 0, 0, {}},
        {"wave sine, distorted", kOpWave, 0, 0, 0, 3, 0, {2.0f, 3.0f, 2.0f, 1.0f, 0.5f, 0.3f}},
        {"wave rings saw", kOpWave, 1, 0, 0, 3, 1, {1.5f, 0.0f, 2.0f, 1.0f, 0.5f, 0.0f}},
        {"wave triangle", kOpWave, 0, 0, 0, 1, 2, {1.5f, 1.0f, 2.0f, 1.0f, 0.5f, 0.0f}},
        {"white noise", kOpWhiteNoise, 0, 0, 3, 0, 0, {0.7f}},
        {"checker", kOpChecker, 0, 0, 0, 0, 0, {0.2f, 0.9f, 0.4f, 1.5f, -0.3f, 0.6f, 2.0f}},
        {"noise fBm 3D normalised", kOpNoise, 3, 1, 3, 0, 0,
         {0.0f, 2.0f, 5.5f, 0.7f, 2.0f, 0.0f, 1.0f, 0.4f}},
        {"noise fBm 1D normalised", kOpNoise, 3, 1, 1, 0, 0,
         {0.3f, 2.0f, 3.0f, 0.5f, 2.0f, 0.0f, 1.0f, 0.0f}},
        {"noise fBm 2D raw", kOpNoise, 3, 0, 2, 0, 0,
         {0.0f, 1.5f, 2.5f, 0.6f, 2.0f, 0.0f, 1.0f, 0.0f}},
        {"noise fBm 4D raw", kOpNoise, 3, 0, 4, 0, 0,
         {0.4f, 1.5f, 1.0f, 0.9f, 2.5f, 0.0f, 1.0f, 0.0f}},
    };
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const TexCase& t : cases) {
        HostScene scene(texture_scene(t));
        const SceneView& s = scene.view();
        const int32_t med = s.material_medium[0];
        const Medium& m = s.media[med];
        ASSERT_GE(m.density_prog, 0) << t.name;
        for (const std::string& w : scene.warnings())
            EXPECT_EQ(w.find("no bound"), std::string::npos) << t.name << ": " << w;
        const MaterialProgram& p = s.programs[m.density_prog];
        float reach[3] = {-kInf, -kInf, -kInf}, whole[3] = {0, 0, 0};
        Interval all[3];
        ASSERT_TRUE(program_bound(s, p, med, vec3(-2.3f), vec3(3.1f), all)) << t.name;
        for (int b = 0; b < 60; ++b) {
            const Vec3 c{-2.0f + 5.0f * u(rng), -2.0f + 5.0f * u(rng), -2.0f + 5.0f * u(rng)};
            const Vec3 h{0.02f + 0.3f * u(rng), 0.02f + 0.3f * u(rng), 0.02f + 0.3f * u(rng)};
            Interval iv[3];
            ASSERT_TRUE(program_bound(s, p, med, c - h, c + h, iv)) << t.name;
            for (int k = 0; k < 400; ++k) {
                const Vec3 q = c - h + 2.0f * h * Vec3{u(rng), u(rng), u(rng)};
                const Vec3 v = program_run(s, p, medium_shade_point(med, q, Vec3{1, 0, 0}));
                const float vv[3] = {v.x, v.y, v.z};
                for (int ch = 0; ch < 3; ++ch) {
                    ASSERT_GE(vv[ch], iv[ch].lo) << t.name << " channel " << ch;
                    ASSERT_LE(vv[ch], iv[ch].hi) << t.name << " channel " << ch;
                    reach[ch] = std::max(reach[ch], vv[ch]);
                    whole[ch] = all[ch].hi;
                }
            }
        }
        std::printf("%s: largest sample %.3f %.3f %.3f, bound over the cube %.3f %.3f %.3f; "
                    "majorant's density %.3f\n", t.name, reach[0], reach[1], reach[2], whole[0],
                    whole[1], whole[2], m.density_max);
        EXPECT_GE(m.density_max, reach[0]) << t.name;
    }
}
