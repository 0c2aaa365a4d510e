// The low-discrepancy sampler (core/sampler.h, core/rng.h): every dimension uniform, pairs
// stratified for any sample count, pixels and seeds decorrelated, the same key the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "core/sample_dims.h"
#include "integrator/pt.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// Pearson chi^2 of counts against equal expectations.
double chi2_equal(const std::vector<int>& counts, int n) {
    const double e = double(n) / counts.size();
    double c2 = 0.0;
    for (int c : counts) c2 += (c - e) * (c - e) / e;
    return c2;
}

// Upper 1e-4 tail of chi^2 with k degrees of freedom (Wilson-Hilferty).
double chi2_upper(int k) {
    const double z = 3.719;  // one-sided 1e-4
    const double a = 2.0 / (9.0 * k);
    return k * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

// Kolmogorov-Smirnov statistic of samples against U(0, 1).
double ks_uniform(std::vector<double> x) {
    std::sort(x.begin(), x.end());
    double d = 0.0;
    const double n = double(x.size());
    for (size_t i = 0; i < x.size(); ++i)
        d = std::max({d, (i + 1) / n - x[i], x[i] - i / n});
    return d;
}

// Sample `index` of pixel `pixel`: dimension `dim` as Rng hands it out (pairs start even).
float draw(uint64_t seed, uint64_t pixel, uint64_t index, uint32_t dim) {
    Rng r = Rng::for_pixel(seed, pixel, index);
    r.dim = dim;
    return r.uniform();
}

// Counts of n points in each of the 2^a x 2^b elementary intervals.
std::vector<int> cell_counts(const std::vector<Vec2>& p, int n, int a, int b) {
    std::vector<int> c(size_t(1) << (a + b), 0);
    for (int i = 0; i < n; ++i) {
        int x = int(p[i].x * float(1 << a)), y = int(p[i].y * float(1 << b));
        ++c[size_t(y) * (size_t(1) << a) + size_t(x)];
    }
    return c;
}

}  // namespace

// ---- Uniform: each dimension, across pixels (independent scrambles) and within one pixel ----

TEST(Sampler, EveryDimensionUniformAcrossPixels) {
    // 288 KS tests, each at 4e-6 (2.6 / sqrt(n)): 1e-3 for the family (Bonferroni)
    const int n = 20000;
    for (uint32_t dim = 0; dim < kQmcDims + 8; ++dim) {
        for (uint64_t index : {0ull, 1ull, 7ull, 1000ull}) {
            std::vector<double> x(n);
            for (int p = 0; p < n; ++p) x[p] = draw(42, uint64_t(p), index, dim);
            ASSERT_LT(ks_uniform(x), 2.6 / std::sqrt(double(n))) << "dim " << dim << " index "
                                                                  << index;
        }
    }
}

TEST(Sampler, EveryDimensionUniformWithinAPixel) {
    // a pixel's first n samples, 64 bins: chi^2 far below the tail (stratified), never above
    for (int n : {4096, 3000, 777}) {
        for (uint32_t dim = 0; dim < kQmcDims + 8; ++dim) {
            std::vector<int> c(64, 0);
            for (int i = 0; i < n; ++i) ++c[int(draw(7, 12345, uint64_t(i), dim) * 64.0f)];
            ASSERT_LT(chi2_equal(c, n), chi2_upper(63)) << "n " << n << " dim " << dim;
        }
    }
}

TEST(Sampler, NextGivesThirtyTwoUniformBits) {
    // every bit of next() is a fair coin across pixels, for the first and a late dimension
    const int n = 40000;
    for (uint32_t dim : {0u, 1u, 5u, kQmcDims + 3}) {
        int ones[32] = {};
        for (int p = 0; p < n; ++p) {
            Rng r = Rng::for_pixel(3, uint64_t(p), 17);
            r.dim = dim;
            uint32_t b = r.next();
            for (int k = 0; k < 32; ++k) ones[k] += (b >> k) & 1u;
        }
        for (int k = 0; k < 32; ++k)  // 5 sigma of a binomial(n, 1/2)
            EXPECT_NEAR(ones[k], n / 2, 5.0 * std::sqrt(n / 4.0)) << "dim " << dim << " bit " << k;
    }
}

