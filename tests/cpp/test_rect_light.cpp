// Solid-angle sampling of rectangular area lights (lights.h spherical_rect): sample_light's
// directions against light_pdf_w by chi-square over the sphere, for receivers under, beside and
// near the plane of a large rotated rectangle, binned on the light (negative controls: the same
// samples against the area pdf, and area samples against the solid-angle pdf); the irradiance under the centre
// against the analytic form factor; the estimator's variance against area sampling's; and the
// area fallback near the plane and far away.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/rng.h"
#include "integrator/light_path.h"
#include "scene/lights.h"
#include "scene/scene.h"
#include "test_bsdf_helpers.h"

using namespace lantern;

namespace {

// A 1.9 x 1.2 m rectangle 1 m above the origin, emitting downwards, turned 0.4 rad about Z and
// tilted 0.3 rad about X (an arbitrary frame, so axis-aligned bins do not flatter it).
HostScene rect_scene(float size_x = 1.9f, float size_y = 1.2f) {
    SceneInput in;
    LightInput l;
    l.type = "area";
    l.shape = "rectangle";
    l.size_x = size_x;
    l.size_y = size_y;
    l.power = {10, 10, 10};
    const float a = 0.4f, b = 0.3f, ca = std::cos(a), sa = std::sin(a), cb = std::cos(b),
                sb = std::sin(b);
    // R = Rz(a) * Rx(b), translation (0.1, -0.2, 1)
    const float m[16] = {ca, -sa * cb, sa * sb,  0.1f,  //
                         sa, ca * cb,  -ca * sb, -0.2f,  //
                         0,  sb,       cb,       1.0f,   //
                         0,  0,        0,        1};
    for (int i = 0; i < 16; ++i) l.to_world[i] = m[i];
    in.lights.push_back(l);
    return HostScene(in);
}

struct RectChi2 {
    double chi2 = 0.0, p_value = 0.0, mass = 0.0;
    int dof = 0, valid = 0;
};

// Chi-square of a sampler of points on rectangle l (seen from p) against a solid-angle pdf,
// binned on the rectangle itself (n_cells x n_cells), so that no bin is cut by the light's
// edge: a bin expects the integral of pdf_w(p -> q) cos_l / d^2 over its area (8 x 8 midpoint
// sub-grid of a smooth integrand); mass is that integral over the whole light (1 for a pdf).
// area_samples: uniform area samples instead of sample_light's; area_pdf: the area pdf
// instead of light_pdf_w.
RectChi2 chi2_rect(const Light& l, const SceneView& v, Vec3 p, bool area_samples,
                   bool area_pdf, int n = 200000, int n_cells = 24) {
    const Vec3 ex = l.frame.axis(0), ey = l.frame.axis(1), c = l.frame.origin();
    auto cell_of = [&](Vec3 q) {
        const float a = dot(q - c, ex) / l.half_x, b = dot(q - c, ey) / l.half_y;
        const int i = std::min(n_cells - 1, std::max(0, int((a + 1.0f) * 0.5f * n_cells)));
        const int j = std::min(n_cells - 1, std::max(0, int((b + 1.0f) * 0.5f * n_cells)));
        return j * n_cells + i;
    };
    std::vector<double> observed(n_cells * n_cells, 0.0), expected(n_cells * n_cells, 0.0);
    RectChi2 r;
    Pcg32 rng = Pcg32::for_path(7, 0, 0);
    for (int k = 0; k < n; ++k) {
        const Vec2 u = rng.uniform2();
        Vec3 q;
        if (area_samples) {
            q = area_point(l, u);
        } else {
            LightSample ls = sample_light(v, l, p, u, 0.0f);
            if (!ls.valid) continue;
            q = ls.p_light;
        }
        ++r.valid;
        observed[cell_of(q)] += 1.0;
    }
    const int sub = 8;
    const double da = 4.0 * l.half_x * l.half_y / (double(n_cells) * n_cells * sub * sub);
    const Vec3 nl = -l.frame.axis(2);
    for (int j = 0; j < n_cells * sub; ++j)
        for (int i = 0; i < n_cells * sub; ++i) {
            const float a = -1.0f + 2.0f * (i + 0.5f) / (n_cells * sub);
            const float b = -1.0f + 2.0f * (j + 0.5f) / (n_cells * sub);
            const Vec3 q = c + ex * (a * l.half_x) + ey * (b * l.half_y);
            const Vec3 to = q - p;
            const float d2 = length_sq(to), d = std::sqrt(d2);
            const Vec3 wi = to / d;
            const float cos_l = -dot(wi, nl);
            if (!(cos_l > 0.0f)) continue;
            const double pdf = area_pdf ? pdf_a_to_w(1.0f / l.area, d2, cos_l)
                                        : light_pdf_w(l, p, wi, d, nl);
            expected[(j / sub) * n_cells + i / sub] += pdf * cos_l / d2 * da;
        }
    for (double e : expected) r.mass += e;
    double pool_e = 0.0, pool_o = 0.0;
    int cells = 0;
    for (size_t k = 0; k < expected.size(); ++k) {
        double e = expected[k] * n, o = observed[k];
        if (e < 5.0 || pool_e > 0.0) {  // pool cells expecting fewer than 5
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
    r.dof = std::max(1, cells - 1);
    r.p_value = lantern::test::chi2_upper_tail(r.chi2, r.dof);
    return r;
}

}  // namespace

// Receivers under the light, off to one side, 2 cm below its plane beside it, and far below.
TEST(RectLight, SolidAngleSamplesMatchTheirPdf) {
    HostScene s = rect_scene();
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    const Vec3 front = -l.frame.axis(2);  // the emitting side
    const Vec3 below = l.frame.origin() + front * 0.3f;  // 0.3 m under the centre
    const Vec3 beside = l.frame.origin() + front * 0.2f + l.frame.axis(0) * 1.3f;
    const Vec3 near_plane = l.frame.origin() + front * 0.02f + l.frame.axis(1) * 0.7f;
    const Vec3 far = l.frame.origin() + front * 3.0f + l.frame.axis(0) * 0.5f;
    for (Vec3 p : {below, beside, near_plane, far}) {
        SphericalRect sr;
        ASSERT_TRUE(spherical_rect(l, p, &sr)) << p.x << " " << p.y << " " << p.z;
        RectChi2 r = chi2_rect(l, v, p, false, false);
        EXPECT_GT(r.p_value, 1e-4) << "chi2 " << r.chi2 << " dof " << r.dof << " at " << p.x
                                   << " " << p.y << " " << p.z;
        std::printf("rect chi2 %.1f dof %d p %.3g mass %.6f\n", r.chi2, r.dof, r.p_value, r.mass);
        EXPECT_NEAR(r.mass, 1.0, 1e-3);  // the pdf integrates to one over the light
        EXPECT_EQ(r.valid, 200000);      // every receiver in front gets a sample
    }
}

// Negative controls: the test sees a pdf that is not the sampler's (the area pdf against
// solid-angle samples, solid-angle pdf against area samples) close to the light.
TEST(RectLight, ChiSquareRejectsTheOtherSampler) {
    HostScene s = rect_scene();
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    const Vec3 front = -l.frame.axis(2);  // the emitting side
    const Vec3 below = l.frame.origin() + front * 0.3f;
    const RectChi2 a = chi2_rect(l, v, below, false, true), b = chi2_rect(l, v, below, true, false);
    std::printf("controls: chi2 %.1f dof %d, chi2 %.1f dof %d\n", a.chi2, a.dof, b.chi2, b.dof);
    EXPECT_LT(a.p_value, 1e-6);
    EXPECT_LT(b.p_value, 1e-6);
    // and the area sampler passes against its own pdf (the control's own control)
    EXPECT_GT(chi2_rect(l, v, below, true, true).p_value, 1e-4);
}

// Irradiance under the centre of the rectangle, parallel to it: 4 corner form factors,
// E = 2 L sum over (a, b) in {(hx, hy), (hy, hx)} of a/sqrt(a^2+h^2) atan(b/sqrt(a^2+h^2)).
// The solid-angle estimator's standard error is well below area sampling's there.
TEST(RectLight, IrradianceUnderTheCentreAndLowerVariance) {
    SceneInput in;
    LightInput li;
    li.type = "area";
    li.shape = "rectangle";
    li.size_x = 1.9f;
    li.size_y = 1.2f;
    li.power = {10, 10, 10};
    li.to_world[11] = 0.25f;  // 0.25 m above the origin, emitting down -Z
    in.lights.push_back(li);
    HostScene s(in);
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    const Vec3 front = -l.frame.axis(2);  // the emitting side
    const double hx = 0.95, hy = 0.6, h = 0.25, L = l.radiance.x;
    auto term = [&](double a, double b) {
        const double r = std::sqrt(a * a + h * h);
        return a / r * std::atan(b / r);
    };
    const double exact = 2.0 * L * (term(hx, hy) + term(hy, hx));
    const Vec3 p = vec3(0, 0, 0);
    const int n = 40000;
    auto estimate = [&](bool by_area, double* se) {
        Pcg32 rng = Pcg32::for_path(11, 0, 0);
        double sum = 0.0, sum2 = 0.0;
        for (int i = 0; i < n; ++i) {
            const Vec2 u = rng.uniform2();
            double x = 0.0;
            if (by_area) {
                Vec3 q = area_point(l, u), to = q - p;
                float d2 = length_sq(to);
                Vec3 wi = to / sqrtf(d2);
                x = L * wi.z / pdf_a_to_w(1.0f / l.area, d2, wi.z);
            } else {
                LightSample ls = sample_light(v, l, p, u, 0.0f);
                if (ls.valid && ls.wi.z > 0.0f) x = ls.le.x * ls.wi.z / ls.pdf_w;
            }
            sum += x;
            sum2 += x * x;
        }
        const double mean = sum / n;
        *se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
        return mean;
    };
    double se_sa, se_area;
    const double e_sa = estimate(false, &se_sa), e_area = estimate(true, &se_area);
    EXPECT_NEAR(e_sa, exact, 4.5 * se_sa) << "se " << se_sa;
    EXPECT_NEAR(e_area, exact, 4.5 * se_area) << "se " << se_area;
    // negative control: 1 % off the exact value is outside the tolerance
    EXPECT_GT(std::fabs(e_sa - 1.01 * exact), 4.5 * se_sa);
    EXPECT_LT(se_sa, 0.5 * se_area) << se_sa << " vs " << se_area;
}

// The fallback: next to the light's plane and where the light looks tiny, area sampling (pdf
// by area, the same choice in sample_light and light_pdf_w); behind it, nothing.
TEST(RectLight, AreaFallbackNearThePlaneAndFarAway) {
    HostScene s = rect_scene(0.5f, 0.3f);
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    const Vec3 front = -l.frame.axis(2);  // the emitting side
    SphericalRect sr;
    const Vec3 c = l.frame.origin(), z = -l.frame.axis(2), x = l.frame.axis(0);
    EXPECT_FALSE(spherical_rect(l, c + z * 1e-5f + x * 0.6f, &sr));  // in the plane, beside it
    EXPECT_FALSE(spherical_rect(l, c + z * 20.0f, &sr));            // 0.15 sr / 400: tiny
    EXPECT_FALSE(spherical_rect(l, c - z * 0.5f, &sr));             // behind the light
    EXPECT_TRUE(spherical_rect(l, c + z * 0.5f, &sr));
    // far away: the area sampler's pdf, from both functions
    const Vec3 p = c + z * 20.0f;
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    for (int i = 0; i < 100; ++i) {
        LightSample ls = sample_light(v, l, p, rng.uniform2(), 0.0f);
        ASSERT_TRUE(ls.valid);
        const float cos_l = fabsf(dot(ls.wi, ls.n_light));
        const float expect = pdf_a_to_w(1.0f / l.area, ls.dist * ls.dist, cos_l);
        EXPECT_FLOAT_EQ(ls.pdf_w, expect);
        EXPECT_FLOAT_EQ(light_pdf_w(l, p, ls.wi, ls.dist, ls.n_light), expect);
    }
    // behind: no sample
    EXPECT_FALSE(sample_light(v, l, c - z * 0.5f, Vec2{0.3f, 0.6f}, 0.0f).valid);
}

// Every sampled point lies on the rectangle, and the bidirectional integrators' correction
// of the light vertex's stand-in density (1 / area) is the solid-angle density over it.
TEST(RectLight, SampledPointsOnTheLightAndReceiverRatio) {
    HostScene s = rect_scene();
    const SceneView v = s.view();
    const Light& l = v.lights[0];
    const Vec3 front = -l.frame.axis(2);  // the emitting side
    const Vec3 p = l.frame.origin() + front * 0.05f + l.frame.axis(0) * 0.8f;
    Pcg32 rng = Pcg32::for_path(9, 0, 0);
    for (int i = 0; i < 2000; ++i) {
        LightSample ls = sample_light(v, l, p, rng.uniform2(), 0.0f);
        ASSERT_TRUE(ls.valid);
        const Vec3 q = ls.p_light - l.frame.origin();
        EXPECT_LE(fabsf(dot(q, l.frame.axis(0))), l.half_x * (1.0f + 1e-4f));
        EXPECT_LE(fabsf(dot(q, l.frame.axis(1))), l.half_y * (1.0f + 1e-4f));
        EXPECT_LE(fabsf(dot(q, l.frame.axis(2))), 1e-4f);
        const float cos_l = fabsf(dot(ls.wi, ls.n_light));
        const float ratio = direct_pdf_receiver_ratio(l, p, ls.wi, ls.dist, ls.n_light);
        EXPECT_NEAR(ratio, ls.pdf_w * cos_l / (ls.dist * ls.dist) * l.area, 1e-4f * ratio);
    }
}
