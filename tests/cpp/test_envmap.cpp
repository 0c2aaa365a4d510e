// The world's environment map (scene/envmap.h): env_sample's pdf is env_pdf_w of the same
// direction, that pdf integrates to one over the sphere (equirectangular and mirror ball, with
// and without a rotating or stretching mapping), sampled directions follow it (chi-square on a
// coarse grid), the projections invert each other, and bad texels are cleaned with warnings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/rng.h"
#include "scene/envmap_build.h"
#include "scene/lights.h"

using namespace lantern;

namespace {

// A w x h map with a smooth sky, a bright "sun" texel and a black band.
EnvMapInput test_map(int w, int h, const char* projection) {
    EnvMapInput in;
    in.name = "test";
    in.width = w;
    in.height = h;
    in.projection = projection;
    in.pixels.resize(size_t(3 * w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = 0.2f + 0.8f * float(y) / float(h) + 0.3f * std::sin(0.3f * float(x));
            if (y == h / 3) v = 0.0f;
            if (x == w / 4 && y == 3 * h / 4) v = 500.0f;
            for (int c = 0; c < 3; ++c) in.pixels[size_t(3 * (y * w + x) + c)] = v * (1.0f + 0.1f * c);
        }
    return in;
}

// Rotation about z by a, then a stretch along x: a non-orthogonal mapping.
void set_mapping(EnvMapInput& in, float a, float sx) {
    const float c = std::cos(a), s = std::sin(a);
    const float m[9] = {sx * c, -sx * s, 0, s, c, 0, 0, 0, 1};
    for (int k = 0; k < 9; ++k) in.to_map[k] = m[k];
}

Vec3 sphere_dir(double u, double v) {  // uniform grid point on the sphere
    double z = 1.0 - 2.0 * v, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u;
    return {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
}

struct Built {
    EnvMapStorage st;
    std::vector<std::string> warnings;
};

// The pdf integrated in the map's (u, v), k x k midpoints per distribution cell, through this
// file's own projection, Jacobians and inverse mapping (none of envmap.h's): d omega_world =
// d omega_map |M d|^3 / |det M| for m = normalize(M d), and d omega_map = 2 pi^2 cos(elev) du dv
// (equirectangular) or 16 du dv inside the mirror ball's disk. A pdf that is right is p_cell x
// cells there, constant over each cell, so the midpoints sum it exactly.
double pdf_integral_in_map(const EnvMap& e, int k) {
    const float* a = e.to_map;
    double inv[9];  // from_map, in double, by the adjugate
    const double det = double(a[0]) * (double(a[4]) * a[8] - double(a[5]) * a[7]) -
                       double(a[1]) * (double(a[3]) * a[8] - double(a[5]) * a[6]) +
                       double(a[2]) * (double(a[3]) * a[7] - double(a[4]) * a[6]);
    inv[0] = (double(a[4]) * a[8] - double(a[5]) * a[7]) / det;
    inv[1] = (double(a[2]) * a[7] - double(a[1]) * a[8]) / det;
    inv[2] = (double(a[1]) * a[5] - double(a[2]) * a[4]) / det;
    inv[3] = (double(a[5]) * a[6] - double(a[3]) * a[8]) / det;
    inv[4] = (double(a[0]) * a[8] - double(a[2]) * a[6]) / det;
    inv[5] = (double(a[2]) * a[3] - double(a[0]) * a[5]) / det;
    inv[6] = (double(a[3]) * a[7] - double(a[4]) * a[6]) / det;
    inv[7] = (double(a[1]) * a[6] - double(a[0]) * a[7]) / det;
    inv[8] = (double(a[0]) * a[4] - double(a[1]) * a[3]) / det;
    const int nu = e.cells_x * k, nv = e.cells_y * k;
    double integral = 0.0;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double u = (i + 0.5) / nu, v = (j + 0.5) / nv;
            double m[3], jac;
            if (e.projection == kEnvMirrorBall) {
                const double nx = 2.0 * u - 1.0, nz = 2.0 * v - 1.0, r2 = nx * nx + nz * nz;
                if (r2 > 1.0) continue;
                const double ny = -std::sqrt(1.0 - r2);  // the ball's normal, seen from -Y
                m[0] = -2.0 * ny * nx;  // +Y reflected about it: y - 2 (n . y) n
                m[1] = 1.0 - 2.0 * ny * ny;
                m[2] = -2.0 * ny * nz;
                jac = 16.0;
            } else {  // Blender's: u = 0.5 - atan2(y, x) / 2 pi, v = 0.5 + asin(z) / pi
                const double phi = (0.5 - u) * 2.0 * kPi, elev = (v - 0.5) * kPi;
                m[0] = std::cos(elev) * std::cos(phi);
                m[1] = std::cos(elev) * std::sin(phi);
                m[2] = std::sin(elev);
                jac = 2.0 * kPi * kPi * std::cos(elev);
            }
            double d[3], len = 0.0;
            for (int r = 0; r < 3; ++r) {
                d[r] = inv[3 * r] * m[0] + inv[3 * r + 1] * m[1] + inv[3 * r + 2] * m[2];
                len += d[r] * d[r];
            }
            len = std::sqrt(len);
            const Vec3 dw{float(d[0] / len), float(d[1] / len), float(d[2] / len)};
            // |M dw| for the unit dw is 1 / len: M d = m has unit length
            const double to_world = 1.0 / (len * len * len * std::fabs(det));
            integral += env_pdf_w(e, dw) * jac * to_world / (double(nu) * nv);
        }
    return integral;
}

void check_pdf(const EnvMap& e, const std::string& what) {
    // integral of the pdf over the sphere by a fine stratified grid (4 pi / N per point)
    const int n = 1000;
    Pcg32 rng = Pcg32::for_path(1, 2, 3);
    double integral = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            Vec2 u = rng.uniform2();
            integral += env_pdf_w(e, sphere_dir((i + u.x) / n, (j + u.y) / n));
        }
    integral *= 4.0 * kPi / (double(n) * n);
    // exact: in the map's coordinates (measured 1 +- 3e-7: a 1 % error of a Jacobian or of a
    // cell's mass fails it by 100x); the sphere's grid, which needs no Jacobian, is a Monte
    // Carlo estimate (the sun texel at 500x and the pdf's 1 / cos(elev) at the map's poles):
    // measured within 0.31 % of the map's integral in every case here
    const int k = std::max(1, 256 / std::max(e.cells_x, e.cells_y));
    const double in_map = pdf_integral_in_map(e, k);
    if (e.projection == kEnvMirrorBall) {
        // cells across the ball's rim lose the samples that land outside it: at most a few %
        EXPECT_LT(in_map, 1.0 + 1e-4) << what;
        EXPECT_GT(in_map, 0.93) << what;
    } else {
        EXPECT_NEAR(in_map, 1.0, 1e-4) << what;
    }
    EXPECT_NEAR(integral, in_map, 5e-3) << what << ": the sphere's grid against the map's";
    // samples: pdf agrees with env_pdf_w; radiance with env_radiance
    for (int k = 0; k < 20000; ++k) {
        Vec3 d, le;
        float pdf;
        if (!env_sample(e, rng.uniform2(), &d, &pdf, &le)) continue;
        float ref = env_pdf_w(e, d);
        ASSERT_NEAR(pdf, ref, 2e-3f * ref + 1e-6f) << what;
        Vec3 l2 = env_radiance(e, d);
        ASSERT_NEAR(le.x, l2.x, 2e-3f * l2.x + 1e-5f) << what;
    }
}

// Chi-square of sampled directions against the pdf on a coarse (cos theta, phi) grid.
void check_chi2(const EnvMap& e, const std::string& what) {
    const int nz = 16, nphi = 32, fine = 16, samples = 400000;
    std::vector<double> expected(nz * nphi, 0.0), observed(nz * nphi, 0.0);
    for (int a = 0; a < nz * fine; ++a)
        for (int b = 0; b < nphi * fine; ++b) {
            double v = (a + 0.5) / (nz * fine), u = (b + 0.5) / (nphi * fine);
            double cell = 4.0 * kPi / (double(nz) * fine * nphi * fine);
            expected[(a / fine) * nphi + b / fine] +=
                env_pdf_w(e, sphere_dir(u, v)) * cell * samples;
        }
    Pcg32 rng = Pcg32::for_path(9, 9, 9);
    for (int k = 0; k < samples; ++k) {
        Vec3 d, le;
        float pdf;
        if (!env_sample(e, rng.uniform2(), &d, &pdf, &le)) continue;
        double v = (1.0 - d.z) / 2.0, u = std::atan2(d.y, d.x) / (2.0 * kPi);
        u -= std::floor(u);
        int a = std::min(int(v * nz), nz - 1), b = std::min(int(u * nphi), nphi - 1);
        observed[a * nphi + b] += 1.0;
    }
    double chi2 = 0.0;
    int dof = 0;
    for (size_t k = 0; k < expected.size(); ++k) {
        if (expected[k] < 5.0) continue;  // pooled away: cells too small for the test
        chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
        ++dof;
    }
    // mean dof, sd sqrt(2 dof): 5 sd is far beyond chance; the grid pdf is itself a
    // quadrature (fine = 8), so allow its ~1e-3 relative error on top
    EXPECT_LT(chi2, dof + 5.0 * std::sqrt(2.0 * dof) + 2e-6 * samples) << what;
}

}  // namespace

