// Interval rules of node programs (scene/program_bound.h, program_bound_rules.h): the Noise
// bound's proof (the supremum of Perlin's noise over every gradient choice, by a lattice and a
// bound of the curvature: program_bound_noise.cpp), Noise's range over boxes of noise space,
// and every rule of the table over random boxes: dense samples of the program inside a box
// never fall outside the interval program_bound gives for it. A density program of the
// issue's clamped Noise smoke gets a majorant below the old bound's.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "program_bound_cases.h"
#include "scene/medium_hetero.h"
#include "scene/program_bound.h"
#include "scene/program_bound_rules.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;

namespace {

// G(x) = sum_c W_c(x) m(x - c) (program_bound_noise.cpp) at x in [0, 1]^D
double rb_sup_integrand(int D, const double* x) {
    auto fade = [](double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); };
    double G = 0.0;
    for (int c = 0; c < (1 << D); ++c) {
        double W = 1.0, d[4];
        for (int j = 0; j < D; ++j) {
            const int b = (c >> j) & 1;
            const double u = fade(x[j]);
            W *= b ? u : 1.0 - u;
            d[j] = std::fabs(x[j] - b);
        }
        std::sort(d, d + D, [](double p, double q) { return p > q; });
        const double m = D == 1   ? 8.0 * d[0]
                         : D == 2 ? std::max(d[0] + 2.0 * d[1], 2.0 * d[0] + d[1])
                         : D == 3 ? d[0] + d[1]
                                  : d[0] + d[1] + d[2];
        G += W * m;
    }
    return G;
}

constexpr double kRbScale[4] = {0.25, 0.6616, 0.9820, 0.8344};

}  // namespace

// The proof of kSnoiseSup: sup G <= the lattice's max + D x 7.5 kappa h^2 / 8, times Blender's
// scale, within snoise_sup less its float margin. G(x) = G(1 - x) per axis (fade(1 - t) =
// 1 - fade(t), the corners mirrored): the lattice covers [0, 1/2]^D.
TEST(ProgramBoundRules, NoiseSupremumProof) {
    const int n[4] = {4096, 1024, 128, 40};
    const double kappa[4] = {8.0, 2.0, 1.0, 1.0};
    for (int D = 1; D <= 4; ++D) {
        double best = 0.0;
        const int half = n[D - 1] / 2 + 1;
        long total = 1;
        for (int j = 0; j < D; ++j) total *= half;
        for (long k = 0; k < total; ++k) {
            double x[4];
            long rest = k;
            for (int j = 0; j < D; ++j) {
                x[j] = double(rest % half) / n[D - 1];
                rest /= half;
            }
            best = std::max(best, rb_sup_integrand(D, x));
        }
        const double h = 1.0 / n[D - 1];
        const double sup = (best + D * 7.5 * kappa[D - 1] * h * h / 8.0) * kRbScale[D - 1];
        std::printf("%dD: sup |snoise| <= %.5f (lattice %.5f), bound %.4f\n", D, sup,
                    best * kRbScale[D - 1], bound::snoise_sup(D));
        EXPECT_LE(sup + 4e-4, double(bound::snoise_sup(D))) << D;
        EXPECT_GT(sup + 2e-3, double(bound::snoise_sup(D))) << D;  // tight, not loose
        // and the noise itself stays inside (its observed range about 0.8-1 of the bound)
        std::mt19937 rng(7 + D);
        std::uniform_real_distribution<float> u(-50.0f, 50.0f);
        float seen = 0.0f;
        for (int k = 0; k < 200000; ++k) {
            const float p[4] = {u(rng), u(rng), u(rng), u(rng)};
            seen = std::max(seen, std::fabs(snoise(p, D)));
        }
        std::printf("   largest |snoise| of 200000 points: %.4f\n", seen);
        EXPECT_LE(seen, bound::snoise_sup(D));
        EXPECT_GT(seen, 0.6f * bound::snoise_sup(D));
    }
}

