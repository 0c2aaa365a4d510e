// Strands of a turning object (docs/motion_blur.md "Strands of a turning object"): a fur ball
// exported with its object's matrix at 3 steps (a half turn about z over the shutter, sliding
// along x) keeps its strands in their exported frame under the slerped matrix. At times between
// two steps (0.25: the middle of an interval, where a chord is 0.29 x the radius inside its
// arc), at the steps and at the frame, the built-in curve BVH and Embree's instance must hit
// what the same backend's still structure over the points turned exactly there hits (segment
// or its neighbour at a joint, t to 1e-4 relative, the same shadow answer), through
// HostScene (the scene's CurveSetMotion) and CurveAccel; pt's strand surface there has its
// normal and tangent from the turned segment; likewise where the strands also grow in the
// object's frame (`deform` placed as exported, lerped there under the turn). Control: the same strands exported as world
// points at the steps (`deform`, lerped: the behaviour before) miss that arc.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "backend/cpu/curve_accel.h"
#include "backend/cpu/embree_loader.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "integrator/pt_curve.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// The spinning object's object-to-world at shutter time f: a turn by pi f about z, then a slide.
std::vector<float> spin_world_at(double f) {
    const double a = -0.5 * kPi + kPi * f, c = std::cos(a), s = std::sin(a);
    return {float(c), float(-s), 0.0f, float(0.3 * f), float(s), float(c), 0.0f, 0.1f,
            0.0f,     0.0f,      1.0f, -0.2f,          0.0f,     0.0f,      0.0f, 1.0f};
}