TEST(EnvMap, ProjectionsInvert) {
    Pcg32 rng = Pcg32::for_path(4, 5, 6);
    for (int p : {int(kEnvEquirect), int(kEnvMirrorBall)})
        for (int k = 0; k < 2000; ++k) {
            Vec2 uv = rng.uniform2();
            uv = {0.02f + 0.96f * uv.x, 0.02f + 0.96f * uv.y};
            float jac;
            Vec3 d = env_uv_to_direction(p, uv, &jac);
            if (!(jac > 0.0f)) continue;
            Vec2 back = env_direction_to_uv(p, d);
            EXPECT_NEAR(back.x, uv.x, 1e-4f) << p;
            EXPECT_NEAR(back.y, uv.y, 1e-4f) << p;
        }
    // Blender's equirectangular: +X at the centre, +Y at u = 0.25, up at the top
    Vec2 c = env_direction_to_uv(kEnvEquirect, vec3(1, 0, 0));
    EXPECT_NEAR(c.x, 0.5f, 1e-6f);
    EXPECT_NEAR(c.y, 0.5f, 1e-6f);
    EXPECT_NEAR(env_direction_to_uv(kEnvEquirect, vec3(0, 1, 0)).x, 0.25f, 1e-6f);
    EXPECT_NEAR(env_direction_to_uv(kEnvEquirect, vec3(0, 0, 1)).y, 1.0f, 1e-6f);
    // mirror ball: the ball's centre reflects the direction back towards the viewer (-Y)
    Vec2 m = env_direction_to_uv(kEnvMirrorBall, vec3(0, -1, 0));
    EXPECT_NEAR(m.x, 0.5f, 1e-6f);
    EXPECT_NEAR(m.y, 0.5f, 1e-6f);
}