// snoise_range over random boxes of noise space (0.002 to 4 cells wide, some far from the
// origin): dense samples inside; narrow boxes get ranges far inside the global bound.
TEST(ProgramBoundRules, NoiseRangeOverBoxes) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int D = 1; D <= 4; ++D) {
        double narrow = 0.0;
        int narrow_n = 0, exceeded = 0;
        for (int b = 0; b < 300; ++b) {
            float lo[4], hi[4], w[4];
            const float far = b % 5 == 0 ? 9e4f : 30.0f;
            for (int j = 0; j < D; ++j) {
                w[j] = 0.002f * std::pow(2000.0f, u(rng));
                lo[j] = (2.0f * u(rng) - 1.0f) * far;
                hi[j] = lo[j] + w[j];
            }
            const bound::Reg r = bound::snoise_range(D, lo, hi);
            ASSERT_TRUE(r.known);
            float ilo[4], ihi[4];  // the control: the box's inner half
            for (int j = 0; j < D; ++j) {
                ilo[j] = lo[j] + 0.25f * w[j];
                ihi[j] = hi[j] - 0.25f * w[j];
            }
            const bound::Reg inner = bound::snoise_range(D, ilo, ihi);
            bool out_of_inner = false;
            EXPECT_LE(r.hi, bound::snoise_sup(D));
            EXPECT_GE(r.lo, -bound::snoise_sup(D));
            bool small = true;
            for (int j = 0; j < D; ++j) small = small && w[j] < 0.1f;
            if (small) {
                narrow += (r.hi - r.lo) / (2.0 * bound::snoise_sup(D));
                ++narrow_n;
            }
            for (int k = 0; k < 400; ++k) {
                float p[4];
                for (int j = 0; j < D; ++j)
                    p[j] = k < (1 << D) ? ((k >> j) & 1 ? hi[j] : lo[j])
                                        : lo[j] + (hi[j] - lo[j]) * u(rng);
                const float v = snoise(p, D);
                ASSERT_GE(v, r.lo) << D << "D box " << b;
                ASSERT_LE(v, r.hi) << D << "D box " << b;
                out_of_inner = out_of_inner || v < inner.lo || v > inner.hi;
            }
            exceeded += out_of_inner;
        }
        std::printf("%dD: boxes under 0.1 cell: mean width %.3f of the global bound's\n", D,
                    narrow / std::max(narrow_n, 1));
        EXPECT_LT(narrow / std::max(narrow_n, 1), 0.3) << D;
        // the control: samples of the whole box leave the inner half's range in most boxes
        // small enough for a lattice (a bound that narrow would be caught)
        std::printf("   %d of 300 boxes' samples leave their inner half's range\n", exceeded);
        EXPECT_GT(exceeded, 100) << D;
    }
}

// Noise, every type and dimension, value and colour, with and without distortion.
TEST(ProgramBoundRules, NoiseTypesInsideRandomBoxes) {
    // in: vector(3) w scale detail roughness lacunarity offset gain distortion
    struct T {
        const char* name;
        int type;
        float detail, roughness, lacunarity, offset, gain;
    } types[] = {{"multifractal", kNoiseMultifractal, 3.3f, 0.5f, 2.1f, 0.0f, 1.0f},
                 {"ridged", kNoiseRidged, 3.0f, 0.5f, 2.0f, 1.0f, 2.0f},
                 {"hybrid", kNoiseHybrid, 4.5f, 0.6f, 2.0f, 0.8f, 2.0f},
                 {"fBm", kNoiseFbm, 2.5f, 0.6f, 2.0f, 0.0f, 1.0f},
                 {"hetero", kNoiseHetero, 2.7f, 0.5f, 2.0f, 0.6f, 1.0f}};
    std::mt19937 rng(5);
    pbc::Tally tally;
    for (const T& ty : types)
        for (int dim = 1; dim <= 4; ++dim)
            for (int variant = 0; variant < 3; ++variant) {
                // 0: normalised, colour; 1: raw, distorted; 2: a hybrid's offset 0.3, ridged's 0.5
                const float dist = variant == 1 ? 0.4f : 0.0f;
                const float off = variant == 2 ? (ty.type == kNoiseRidged ? 0.5f : 0.3f) : ty.offset;
                pbc::Case c{std::string(ty.name) + " " + std::to_string(dim) + "D v" +
                             std::to_string(variant),
                         kOpNoise, ty.type, variant == 1 ? 0 : 1, dim, 0, 0,
                         {0, 0, 0, 0, 1.5f, ty.detail, ty.roughness, ty.lacunarity, off, ty.gain,
                          dist},
                         {{0, 0}, {1, 1}, {2, 2}, {3, 0}}, {0, 2, 3}};
                const double w = pbc::check(c, rng, 12, 150, 0.4f, 1, &tally);
                if (variant == 0 && dim == 3) std::printf("%s: mean width %.3f\n", c.name.c_str(), w);
            }
    std::printf("control: %d of %d boxes have samples outside the inner half's bound\n",
                tally.exceeded, tally.boxes);
    EXPECT_GT(tally.exceeded, tally.boxes / 5);  // fractal types are looser
}

