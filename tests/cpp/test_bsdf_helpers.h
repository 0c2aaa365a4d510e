// Shared checks for the lobe tests (tests/cpp/test_bsdf_*.cpp): a chi-square goodness-of-fit of
// a sampler against a pdf over the sphere, binned in (cos theta, phi) with low-expectation bins
// merged, and small helpers. The pdf is integrated per bin with a midpoint rule on a sub-grid.
// MeanSe / mean_matches: a Monte Carlo mean against an exact value with a tolerance from its own
// standard error, and its +-1 % negative controls (tests/README.md).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/rng.h"

namespace lantern::test {

struct Chi2Result {
    double chi2 = 0.0;
    int dof = 0;
    double p_value = 0.0;
    double pdf_mass = 0.0;    // integral of the pdf over the sphere (pdf_mass_on_sphere)
    double valid_frac = 0.0;  // fraction of sample() calls that returned a direction
    double valid_se = 0.0;    // its standard error (binomial)
    bool impossible = false;  // samples landed where the pdf has no mass at all
};

// Upper tail of the chi-square distribution, Wilson-Hilferty approximation (good for dof >~ 20).
inline double chi2_upper_tail(double x, int dof) {
    double k = dof;
    double z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
    return 0.5 * std::erfc(z / std::sqrt(2.0));
}

// The integral of pdf over the sphere: the midpoint rule in (theta, phi), d omega = sin theta
// d theta d phi, 768 x 768 points. In theta, not in cos theta, so a lobe about the pole keeps
// its points: a GGX pdf of alpha 0.2 spans ~25 of them, and the rule's error stays below 1e-3
// (the chi-square bins' own 32 x 32 x 36 points were 1 % off there).
inline double pdf_mass_on_sphere(const std::function<double(Vec3)>& pdf, int n = 768) {
    double acc = 0.0;
    const double dt = kPi / n, dp = 2.0 * kPi / n;
    for (int i = 0; i < n; ++i) {
        const double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
        for (int j = 0; j < n; ++j) {
            const double phi = (j + 0.5) * dp;
            acc += pdf(vec3(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct))) * st;
        }
    }
    return acc * dt * dp;
}

// The chi-square test's mass check: the pdf integrates to the fraction of samples returned (1
// where every call returns one), within 4.5 of that fraction's se plus the quadrature's 2e-4
// (measured at most 3.5e-5 on the lobes here): a pdf 1 % off fails (200,000 samples: at most
// 0.5 % + 0.02 %).
inline bool pdf_mass_agrees(const Chi2Result& r) {
    return std::fabs(r.pdf_mass - r.valid_frac) <= 4.5 * r.valid_se + 2e-4;
}
inline void expect_pdf_mass(const Chi2Result& r, const std::string& what) {
    EXPECT_TRUE(pdf_mass_agrees(r))
        << what << ": pdf mass " << r.pdf_mass << " against the samples' " << r.valid_frac
        << " (se " << r.valid_se << ")";
}

// sample(u, uc, &wi) -> bool; pdf(wi) -> solid-angle density of sample() producing wi.
inline Chi2Result chi2_sphere(const std::function<bool(Vec2, float, Vec3*)>& sample,
                              const std::function<double(Vec3)>& pdf, int n_samples,
                              uint64_t seed = 1, int n_theta = 32, int n_phi = 32, int sub = 6) {
    const int bins = n_theta * n_phi;
    auto bin_of = [&](Vec3 w) {
        float z = clampf(w.z, -1.0f, 1.0f);
        int t = std::min(n_theta - 1, int((z + 1.0f) * 0.5f * n_theta));
        float phi = atan2f(w.y, w.x);
        if (phi < 0.0f) phi += 2.0f * kPi;
        int p = std::min(n_phi - 1, int(phi / (2.0f * kPi) * n_phi));
        return t * n_phi + p;
    };
    Chi2Result r;
    std::vector<double> observed(bins, 0.0), expected(bins, 0.0);
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    int valid = 0;
    for (int i = 0; i < n_samples; ++i) {
        Vec2 u = rng.uniform2();
        float uc = rng.uniform();
        Vec3 wi;
        if (!sample(u, uc, &wi)) continue;
        ++valid;
        observed[bin_of(wi)] += 1.0;
    }
    r.valid_frac = double(valid) / n_samples;
    // expected mass: dw = dz dphi, so integrate pdf on the (z, phi) rectangle of each bin
    const double dz = 2.0 / n_theta, dphi = 2.0 * kPi / n_phi;
    for (int t = 0; t < n_theta; ++t)
        for (int p = 0; p < n_phi; ++p) {
            double acc = 0.0;
            for (int i = 0; i < sub; ++i)
                for (int j = 0; j < sub; ++j) {
                    double z = -1.0 + dz * (t + (i + 0.5) / sub);
                    double phi = dphi * (p + (j + 0.5) / sub);
                    double s = std::sqrt(std::max(0.0, 1.0 - z * z));
                    acc += pdf(vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(z)));
                }
            expected[t * n_phi + p] = acc * dz * dphi / (sub * sub);
        }
    r.pdf_mass = pdf_mass_on_sphere(pdf);
    r.valid_se = std::sqrt(std::max(r.valid_frac * (1.0 - r.valid_frac), 1.0 / n_samples) /
                           n_samples);
    for (double& e : expected) e *= n_samples;
    // merge bins expecting fewer than 5 samples (smallest first) until each pool expects >= 5
    std::vector<int> order(bins);
    for (int i = 0; i < bins; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });
    double pool_e = 0.0, pool_o = 0.0;
    int cells = 0;
    for (int idx : order) {
        double e = expected[idx], o = observed[idx];
        if (e <= 0.0 && o <= 0.0) continue;
        // bins the quadrature sees as empty (e.g. cut by the visibility edge) join the pool too
        if (e < 5.0 || pool_e > 0.0) {
            pool_e += e;
            pool_o += o;
            if (pool_e < 5.0) continue;
            e = pool_e;
            o = pool_o;
            pool_e = pool_o = 0.0;
        }
        r.chi2 += (o - e) * (o - e) / e;
        ++cells;
    }
    if (pool_o > 0.0 && pool_e <= 0.0) r.impossible = true;
    if (pool_e > 0.0) {  // leftover pool: count it as one more cell
        r.chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        ++cells;
    }
    r.dof = std::max(1, cells - 1);
    r.p_value = r.impossible ? 0.0 : chi2_upper_tail(r.chi2, r.dof);
    return r;
}

