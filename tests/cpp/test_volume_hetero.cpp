// Heterogeneous media's tracking (scene/medium_hetero.h, docs/volumes.md) against exact values:
// a density that is a known function of position (the x coordinate, a node program reading the
// position), so that along +x from 0 the transmittance is exp(-sigma_t x^2 / 2) and the
// collision density sigma_s(x) T(x). Ratio tracking's mean per channel, and spectral tracking's
// weighted collision density per distance bin and its pass weight (a chi-square over bins),
// with the majorant above the density and below it (negative null weights); each with a
// negative control that must fail.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "scene/medium_hetero.h"

using namespace lantern;

namespace {

// A SceneView whose one program returns the position's x (kOpInput, mode 0) and one medium of
// density x with coefficients per unit density sigma_a, sigma_s.
struct RampScene {
    NodeInstr code[1];
    MaterialProgram prog;
    Medium medium{};
    SceneView view{};
    RampScene(Vec3 sigma_a, Vec3 sigma_s, float majorant) {
        code[0] = NodeInstr{};
        code[0].op = kOpInput;
        code[0].mode = 0;
        code[0].dim = 3;
        code[0].in = 0;
        code[0].out = 0;
        prog = MaterialProgram{0, 1, 0, 0, kTargetDensity, 0};
        medium.sigma_a = sigma_a;
        medium.sigma_s = sigma_s;
        medium.sigma_t = sigma_a + sigma_s;
        medium.scatters = max_component(sigma_s) > 0.0f ? 1u : 0u;
        medium.hetero = 1;
        medium.density_prog = 0;
        medium.majorant = majorant;
        view.programs = &prog;
        view.program_code = code;
        view.media = &medium;
        view.num_media = 1;
    }
};

const Vec3 kO{0.0f, 0.3f, -0.2f}, kD{1.0f, 0.0f, 0.0f};

double expected_tr(double sigma, double x) { return std::exp(-sigma * x * x / 2.0); }

// sum over bins and channels of z^2 (z: the estimate's mean minus `scale` x the exact value,
// over its standard error), and the number of terms
struct Chi {
    double sum = 0.0;
    int n = 0;
};

// Spectral tracking from x = 0 to L, beta (0.9, 0.5, 0.2): E[W 1{scatter in bin}] =
// int_bin sigma_s x T(x) dx = sigma_s / sigma_t (T(a) - T(b)); E[W 1{pass}] = T(L).
Chi spectral_chi(const RampScene& sc, float L, int bins, int n, double scale) {
    const Vec3 beta{0.9f, 0.5f, 0.2f};
    std::vector<double> s(size_t(bins + 1) * 3, 0.0), s2(size_t(bins + 1) * 3, 0.0);
    for (int k = 0; k < n; ++k) {
        Rng path = Rng::for_path(17, 0, uint64_t(k));
        Rng r = medium_tracking_rng(path, 0);
        const HeteroStep st = medium_track(
            sc.view, sc.medium, 0, kO, kD, L, beta, r, [](float, Vec3, float) {},
            [](float, float, Vec3) {});
        int b = bins;
        if (st.scattered) b = std::min(int(st.t / L * float(bins)), bins - 1);
        const float w[3] = {st.weight.x, st.weight.y, st.weight.z};
        for (int c = 0; c < 3; ++c) {
            s[size_t(b) * 3 + size_t(c)] += w[c];
            s2[size_t(b) * 3 + size_t(c)] += double(w[c]) * w[c];
        }
    }
    Chi chi;
    const float sa[3] = {sc.medium.sigma_a.x, sc.medium.sigma_a.y, sc.medium.sigma_a.z};
    const float ss[3] = {sc.medium.sigma_s.x, sc.medium.sigma_s.y, sc.medium.sigma_s.z};
    for (int b = 0; b <= bins; ++b)
        for (int c = 0; c < 3; ++c) {
            const double st = double(sa[c]) + ss[c];
            double want;
            if (b == bins) {
                want = expected_tr(st, L);
            } else {
                const double x0 = double(L) * b / bins, x1 = double(L) * (b + 1) / bins;
                want = ss[c] / st * (expected_tr(st, x0) - expected_tr(st, x1));
            }
            const double mean = s[size_t(b) * 3 + size_t(c)] / n;
            const double var = s2[size_t(b) * 3 + size_t(c)] / n - mean * mean;
            const double se = std::sqrt(std::max(var, 0.0) / n);
            if (!(se > 0.0)) continue;
            const double z = (mean - scale * want) / se;
            chi.sum += z * z;
            ++chi.n;
        }
    return chi;
}

}  // namespace