// Voronoi (features, metrics, dimensions; distance, colour, positions), Magic and Brick.
TEST(ProgramBoundRules, VoronoiMagicBrickInsideRandomBoxes) {
    std::mt19937 rng(9);
    for (int feature = 0; feature <= 2; ++feature)
        for (int metric = 0; metric <= 3; ++metric)
            for (int dim = 1; dim <= 4; ++dim)
                for (int outs = 0; outs < 2; ++outs) {
                    // in: vector(3) w scale smoothness exponent randomness
                    pbc::Case c{"voronoi f" + std::to_string(feature) + " m" + std::to_string(metric) +
                                 " " + std::to_string(dim) + "D o" + std::to_string(outs),
                             kOpVoronoi, feature, 0, dim, metric, 0,
                             {0, 0, 0, 0, 2.0f, 0.8f, 1.5f, outs ? 0.7f : 1.0f},
                             {{0, 0}, {1, 1}, {2, 2}, {3, 1}},
                             {outs ? 4 : 0, outs ? 5 : 1, outs ? 7 : 3}};
                    pbc::check(c, rng, 6, 120, 0.5f);
                }
    const pbc::Case others[] = {
        {"magic depth 0", kOpMagic, 0, 0, 0, 0, 0, {0, 0, 0, 1.7f, 1.3f}, {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 3}},
        {"magic depth 0, no distortion", kOpMagic, 0, 0, 0, 0, 0, {0, 0, 0, 1.7f, 0.0f},
         {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 3}},
        {"magic depth 2", kOpMagic, 0, 0, 0, 2, 0, {0, 0, 0, 1.7f, -0.7f}, {{0, 0}, {1, 1}, {2, 2}}, {0, 2, 3}},
        {"magic depth 9", kOpMagic, 0, 0, 0, 9, 0, {0, 0, 0, 2.5f, 3.0f}, {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}},
        {"brick", kOpBrick, 0, 0, 0, 2, 1,
         {0, 0, 0, 0.8f, 0.1f, 0.3f, -0.4f, 0.9f, 0.5f, 1.5f, 1.2f, 0.2f, 2.0f, 0.05f, 0.3f, 0.1f,
          0.5f, 0.25f, 0.5f, 1.3f},
         {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 3}},
        {"brick, mortar colour from the position", kOpBrick, 0, 0, 0, 3, 2,
         {0, 0, 0, 0.8f, 0.1f, 0.3f, -0.4f, 0.9f, 0.5f, 0, 0, 0, 3.0f, 0.02f, 0.0f, -0.2f,
          0.4f, 0.2f, 0.3f, 0.7f},
         {{0, 0}, {1, 1}, {2, 2}, {9, 0}, {10, 1}, {11, 2}}, {0, 1, 2}},
    };
    for (const pbc::Case& c : others) pbc::check(c, rng, 25, 200, 0.6f);
}

