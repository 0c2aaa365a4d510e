// The round linear curve segment (accel/curve_hit.h) against a reference written here: the
// swept-sphere volume's distance min_u |x - c(u)| - r(u) on a dense u grid, marched along the
// ray and bisected to its first zero. Random segments (tapered, cylindrical, one end sphere
// holding the other) and rays from outside; hit or miss, t, normal and u must agree except on
// grazing rays (the reference's closest approach within its own error of the surface). A
// radius 1 % off is the negative control: the t comparison must catch it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "accel/curve_hit.h"
#include "core/rng.h"

using namespace lantern;

namespace {

struct Seg {
    Vec3 p0, p1;
    float r0, r1;
};

// The distance from x to the swept volume, min over u of |x - c(u)| - r(u) (exact outside it:
// the distance to a union is the least distance to its members), by ternary search in u (the
// function is convex in u: a norm of an affine map minus an affine map); in double.
double dist(const Seg& s, Vec3 x, double* u_best) {
    auto f = [&](double u) {
        const double cx = s.p0.x + u * (double(s.p1.x) - s.p0.x) - x.x;
        const double cy = s.p0.y + u * (double(s.p1.y) - s.p0.y) - x.y;
        const double cz = s.p0.z + u * (double(s.p1.z) - s.p0.z) - x.z;
        return std::sqrt(cx * cx + cy * cy + cz * cz) - (s.r0 + u * (double(s.r1) - s.r0));
    };
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 100; ++i) {
        const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
        (f(m1) < f(m2) ? hi : lo) = (f(m1) < f(m2) ? m2 : m1);
    }
    *u_best = 0.5 * (lo + hi);
    return f(*u_best);
}

// Sphere tracing with that exact distance: the first t in (0, tmax] on the surface, or -1;
// *closest: the least distance seen on the way (a miss's closest approach).
double reference_t(const Seg& s, Vec3 o, Vec3 w, double tmax, double* closest) {
    double u, t = 0.0;
    *closest = 1e30;
    for (int i = 0; i < 100000 && t <= tmax; ++i) {
        const double d = dist(s, vec3(float(o.x + t * w.x), float(o.y + t * w.y),
                                      float(o.z + t * w.z)), &u);
        *closest = std::min(*closest, d);
        if (d < 1e-7) return t;
        t += d;
    }
    return -1.0;
}

Seg random_seg(Pcg32& rng, int kind) {
    Seg s;
    s.p0 = vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f);
    s.p1 = vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f);
    s.r0 = 0.02f + 0.2f * rng.uniform();
    s.r1 = kind == 1 ? s.r0 : 0.02f + 0.2f * rng.uniform();
    if (kind == 2) {  // one end's sphere holds the other
        s.p1 = s.p0 + vec3(0.05f, 0.02f, 0.0f);
        s.r0 = 0.3f;
        s.r1 = 0.1f;
    }
    return s;
}

struct Tally {
    int compared = 0, hits = 0, grazing = 0, bad_hit = 0, bad_t = 0, bad_n = 0, bad_u = 0;
};

Tally run(uint64_t seed, int n, float radius_scale) {
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    Tally tally;
    for (int i = 0; i < n; ++i) {
        Seg s = random_seg(rng, i % 3);
        const Vec3 mid = (s.p0 + s.p1) * 0.5f;
        const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
        const float rr = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 o = mid + vec3(rr * cosf(phi), rr * sinf(phi), z) * 1.5f;
        const Vec3 target = mid + vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f,
                                       rng.uniform() - 0.5f) * 0.5f;
        const Vec3 w = normalize(target - o);
        CurveHit h;
        const bool got = curve_hit_segment(o, w, s.p0, s.r0 * radius_scale, s.p1,
                                           s.r1 * radius_scale, 0.0f, 4.0f, &h);
        double closest;
        const double t_ref = reference_t(s, o, w, 4.0, &closest);
        double u0;
        const bool graze_hit = t_ref > 0.0 && [&] {
            dist(s, o + w * float(t_ref), &u0);
            const Vec3 xr = o + w * float(t_ref);
            const Vec3 cr = s.p0 + (s.p1 - s.p0) * float(u0);
            return std::fabs(dot(normalize(xr - cr), w)) < 0.05f;
        }();
        if ((t_ref < 0.0 && closest < 2e-3) || graze_hit) {  // grazing: either answer is right
            ++tally.grazing;
            continue;
        }
        ++tally.compared;
        if (got != (t_ref > 0.0)) {
            ++tally.bad_hit;
            continue;
        }
        if (!got) continue;
        ++tally.hits;
        if (std::fabs(h.t - t_ref) > 2e-5) ++tally.bad_t;
        double u_ref;
        const Vec3 x = o + w * h.t;
        dist(s, x, &u_ref);
        const Vec3 c = s.p0 + (s.p1 - s.p0) * float(u_ref);
        const Vec3 n_ref = normalize(x - c);
        if (dot(n_ref, h.n) < 0.9999f || std::fabs(length(h.n) - 1.0f) > 1e-4f) ++tally.bad_n;
        if (std::fabs(h.u - u_ref) > 2e-3 && i % 3 != 2) ++tally.bad_u;
    }
    return tally;
}

}  // namespace