TEST(EnvMap, PdfMatchesSamplesAndIntegratesToOne) {
    for (const char* proj : {"equirectangular", "mirror_ball"})
        for (int mapping = 0; mapping < 3; ++mapping) {
            EnvMapInput in = test_map(64, proj[0] == 'm' ? 64 : 32, proj);
            if (mapping == 1) set_mapping(in, 0.7f, 1.0f);
            if (mapping == 2) set_mapping(in, -1.1f, 1.8f);
            Built b;
            build_envmap(in, b.st, b.warnings);
            ASSERT_GT(b.st.view.width, 0);
            std::string what = std::string(proj) + " mapping " + std::to_string(mapping);
            check_pdf(b.st.view, what);
            // negative control: the mapping's Jacobian 1 % off must fail the exact integral
            EnvMap off = b.st.view;
            off.det *= 1.01f;
            EXPECT_GT(std::fabs(pdf_integral_in_map(off, 4) - pdf_integral_in_map(b.st.view, 4)),
                      50.0 * 1e-4) << what;
            // chi-square on a smooth map: the grid's quadrature of a sharp sun would dominate
            EnvMapInput smooth = in;
            for (size_t k = 0; k < smooth.pixels.size(); ++k)
                smooth.pixels[k] = std::min(smooth.pixels[k], 2.0f) + 0.05f;
            Built c;
            build_envmap(smooth, c.st, c.warnings);
            check_chi2(c.st.view, what);
        }
}