// Vector Math (the operations with a rule), Mapping, Normalize, Gamma, Bright/Contrast and
// the Math operations added with them.
TEST(ProgramBoundRules, VectorMathMappingMathInsideRandomBoxes) {
    std::mt19937 rng(13);
    pbc::Tally tally;
    // in: a(3) b(3) c(3) scale
    for (int mode : {0, 1, 2, 3, 4, 5, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23,
                     24, 25, 26, 27, 28, 29})
        for (int bpos = 0; bpos < 2; ++bpos) {
            pbc::Case c{"vector math " + std::to_string(mode) + (bpos ? " b(p)" : ""),
                        kOpVectorMath,
                     mode, 0, 0, 0, 0, {0, 0, 0, 0.7f, -1.3f, 2.1f, 0.4f, 0.2f, -0.9f, -1.7f},
                     {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 3}};
            if (bpos) c.pos.insert(c.pos.end(), {{3, 2}, {4, 0}, {5, 1}});
            // divide by a b that reaches 0, snap to a varying increment, a tangent across a
            // pole, a power of a base that reaches below 0: no bound there
            // (snap and power need b constant: none where it is the position)
            const bool some = (mode == 3 && bpos) || mode == 26;
            const bool none = (mode == 15 || mode == 27) && bpos;
            if (mode == 27) c.clo = 1.5f;  // power: a base > 0 (the position), b constant
            pbc::check(c, rng, 15, 150, 0.6f, none ? 0 : some ? 2 : 1, &tally);
        }
    for (int mode = 0; mode <= 3; ++mode) {
        pbc::Case c{"mapping " + std::to_string(mode), kOpMapping, mode, 0, 0, 0, 0,
                 {0, 0, 0, 0.3f, -1.2f, 2.0f, 0.4f, -1.1f, 2.6f, 1.5f, -0.6f, 2.2f},
                 {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}};
        pbc::check(c, rng, 20, 150, 0.6f, 1, &tally);
    }
    std::printf("control: %d of %d boxes have samples outside the inner half's bound\n",
                tally.exceeded, tally.boxes);
    EXPECT_GT(tally.exceeded, tally.boxes / 2);
    const pbc::Case misc[] = {
        {"normalize", kOpNormalize, 0, 0, 0, 0, 0, {0, 0, 0}, {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}},
        {"gamma 2.2", kOpGamma, 0, 0, 0, 0, 0, {0, 0, 0, 2.2f}, {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}},
        {"gamma 0", kOpGamma, 0, 0, 0, 0, 0, {0, 0, 0, 0.0f}, {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}},
        {"bright contrast", kOpBrightContrast, 0, 0, 0, 0, 0, {0, 0, 0, 0.2f, 0.5f},
         {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}},
        {"bright contrast from p", kOpBrightContrast, 0, 0, 0, 0, 0, {0, 0, 0, -0.1f, -0.4f},
         {{0, 0}, {1, 1}, {2, 2}, {4, 1}}, {0, 1, 2}},
    };
    for (const pbc::Case& c : misc) pbc::check(c, rng, 20, 150, 0.6f, 1, &tally);
    // gamma < 0 over a colour reaching 0: no bound there
    pbc::check({"gamma -1.5", kOpGamma, 0, 0, 0, 0, 0, {0, 0, 0, -1.5f}, {{0, 0}, {1, 1}, {2, 2}},
              {0, 1, 2}}, rng, 30, 100, 0.6f, 2, &tally);
    // Math: a the position's x, b a constant or the position's y, c a constant
    struct M {
        int mode;
        float b, c;
        bool bpos;
        int bounded;
    } maths[] = {{6, 2.5f, 0, false, 2},   {6, 0.4f, 0, false, 2},  {8, 0, 0, false, 2},
                 {17, 0.8f, 0.7f, true, 1}, {18, 0.8f, 0.7f, true, 1}, {17, 0.5f, -0.3f, false, 1},
                 {22, 0, 0, false, 1},     {24, 1.3f, 0, false, 1}, {24, 0, 0, true, 1},
                 {25, 0.7f, 0, false, 1},  {25, -0.9f, 0, true, 1}, {26, 1.5f, -0.5f, false, 1},
                 {26, 0, 2.0f, true, 1},   {27, 0.3f, 0, false, 1}, {27, -0.45f, 0, false, 1},
                 {28, 0.6f, 0, false, 1},  {28, 0, 0, true, 1},     {32, 0, 0, false, 1},
                 {33, 0, 0, false, 1},     {35, 0, 0, true, 1},     {36, 0, 0, false, 1},
                 {37, 0, 0, false, 1},     {31, 0, 0, false, 2}};
    for (const M& mm : maths) {
        pbc::Case c{"math " + std::to_string(mm.mode) + (mm.bpos ? " b(p)" : ""), kOpMath,
                    mm.mode, 0,
                 0, 0, 0, {0, mm.b, mm.c}, {{0, 0}}, {0, 0, 0}};
        if (mm.bpos) c.pos.push_back({1, 1});
        pbc::check(c, rng, 30, 150, 0.6f, mm.bounded, &tally);
    }
}

