// Lantern's curve intersector (accel/curve_bvh.h over curve_hit.h) against Embree's
// ROUND_LINEAR_CURVE geometry (backend/cpu/embree_curves.h), an implementation written by
// others: fur on a sphere, random rays; hit or miss must agree but for grazing rays, t within
// 1e-5 relative, the normals within 0.5 degrees. Radii 1 % larger on Lantern's side are the
// negative control. Skipped where Embree is not loadable. At a joint of two segments of a strand
// neither draws the joint's sphere whole (RTC_CURVE_FLAG_NEIGHBOR_*): Embree keeps the part of
// it that fills the outer wedge of a bend (clipped by the neighbour's cone), Lantern leaves it
// out (accel/curve_hit.h), so rays whose hit on either side lies within one joint radius of a
// joint are counted apart (printed), not compared.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "accel/curve_bvh_build.h"
#include "backend/cpu/embree_curves.h"
#include "core/rng.h"

using namespace lantern;

#if LANTERN_HAVE_EMBREE
namespace {

std::vector<CurveSeg> fur(int strands, int keys, uint64_t seed) {
    std::vector<float> pts, rad;
    std::vector<int32_t> off{0};
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    for (int s = 0; s < strands; ++s) {
        const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 n = vec3(r * cosf(phi), r * sinf(phi), z);
        const Vec3 bend = vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, -0.5f) * 0.3f;
        for (int k = 0; k < keys; ++k) {
            const float t = float(k) / float(keys - 1);
            const Vec3 p = n * (1.0f + 0.3f * t) + bend * (t * t);
            pts.insert(pts.end(), {p.x, p.y, p.z});
            rad.push_back(0.02f * (1.0f - 0.8f * t));
        }
        off.push_back(int32_t(rad.size()));
    }
    return curve_segments(pts.data(), rad.data(), off.data(), strands);
}

// Whether x lies within the radius of a joint (a joined end) of some segment.
bool near_joint(const std::vector<CurveSeg>& segs, Vec3 x) {
    for (const CurveSeg& g : segs)
        if ((g.flags & kCurveJoinEnd) && length(x - g.p1) <= 1.001f * g.r1) return true;
    return false;
}

struct EmbreeTally {
    int hits = 0, mismatch = 0, far_t = 0, bad_n = 0, at_joint = 0;
    double max_dt = 0.0;  // largest |t - t_embree| / t_embree
};

EmbreeTally compare(const std::vector<CurveSeg>& segs, float radius_scale, int rays) {
    const EmbreeApi& e = embree_api();
    RTCDevice dev = e.newDevice(nullptr);
    RTCScene scene = e.newScene(dev);
    embree_attach_curves(e, dev, scene, segs.data(), segs.size());
    e.commitScene(scene);
    std::vector<CurveSeg> mine = segs;
    for (CurveSeg& s : mine) {
        s.r0 *= radius_scale;
        s.r1 *= radius_scale;
    }
    CurveBvh bvh = build_curve_bvh(mine);
    Pcg32 rng = Pcg32::for_path(4, 1, 0);
    EmbreeTally t;
    for (int i = 0; i < rays; ++i) {
        const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 o = vec3(r * cosf(phi), r * sinf(phi), z) * 3.0f;
        const Vec3 target = vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f,
                                 rng.uniform() - 0.5f) * 2.6f;
        const Vec3 w = normalize(target - o);
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh{};
        rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
        rh.ray.dir_x = w.x, rh.ray.dir_y = w.y, rh.ray.dir_z = w.z;
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = 10.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        e.intersect1(scene, &ctx, &rh);
        const bool eh = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        const CurveBvhHit mh = curve_bvh_intersect(bvh.view(), o, w, 0.0f, 10.0f);
        const bool lh = mh.seg >= 0;
        if ((eh && near_joint(segs, o + w * rh.ray.tfar)) ||
            (lh && near_joint(segs, o + w * mh.t))) {
            ++t.at_joint;
            continue;
        }
        if (eh) ++t.hits;
        if (eh != lh) {
            // grazing: the hit normal (either side's) nearly perpendicular to the ray
            const Vec3 n = eh ? normalize(vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z)) : mh.n;
            if (std::fabs(dot(n, w)) > 0.02f) ++t.mismatch;
            continue;
        }
        if (!eh) continue;
        const double dt = std::fabs(double(mh.t) - rh.ray.tfar) / rh.ray.tfar;
        t.max_dt = std::max(t.max_dt, dt);
        if (dt > 1e-5) ++t.far_t;
        const Vec3 en = normalize(vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
        if (dot(en, mh.n) < cosf(0.5f * kPi / 180.0f)) ++t.bad_n;
    }
    e.releaseScene(scene);
    e.releaseDevice(dev);
    return t;
}

}  // namespace
#endif

TEST(CurveEmbree, AgreesWithEmbreeRoundLinearCurves) {
#if LANTERN_HAVE_EMBREE
    if (!embree_available()) GTEST_SKIP() << "Embree: " << embree_version();
    const std::vector<CurveSeg> segs = fur(800, 6, 2);
    const EmbreeTally t = compare(segs, 1.0f, 4000);
    std::printf("hits %d of 4000 (%d at joints, not compared): mismatched %d, t off %d (max %.2g "
                "relative), normals off %d\n", t.hits, t.at_joint, t.mismatch, t.far_t, t.max_dt,
                t.bad_n);
    EXPECT_GT(t.hits, 800);
    EXPECT_EQ(t.mismatch, 0);
    EXPECT_EQ(t.far_t, 0);
    EXPECT_EQ(t.bad_n, 0);
    const EmbreeTally c = compare(segs, 1.01f, 4000);
    EXPECT_GT(c.far_t + c.mismatch, c.hits / 2) << "control: radii 1 % larger passed";
#else
    GTEST_SKIP() << "built without Embree";
#endif
}