TEST(EnvMap, LargeMapsUseCoarserCells) {
    EnvMapInput in = test_map(4100, 9, "equirectangular");
    Built b;
    build_envmap(in, b.st, b.warnings);
    EXPECT_EQ(b.st.view.cells_x, 2048);
    EXPECT_EQ(b.st.view.cells_y, 9);
    check_pdf(b.st.view, "4100x9");
}

TEST(EnvMap, OneTexelIsAConstantWorld) {
    EnvMapInput in;
    in.width = in.height = 1;
    in.pixels = {0.5f, 0.25f, 2.0f};
    in.strength = {2.0f, 2.0f, 2.0f};
    Built b;
    build_envmap(in, b.st, b.warnings);
    ASSERT_EQ(b.st.view.width, 1);
    EXPECT_NEAR(b.st.mean.x, 1.0f, 1e-5f);
    EXPECT_NEAR(b.st.mean.z, 4.0f, 1e-5f);
    Pcg32 rng = Pcg32::for_path(1, 1, 1);
    for (int k = 0; k < 100; ++k) {
        Vec3 d = sphere_dir(rng.uniform(), rng.uniform());
        EXPECT_NEAR(env_radiance(b.st.view, d).y, 0.5f, 1e-6f);
    }
    check_pdf(b.st.view, "1x1");
}

TEST(EnvMap, BadTexelsAreCleanedWithWarnings) {
    EnvMapInput in = test_map(16, 8, "equirectangular");
    in.pixels[0] = NAN;
    in.pixels[4] = INFINITY;
    in.pixels[8] = -3.0f;
    Built b;
    build_envmap(in, b.st, b.warnings);
    ASSERT_EQ(b.warnings.size(), 2u);
    EXPECT_NE(b.warnings[0].find("NaN or infinite"), std::string::npos);
    EXPECT_NE(b.warnings[1].find("negative"), std::string::npos);
    for (float v : b.st.texels) {
        EXPECT_TRUE(std::isfinite(v));
        EXPECT_GE(v, 0.0f);
    }
    // a singular mapping (scale 0): the identity, with a warning
    EnvMapInput sing = test_map(16, 8, "equirectangular");
    set_mapping(sing, 0.0f, 0.0f);
    Built c;
    build_envmap(sing, c.st, c.warnings);
    ASSERT_GE(c.warnings.size(), 1u);
    EXPECT_NE(c.warnings[0].find("singular"), std::string::npos) << c.warnings[0];
    EXPECT_EQ(c.st.view.to_map[0], 1.0f);
    // all black: no map (no light)
    EnvMapInput black = test_map(4, 2, "equirectangular");
    for (float& v : black.pixels) v = 0.0f;
    Built d;
    build_envmap(black, d.st, d.warnings);
    EXPECT_EQ(d.st.view.width, 0);
    // a size that does not match its pixels is the exporter's bug: a clear error
    EnvMapInput wrong = test_map(4, 2, "equirectangular");
    wrong.pixels.pop_back();
    Built e;
    EXPECT_THROW(build_envmap(wrong, e.st, e.warnings), std::invalid_argument);
}

// The distribution is built once per content (a viewport restart makes a new HostScene from the
// same export): the same map returns the same storage, and its warnings again; a changed
// texel, strength or mapping builds anew.
TEST(EnvMap, BuiltOncePerContent) {
    EnvMapInput in = test_map(64, 32, "equirectangular");
    in.pixels[7] = -1.0f;  // one warning, to be repeated on a cache hit
    std::vector<std::string> w1, w2, w3, w4;
    const int64_t before = envmap_builds();
    auto a = build_envmap_cached(in, w1);
    auto b = build_envmap_cached(in, w2);
    EXPECT_EQ(a.get(), b.get());
    EXPECT_EQ(envmap_builds(), before + 1);
    ASSERT_EQ(w1.size(), 1u);
    EXPECT_EQ(w1, w2);
    in.pixels[100] += 1.0f;
    auto c = build_envmap_cached(in, w3);
    EXPECT_NE(c.get(), a.get());
    in.strength = Vec3{2.0f, 2.0f, 2.0f};
    auto d = build_envmap_cached(in, w4);
    EXPECT_NE(d.get(), c.get());
    EXPECT_EQ(envmap_builds(), before + 3);
    EXPECT_GT(d->mean.x, c->mean.x * 1.99f);  // the new strength, not the cached build's
    EXPECT_EQ(b->view.texels, b->texels.data());  // the view still points into its storage
}