// ---- Stratified: every pair's first n points of a pixel, n any count ----

TEST(Sampler, PairsFillElementaryIntervals) {
    // first 2^k samples: exactly one in each 2^a x 2^(k-a) interval, every a, every pair
    for (uint32_t g = 0; g < kQmcDims / 2; ++g) {
        for (uint64_t pixel : {0ull, 99ull}) {
            std::vector<Vec2> p(1 << 12);
            for (int i = 0; i < (1 << 12); ++i) {
                Rng r = Rng::for_pixel(11, pixel, uint64_t(i));
                r.dim = 2 * g;
                p[i] = r.uniform2();
            }
            for (int k = 0; k <= 12; ++k)
                for (int a = 0; a <= k; ++a)
                    for (int c : cell_counts(p, 1 << k, a, k - a))
                        ASSERT_EQ(c, 1) << "pair " << g << " k " << k << " a " << a;
        }
    }
}

TEST(Sampler, AnySampleCountIsBalanced) {
    // n = q 2^k + r: every elementary interval of volume 2^-k holds q or q + 1 of the first n
    for (int n : {3, 100, 1000, 3001}) {
        for (uint32_t g : {0u, 1u, 4u, kQmcDims / 2 - 1}) {
            std::vector<Vec2> p(n);
            for (int i = 0; i < n; ++i) {
                Rng r = Rng::for_pixel(5, 77, uint64_t(i));
                r.dim = 2 * g;
                p[i] = r.uniform2();
            }
            for (int k = 0; (1 << k) <= n; ++k) {
                const int q = n >> k;
                for (int a = 0; a <= k; ++a)
                    for (int c : cell_counts(p, n, a, k - a)) {
                        ASSERT_GE(c, q) << "n " << n << " pair " << g;
                        ASSERT_LE(c, q + 1) << "n " << n << " pair " << g;
                    }
            }
        }
    }
}

TEST(Sampler, SobolDimensionOneMatchesItsDirectionNumbers) {
    for (uint32_t i = 0; i < (1u << 16); ++i)
        ASSERT_EQ(sobol_dim1(i), sobol_dim1_reference(i)) << i;
    for (uint32_t k = 0, i = 12345u; k < 100000; ++k, i = i * 747796405u + 2891336453u)
        ASSERT_EQ(sobol_dim1(i), sobol_dim1_reference(i)) << i;
    // the first points: 1/2, 3/4, 1/4 (Joe & Kuo's dimension 2)
    EXPECT_EQ(sobol_dim1(1), 0x80000000u);
    EXPECT_EQ(sobol_dim1(2), 0xC0000000u);
    EXPECT_EQ(sobol_dim1(3), 0x40000000u);
}

TEST(Sampler, UniformTwoStartsAtAnEvenDimension) {
    Rng r = Rng::for_pixel(1, 2, 3);
    r.uniform();  // dim 0
    Vec2 u = r.uniform2();  // dims 2, 3
    EXPECT_EQ(r.dim, 4u);
    EXPECT_EQ(u.x, draw(1, 2, 3, 2));
    EXPECT_EQ(u.y, draw(1, 2, 3, 3));
}

// ---- Unbiased and better than random for any count; decorrelated pixels and seeds ----