inline Vec3 dir_from_angles(float theta, float phi) {
    return vec3(sinf(theta) * cosf(phi), sinf(theta) * sinf(phi), cosf(theta));
}

inline bool finite_eval(Vec3 f, float a, float b) {
    return is_finite(f) && is_finite(a) && is_finite(b);
}

// ---- A Monte Carlo mean against an exact value ----

// The mean of independent samples and its standard error.
struct MeanSe {
    double sum = 0.0, sum2 = 0.0;
    long n = 0;
    void add(double x) {
        sum += x;
        sum2 += x * x;
        ++n;
    }
    double mean() const { return n > 0 ? sum / double(n) : 0.0; }
    double se() const {
        if (n < 2) return 0.0;
        double m = mean(), var = std::max(0.0, (sum2 / double(n) - m * m) * n / (n - 1.0));
        return std::sqrt(var / double(n));
    }
};

// |z| that a fair comparison of n_tests normal z-scores exceeds with probability alpha in all
// (Bonferroni: the 1 - alpha / (2 n) normal quantile, by bisection on erfc).
inline double z_bonferroni(int n_tests, double alpha = 1e-3) {
    double target = alpha / n_tests, lo = 0.0, hi = 40.0;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (std::erfc(mid / std::sqrt(2.0)) > target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// m's mean agrees with `expected` when |mean - expected| <= cap |expected| + z se (cap: a
// stated systematic difference, 1e-4 for an exact case; z: z_bonferroni over the test's
// comparisons), and the negative controls, the mean `control` (1 %) higher and lower, must
// not (a case whose noise cannot afford 1 % states its level; 0: none, for a stated defect).
inline ::testing::AssertionResult mean_matches(const MeanSe& m, double expected, double z,
                                               double cap = 1e-4, double control = 0.01) {
    double allowed = cap * std::fabs(expected) + z * m.se();
    char buf[256];
    std::snprintf(buf, sizeof buf, "mean %.6f +- %.6f against %.6f (%+.4f%%, allowed %.4f%%)",
                  m.mean(), m.se(), expected, 100.0 * (m.mean() - expected) / expected,
                  100.0 * allowed / std::fabs(expected));
    if (!(std::fabs(m.mean() - expected) <= allowed))
        return ::testing::AssertionFailure() << buf;
    for (double bias : {control, -control})
        if (control > 0.0 && std::fabs(m.mean() * (1.0 + bias) - expected) <= allowed)
            return ::testing::AssertionFailure()
                   << "negative control " << 100.0 * bias << " % passed, so the test cannot see "
                   << "it: " << buf;
    return ::testing::AssertionSuccess() << buf;
}

// An energy bound: m's mean (a directional albedo) is at most `bound` when mean <= bound (1 +
// cap) + z se, one-sided (cap: a stated systematic gain, 0 where the bound holds exactly). Its
// control, the mean `control` (1 %) higher, can only fail where the albedo lies within about
// `control` of the bound; *caught counts the cases where it did, and a test asserts that its
// most reflective cases were among them (a 1 % energy gain there fails) or says why none can be.
// LANTERN_TEST_PRINT=1 prints every case.
inline ::testing::AssertionResult mean_at_most(const MeanSe& m, double bound, double z,
                                               double cap = 0.0, int* caught = nullptr,
                                               double control = 0.01) {
    const double allowed = bound * (1.0 + cap) + z * m.se();
    char buf[256];
    std::snprintf(buf, sizeof buf, "mean %.6f +- %.6f, at most %.6f (allowed %.6f)", m.mean(),
                  m.se(), bound, allowed);
    if (std::getenv("LANTERN_TEST_PRINT")) std::printf("%s\n", buf);
    if (!(m.mean() <= allowed)) return ::testing::AssertionFailure() << buf;
    if (caught && m.mean() * (1.0 + control) > allowed) ++*caught;
    return ::testing::AssertionSuccess() << buf;
}

}  // namespace lantern::test