TEST(CurveHit, AgreesWithSweptSphereReference) {
    Tally t = run(1, 3000, 1.0f);
    std::printf("compared %d (hits %d), grazing %d\n", t.compared, t.hits, t.grazing);
    EXPECT_GT(t.hits, 1000);
    EXPECT_LT(t.grazing, 100);
    EXPECT_EQ(t.bad_hit, 0);
    EXPECT_EQ(t.bad_t, 0);
    EXPECT_EQ(t.bad_n, 0);
    EXPECT_EQ(t.bad_u, 0);
    // negative control: radii 1 % larger move most hit distances by more than the tolerance
    Tally c = run(1, 3000, 1.01f);
    std::printf("control: %d of %d hits off\n", c.bad_t + c.bad_hit, c.hits);
    EXPECT_GT(c.bad_t + c.bad_hit, c.hits / 2);
}

TEST(CurveHit, RangeAndInside) {
    CurveHit h;
    const Vec3 p0 = vec3(0.0f, 0.0f, 0.0f), p1 = vec3(1.0f, 0.0f, 0.0f);
    // straight at the middle of a cylinder of radius 0.1 from y = -1: t = 0.9, n = -y
    ASSERT_TRUE(curve_hit_segment(vec3(0.5f, -1.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), p0, 0.1f, p1,
                                  0.1f, 0.0f, 10.0f, &h));
    EXPECT_NEAR(h.t, 0.9f, 1e-6f);
    EXPECT_NEAR(h.n.y, -1.0f, 1e-6f);
    EXPECT_NEAR(h.u, 0.5f, 1e-6f);
    // tmax before the surface, tmin past it: nothing
    EXPECT_FALSE(curve_hit_segment(vec3(0.5f, -1.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), p0, 0.1f, p1,
                                   0.1f, 0.0f, 0.89f, &h));
    EXPECT_FALSE(curve_hit_segment(vec3(0.5f, -1.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), p0, 0.1f, p1,
                                   0.1f, 0.95f, 10.0f, &h));
    // from inside (a ray leaving the strand): nothing, on the cone and in an end sphere
    EXPECT_FALSE(curve_hit_segment(vec3(0.5f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), p0, 0.1f, p1,
                                   0.1f, 0.0f, 10.0f, &h));
    EXPECT_FALSE(curve_hit_segment(vec3(-0.05f, 0.0f, 0.0f), vec3(-1.0f, 0.0f, 0.0f), p0, 0.1f,
                                   p1, 0.1f, 0.0f, 10.0f, &h));
    // end on: the cap sphere of p0 at t = 0.9
    ASSERT_TRUE(curve_hit_segment(vec3(-1.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), p0, 0.1f, p1,
                                  0.1f, 0.0f, 10.0f, &h));
    EXPECT_NEAR(h.t, 0.9f, 1e-6f);
    EXPECT_EQ(h.u, 0.0f);
    // zero, NaN and negative radii: no hit, no NaN
    for (float r : {0.0f, std::nanf(""), -0.1f})
        EXPECT_FALSE(curve_hit_segment(vec3(0.5f, -1.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), p0, r,
                                       p1, r, 0.0f, 10.0f, &h));
}