TEST(MediumHetero, RatioTrackingMatchesTransmittanceOfARamp) {
    const float L = 1.5f;
    // sigma_t = density x (0.4, 1.0, 2.0) over x in [0, 1.5]: at most 3 / m
    for (float majorant : {4.0f, 2.0f}) {  // above the extinction; below it over a third
        RampScene sc(vec3(0.1f, 0.3f, 0.5f), vec3(0.3f, 0.7f, 1.5f), majorant);
        const int n = 200000;
        double s[3] = {}, s2[3] = {};
        for (int k = 0; k < n; ++k) {
            Rng path = Rng::for_path(5, 0, uint64_t(k));
            Rng r = medium_tracking_rng(path, 1);
            const Vec3 t = medium_ratio_tracking(sc.view, sc.medium, 0, kO, kD, L, r);
            const double v[3] = {t.x, t.y, t.z};
            for (int c = 0; c < 3; ++c) {
                s[c] += v[c];
                s2[c] += v[c] * v[c];
            }
        }
        const double st[3] = {0.4, 1.0, 2.0};
        for (int c = 0; c < 3; ++c) {
            const double mean = s[c] / n, se = std::sqrt((s2[c] / n - mean * mean) / n);
            const double want = expected_tr(st[c], L);
            EXPECT_LT(std::fabs(mean - want), 4.0 * se)
                << "majorant " << majorant << " channel " << c << ": " << mean << " vs " << want
                << " (se " << se << ")";
            // negative control: a transmittance of 3 % more extinction is told apart
            EXPECT_GT(std::fabs(mean - expected_tr(st[c] * 1.03, L)), 4.0 * se)
                << "majorant " << majorant << " channel " << c;
        }
    }
}

TEST(MediumHetero, SpectralTrackingCollisionDensityChiSquare) {
    const float L = 1.5f;
    const int bins = 12, n = 300000;
    for (float majorant : {4.0f, 2.0f}) {
        RampScene sc(vec3(0.1f, 0.3f, 0.5f), vec3(0.3f, 0.7f, 1.5f), majorant);
        const Chi ok = spectral_chi(sc, L, bins, n, 1.0);
        // chi-square of n terms: mean n, sd sqrt(2n); 5 sd above the mean is p < 1e-5
        EXPECT_LT(ok.sum, ok.n + 5.0 * std::sqrt(2.0 * ok.n))
            << "majorant " << majorant << ": chi2 " << ok.sum << " over " << ok.n;
        // negative control: every expectation 3 % off
        const Chi bad = spectral_chi(sc, L, bins, n, 1.03);
        EXPECT_GT(bad.sum, bad.n + 5.0 * std::sqrt(2.0 * bad.n))
            << "majorant " << majorant << ": chi2 " << bad.sum << " over " << bad.n;
    }
}

TEST(MediumHetero, ZeroMajorantPassesUnweighted) {
    RampScene sc(vec3(0.0f), vec3(0.0f), 0.0f);
    Rng path = Rng::for_path(1, 0, 0);
    Rng r = medium_tracking_rng(path, 0);
    const HeteroStep st = medium_track(sc.view, sc.medium, 0, kO, kD, 2.0f, vec3(1.0f), r,
                                       [](float, Vec3, float) {}, [](float, float, Vec3) {});
    EXPECT_FALSE(st.scattered);
    EXPECT_EQ(st.weight.x, 1.0f);
}