Vec3 spin_apply(const std::vector<float>& m, Vec3 p) {
    return vec3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
                m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

struct SpinFur {
    std::vector<Vec3> local;  // object-space points
    std::vector<float> radius;
    std::vector<int32_t> offsets{0};
};

SpinFur make_spin_fur(int strands, int keys) {
    SpinFur f;
    Pcg32 rng = Pcg32::for_path(21, 0, 0);
    for (int s = 0; s < strands; ++s) {
        const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 n = vec3(r * cosf(phi), r * sinf(phi), z);
        for (int k = 0; k < keys; ++k) {
            const float t = float(k) / float(keys - 1);
            f.local.push_back(n * (0.8f + 0.4f * t) + vec3(0.0f, 0.0f, 0.1f * t * t));
            f.radius.push_back(0.03f * (1.0f - 0.7f * t));
        }
        f.offsets.push_back(int32_t(f.local.size()));
    }
    return f;
}

// How far the strands reach at shutter time t where they also grow (linear in t, so that the
// lerp of the steps is exact): their object-space points scaled about the ball's centre.
float spin_grow(float t, bool grow) { return grow ? 1.0f + 0.4f * (t - 0.5f) : 1.0f; }

// The fur ball as the add-on exports it: points at the frame (shutter time 0.5) with the
// object's matrices (`motion`; where they grow, `deform` placed as exported), or (lerped: true)
// as world points at the steps (`deform`)
SceneInput spin_scene(const SpinFur& f, bool lerped, bool grow = false) {
    SceneInput in;
    in.materials.push_back(MaterialInput{});
    CurveInput c;
    c.name = "fur";
    const std::vector<float> base = spin_world_at(0.5);
    for (const Vec3& p : f.local) {
        const Vec3 w = spin_apply(base, p);
        c.points.insert(c.points.end(), {w.x, w.y, w.z});
    }
    c.radius = f.radius;
    c.offsets = f.offsets;
    for (int k = 0; k < 3; ++k) {
        const std::vector<float> m = spin_world_at(0.5 * k);
        const float g = spin_grow(0.5f * float(k), grow);
        if (lerped) {
            for (const Vec3& p : f.local) {
                const Vec3 w = spin_apply(m, p * g);
                c.deform.insert(c.deform.end(), {w.x, w.y, w.z});
            }
        } else {
            c.motion.insert(c.motion.end(), m.begin(), m.end());
            for (const Vec3& p : f.local) {
                if (!grow) break;
                const Vec3 w = spin_apply(base, p * g);
                c.deform.insert(c.deform.end(), {w.x, w.y, w.z});
            }
        }
    }
    if (!lerped) std::copy(base.begin(), base.end(), c.motion_base);
    in.curves.push_back(c);
    return in;
}

// Hits of the spinning fur (HostScene, CurveAccel) against a still BVH over the points turned
// exactly at `time`: returns the rays whose hit (segment or t) or shadow answer differ.
int spin_mismatches(const SpinFur& f, bool lerped, bool embree, float time, int* hits,
                    bool grow = false) {
    HostScene scene(spin_scene(f, lerped, grow));
    const SceneView& v = scene.view();
    EXPECT_EQ(v.curves.num_sets, lerped ? 0 : 1);
    EXPECT_EQ(v.motion.curves, 1);
    std::vector<std::string> w;
    CurveAccel moving(v, embree, w);
    const std::vector<float> m = spin_world_at(time);
    std::vector<float> pts;
    for (const Vec3& p : f.local) {
        const Vec3 q = spin_apply(m, p * spin_grow(time, grow));
        pts.insert(pts.end(), {q.x, q.y, q.z});
    }
    std::vector<CurveSeg> exact = curve_segments(pts.data(), f.radius.data(), f.offsets.data(),
                                                 int(f.offsets.size()) - 1);
    // the scene's segment k is exact[k] (the same order, no segment left out)
    EXPECT_EQ(int(exact.size()), v.curves.num_segs);
    for (size_t k = 0; k < exact.size(); ++k) exact[k].index = int32_t(k);
    // the reference: the same backend's structure over the points turned exactly (a still
    // scene), so that Embree's own joints (its shape there is not accel/curve_hit.h's to the
    // last ulp: tests/cpp/test_curve_embree.cpp) are on both sides
    SceneInput turned = spin_scene(f, false);
    turned.curves[0].motion.clear();
    turned.curves[0].deform.clear();
    turned.curves[0].points = pts;
    HostScene still_scene(turned);
    CurveAccel still(still_scene.view(), embree, w);
    Pcg32 rng = Pcg32::for_path(5, uint64_t(time * 1000.0f), 0);
    int bad = 0;
    for (int i = 0; i < 2000; ++i) {
        float pdf;
        const Vec3 o = sample_uniform_sphere(rng.uniform2(), &pdf) * 3.0f + vec3(0.15f, 0.1f, -0.2f);
        // aim at a point of a strand where it is at `time`
        const CurveSeg& g = exact[rng.next() % uint32_t(exact.size())];
        const Vec3 d = normalize(g.p0 + (g.p1 - g.p0) * rng.uniform() - o);
        Ray ray{o, d, 1e-4f, kInf};
        ray.time = time;
        HitRecord hs{kInf, -1, {0.0f, 0.0f}}, h{kInf, -1, {0.0f, 0.0f}};
        still.closer(ray, RayKind::kIndirect, &hs);
        const struct { int seg; float t; } e{hs.prim >= 0 ? hs.prim - v.num_triangles : -1, hs.t};
        moving.closer(ray, RayKind::kIndirect, &h);
        *hits += e.seg >= 0;
        const int got = h.prim >= 0 ? h.prim - v.num_triangles : -1;
        // at a joint of one strand either segment may report the hit (at the same t)
        const bool joint = got >= 0 && e.seg >= 0 && std::abs(got - e.seg) == 1;
        const bool same = (got == e.seg || joint) &&
                          (e.seg < 0 || std::fabs(h.t - e.t) <= 1e-4f * e.t);
        if (!same || moving.occluded(ray) != (e.seg >= 0)) {
            ++bad;
            if (getenv("SPIN_DEBUG") && !lerped)
                printf("t %g ray %d: got %d t %g, exact %d t %g, occluded %d\n", time, i, got, h.t, e.seg,
                       e.t, int(moving.occluded(ray)));
        }
        if (same && e.seg >= 0 && !lerped && i % 16 == 0) {
            // pt's surface there: the normal of the exactly turned segment at the hit point
            const SurfaceHit sh = pt_surface_curve(v, h.prim, h.uv, o, d, h.t, time);
            Vec3 tangent;
            Vec3 n = curve_normal_at(exact[e.seg], o + d * e.t, &tangent);
            if (dot(n, d) > 0.0f) n = -n;
            EXPECT_GT(dot(sh.ng, n), 0.999f) << "ray " << i << " time " << time;
        }
    }
    return bad;
}

void check_spin(bool embree) {
    if (embree && !embree_available()) GTEST_SKIP() << "no Embree";
    const SpinFur f = make_spin_fur(300, 5);
    for (float time : {0.5f, 0.0f, 0.25f, 0.6f, 0.9f}) {
        int hits = 0;
        const int bad = spin_mismatches(f, false, embree, time, &hits);
        printf("%s time %.2f: %d of 2000 rays hit, %d differ\n", embree ? "embree" : "bvh", time,
               hits, bad);
        EXPECT_GT(hits, 1500) << time;
        EXPECT_LE(bad, 6) << (embree ? "embree" : "bvh") << " at time " << time;  // grazing
    }
    // the strands also growing in the object's frame (deform there, lerped, under the turn)
    for (float time : {0.25f, 0.7f}) {
        int hits = 0;
        const int bad = spin_mismatches(f, false, embree, time, &hits, true);
        printf("%s, growing too, time %.2f: %d of 2000 rays hit, %d differ\n",
               embree ? "embree" : "bvh", time, hits, bad);
        EXPECT_GT(hits, 1500) << time;
        EXPECT_LE(bad, 6) << (embree ? "embree" : "bvh") << " growing at time " << time;
    }
    // control: the lerped world points (the behaviour before) are off the arc mid-interval
    int hits = 0;
    const int off = spin_mismatches(f, true, embree, 0.25f, &hits);
    printf("%s, lerped world points at time 0.25: %d of 2000 rays differ\n",
           embree ? "embree" : "bvh", off);
    EXPECT_GT(off, 400);
}

}  // namespace

TEST(CurveSpin, BuiltinBvhStrandsOnTheArc) { check_spin(false); }
TEST(CurveSpin, EmbreeStrandsOnTheArc) { check_spin(true); }