// The smoke: density 8 x clamp(Noise fBm Fac(3 x position, detail 1) - 0.45, 0, 1)
// (tests/python/test_volume_hetero_bdpt.py noise_smoke) over its box. The old bound (Fac within
// 0.5 +- 0.982) made the majorant 8; now it lies within a few percent above the density's
// largest sample.
TEST(ProgramBoundRules, NoiseSmokeMajorantIsTight) {
    SceneInput in;
    std::vector<float> c(42, 0.0f);
    const float noise_in[8] = {0.0f, 3.0f, 1.0f, 0.5f, 2.0f, 0.0f, 1.0f, 0.0f};
    std::copy(noise_in, noise_in + 8, c.begin() + 3);
    c[31] = 0.45f;
    c[41] = 8.0f;
    std::vector<uint32_t> code;
    pbc::instr(code, kOpInput, 0, 0, 3, 0, 0);
    pbc::instr(code, kOpNoise, kNoiseFbm, 1 | 2, 3, 0, 20);
    pbc::instr(code, kOpCopy, 0, 0, 1, 20, 30);
    pbc::instr(code, kOpMath, 1, 1, 0, 30, 40);
    pbc::instr(code, kOpMath, 2, 0, 0, 40, 42);
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, 42u, uint32_t(kTargetDensity), 42u};
    MediumInput med;
    med.name = "smoke";
    med.sigma_s = vec3(0.85f, 0.8f, 0.7f);
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "smoke";
    mat.medium = 0;
    mat.volume_only = true;
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    const Vec3 lo{-0.6f, -0.5f, 0.2f}, hi{0.5f, 0.6f, 1.4f};
    in.meshes.push_back(lantern::test::box_mesh(lo, hi, 0));
    const auto t0 = std::chrono::steady_clock::now();
    HostScene scene(in);
    const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const SceneView& s = scene.view();
    const int32_t mi = s.material_medium[0];
    const Medium& m = s.media[mi];
    for (const std::string& w : scene.warnings()) EXPECT_EQ(w.find("no bound"), std::string::npos) << w;
    float seen = 0.0f;
    const int n = 64;
    for (int z = 0; z <= n; ++z)
        for (int y = 0; y <= n; ++y)
            for (int x = 0; x <= n; ++x) {
                const Vec3 p = lo + (hi - lo) * Vec3{float(x) / n, float(y) / n, float(z) / n};
                seen = std::max(seen, medium_density(s, m, mi, p, Vec3{0, 0, 1}));
            }
    std::printf("noise smoke: majorant's density %.3f (old bound 8), largest of 65^3 samples %.3f; "
                "scene build %.3f s\n", m.density_max, seen, build);
    EXPECT_GE(m.density_max, seen);
    EXPECT_LT(m.density_max, 1.2f * seen + 0.1f);
}