TEST(Sampler, PixelEstimatesUnbiasedAndIndependent) {
    // f(x, y) = x y e^(x + y) integrates to 1 over the square. Per pixel: the mean of n samples
    // of one pair; over P pixels the grand mean is within 5 standard errors of 1, the spread
    // below Monte Carlo's, and neighbouring pixels' errors are uncorrelated.
    const int pixels = 4096;
    for (int n : {1, 16, 100}) {
        for (uint64_t seed : {1ull, 2ull}) {
            std::vector<double> err(pixels);
            for (int p = 0; p < pixels; ++p) {
                double s = 0.0;
                for (int i = 0; i < n; ++i) {
                    Rng r = Rng::for_pixel(seed, uint64_t(p), uint64_t(i));
                    r.dim = kCameraBounce0 + 2;
                    Vec2 u = r.uniform2();
                    s += u.x * u.y * std::exp(u.x + u.y);
                }
                err[p] = s / n - 1.0;
            }
            double m = 0.0, v = 0.0, c = 0.0;
            for (double e : err) m += e;
            m /= pixels;
            for (double e : err) v += (e - m) * (e - m);
            v /= pixels - 1;
            for (int p = 0; p + 1 < pixels; ++p) c += (err[p] - m) * (err[p + 1] - m);
            c /= (pixels - 1) * v;
            const double ef2 = (std::exp(2.0) - 1.0) / 4.0;  // E f^2 = ((e^2 - 1) / 4)^2
            const double mc_var = (ef2 * ef2 - 1.0) / n;
            EXPECT_LT(std::fabs(m), 5.0 * std::sqrt(v / pixels)) << "n " << n;
            if (n > 1) {
                EXPECT_LT(v, 0.5 * mc_var) << "n " << n;
            } else {
                EXPECT_NEAR(v, mc_var, 0.2 * mc_var) << "n 1";  // about 5 sd of a sample variance
            }
            EXPECT_LT(std::fabs(c), 5.0 / std::sqrt(double(pixels))) << "n " << n;
        }
    }
}

TEST(Sampler, DecorrelatedAcrossPixelsSeedsAndDimensions) {
    // correlation of the same (index, dim) between neighbouring pixels, between seeds, and of
    // neighbouring dims of one sample, over many draws: all within 5 / sqrt(n) of zero
    const int n = 40000;
    auto corr = [&](auto fa, auto fb) {
        double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
        for (int k = 0; k < n; ++k) {
            double a = fa(k), b = fb(k);
            sa += a, sb += b, sab += a * b, saa += a * a, sbb += b * b;
        }
        double ca = sab / n - sa / n * sb / n;
        return ca / std::sqrt((saa / n - sa / n * sa / n) * (sbb / n - sb / n * sb / n));
    };
    const double tol = 5.0 / std::sqrt(double(n));
    auto idx = [](int k) { return uint64_t(k % 200); };
    auto pix = [](int k) { return uint64_t(k / 200) * 2; };
    auto dm = [](int k) { return uint32_t((k * 7) % (kQmcDims + 4)); };
    EXPECT_LT(std::fabs(corr([&](int k) { return draw(9, pix(k), idx(k), dm(k)); },
                             [&](int k) { return draw(9, pix(k) + 1, idx(k), dm(k)); })),
              tol);
    EXPECT_LT(std::fabs(corr([&](int k) { return draw(9, pix(k), idx(k), dm(k)); },
                             [&](int k) { return draw(10, pix(k), idx(k), dm(k)); })),
              tol);
    for (uint32_t d : {0u, 1u, 2u, 7u}) {  // dims of one sample, within a pair and across
        EXPECT_LT(std::fabs(corr([&](int k) { return draw(9, uint64_t(k), 3, d); },
                                 [&](int k) { return draw(9, uint64_t(k), 3, d + 1); })),
                  tol)
            << "dim " << d;
    }
}

TEST(Sampler, SameKeySameBitsOtherKeysOtherBits) {
    Rng a = Rng::for_camera(5, 3, 4, 41), b = Rng::for_camera(5, 3, 4, 41);
    Rng c = Rng::for_pixel(5, 41 / 4, 3 * 4 + 41 % 4);  // the same sample, named directly
    Rng d = Rng::for_camera(6, 3, 4, 41), e = Rng::for_path(5, 3, 41);
    int differ_seed = 0, differ_kind = 0;
    for (int i = 0; i < 200; ++i) {
        uint32_t x = a.next();
        EXPECT_EQ(x, b.next());
        EXPECT_EQ(x, c.next());
        differ_seed += x != d.next();
        differ_kind += x != e.next();
    }
    EXPECT_EQ(differ_seed, 200);
    EXPECT_EQ(differ_kind, 200);
}

TEST(Sampler, ProgressiveIterationsDrawWhatOneBatchDraws) {
    // 16 iterations of 1 spp and one iteration of 16 spp: the same stream for every sample
    for (int64_t pixel : {0, 3, 4095}) {
        for (int s = 0; s < 16; ++s) {
            Rng a = Rng::for_camera(7, uint64_t(s), 1, pixel);
            Rng b = Rng::for_camera(7, 0, 16, pixel * 16 + s);
            Rng c = Rng::for_camera(7, uint64_t(s / 4), 4, pixel * 4 + s % 4);
            for (int d = 0; d < 80; ++d) {
                uint32_t x = a.next();
                ASSERT_EQ(x, b.next()) << "pixel " << pixel << " sample " << s << " dim " << d;
                ASSERT_EQ(x, c.next()) << "pixel " << pixel << " sample " << s << " dim " << d;
            }
        }
    }
}

TEST(Sampler, LightPathsOfAnIterationAreOneStratifiedSet) {
    // the iteration's first 2^10 light paths: the (pos) pair fills every elementary interval
    const int n = 1 << 10;
    for (uint64_t it : {0ull, 5ull, ~0ull}) {
        std::vector<Vec2> p(n);
        for (int i = 0; i < n; ++i) {
            Rng r = Rng::for_path(8, it, uint64_t(i));
            r.uniform();  // the light pick
            p[i] = r.uniform2();
        }
        for (int a = 0; a <= 10; ++a)
            for (int c : cell_counts(p, n, a, 10 - a)) ASSERT_EQ(c, 1) << "iteration " << it;
    }
}

// ---- The table (core/sample_dims.h) is what the stages draw ----

namespace {

// One pt path slot: generate, then shade one bounce on the floor; the stream's next dimension
// after each stage, rounded up to even (where the next pair starts).
struct OneSlot {
    Vec3 o, d, beta, rad, so, sd, sc;
    float tmin, tmax, prev_pdf, hit_t = 1.0f, stmax;
    Rng rng;
    int32_t depth, prim = 0;
    uint8_t alive, dropped, svalid;
    Vec2 uv{0.25f, 0.25f};
    PathState ps() {
        return PathState{&o, &d, &tmin, &tmax, &beta, &rad, &rng, &depth, &prev_pdf, &alive,
                         &dropped, &hit_t, &prim, &uv, &so, &sd, &stmax, &sc, &svalid};
    }
};

uint32_t next_pair(const Rng& r) { return r.dim + (r.dim & 1u); }

}  // namespace

TEST(SampleDims, CameraPathsDrawWhatTheTableSays) {
    for (bool aperture : {false, true}) {
        for (int rr_depth : {0, 1}) {
            SceneInput in;
            in.lens_radius = aperture ? 0.05f : 0.0f;
            MeshInput floor;
            floor.positions = {-5, -5, -2, 5, -5, -2, 5, 5, -2, -5, 5, -2};
            floor.indices = {0, 1, 2, 0, 2, 3};
            floor.material_ids = {0, 0};
            in.meshes.push_back(floor);
            in.materials.push_back(MaterialInput{});
            LightInput l;
            l.type = "point";
            l.position = {0, 0, 1};
            l.power = {10, 10, 10};
            in.lights.push_back(l);
            HostScene s(in);
            PtSettings st{8, rr_depth, 4, 3, 2};
            OneSlot slot;
            PathState ps = slot.ps();
            for (int64_t path : {0, 5, 17}) {
                pt_generate(s.view(), ps, st, 0, path);
                EXPECT_EQ(next_pair(slot.rng), camera_bounce_dim(aperture, 1));
                for (uint32_t bounce = 1; bounce <= 3; ++bounce) {
                    slot.depth = int32_t(bounce);
                    pt_shade(s.view(), ps, st, 0);
                    EXPECT_EQ(next_pair(slot.rng), camera_bounce_dim(aperture, bounce + 1))
                        << "aperture " << aperture << " rr " << rr_depth << " bounce " << bounce;
                }
            }
        }
    }
}