// Mix's blend modes, RGB / Float Curves, Hue/Saturation/Value, Separate / Combine HSV and HSL.
TEST(ProgramBoundRules, MixCurvesHsvInsideRandomBoxes) {
    std::mt19937 rng(17);
    // Mix in: fac(3) a(3) b(3); a from the position, b constant or the position permuted, the
    // factor constant or the position's z, clamped or not
    for (int mode : {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14})
        for (int variant = 0; variant < 3; ++variant) {
            pbc::Case c{"mix blend " + std::to_string(mode) + " v" + std::to_string(variant),
                        kOpMix,
                     mode, variant == 2 ? 3 : 1, 0, 0, 0,
                     {0.35f, 0, 0, 0, 0, 0, 0.6f, -0.4f, 1.3f},
                     {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}};
            if (variant >= 1) c.pos.insert(c.pos.end(), {{6, 2}, {7, 0}, {8, 1}});
            if (variant == 2) c.pos.push_back({0, 2});
            // dodge: a bound for a colour >= 0 (boxes there), none where it may be negative
            if (mode == 6) {
                pbc::check(c, rng, 10, 50, 0.6f, 2);
                c.clo = 0.7f;
            }
            pbc::check(c, rng, 15, 150, 0.6f);
        }
    // Curves: in fac colour(3); a table of 5 rows (r g b c) over [lo, hi] = [-1, 2] after them
    std::vector<float> table = {0.1f, 0.9f, -0.3f, 0, 0.8f, 0.2f, 0.5f, 0, 0.3f, 1.4f, 0.1f, 0,
                                0.9f, -0.2f, 0.7f, 0, 0.4f, 0.6f, 1.1f, 0, -1.0f, 2.0f};
    for (int mode = 0; mode <= 1; ++mode)
        for (int facpos = 0; facpos < 2; ++facpos) {
            std::vector<float> in = {0.7f, 0, 0, 0};
            in.insert(in.end(), table.begin(), table.end());  // the table at in[4]: const 12
            pbc::Case c{"curves " + std::to_string(mode) + (facpos ? " fac(p)" : ""), kOpCurves,
                        mode,
                     0, 0, 12, 5, in, {{1, 0}, {2, 1}, {3, 2}}, {0, mode ? 0 : 1, mode ? 0 : 2}};
            if (facpos) c.pos.push_back({0, 2});
            pbc::check(c, rng, 20, 150, 0.8f);
        }
    // HSV in: hue sat val fac colour(3)
    for (int facpos = 0; facpos < 2; ++facpos) {
        pbc::Case c{"hue saturation value", kOpHsv, 0, 0, 0, 0, 0,
                    {0.3f, 1.4f, 0.8f, 0.9f, 0, 0, 0}, {{4, 0}, {5, 1}, {6, 2}}, {0, 1, 2}};
        if (facpos) c.pos.push_back({3, 1});
        pbc::check(c, rng, 20, 150, 0.6f);
    }
    for (int op : {kOpSeparate, kOpCombine})
        for (int mode = 1; mode <= 2; ++mode) {
            pbc::Case c{std::string(op == kOpSeparate ? "separate" : "combine") +
                         (mode == 1 ? " hsv" : " hsl"),
                     op, mode, 0, 0, 0, 0, {0, 0, 0}, {{0, 0}, {1, 1}, {2, 2}},
                     {0, op == kOpSeparate ? 2 : 1, 2}};
            pbc::check(c, rng, 20, 150, 0.6f);
            if (op == kOpSeparate) {
                // its saturation needs components >= 0 (HSV) or in [0, 1] (HSL): boxes there
                // (and none elsewhere: unbounded)
                c.name += " (boxes in [0, 1])";
                c.outs[1] = 1;
                c.clo = 0.15f, c.chi = 0.85f;
                pbc::check(c, rng, 20, 150, 0.1f);
                c.clo = -2.0f, c.chi = -1.0f;
                pbc::check(c, rng, 5, 10, 0.5f, 0);
            }
        }
}
