// The curve BVH (accel/curve_bvh.h, curve_bvh_build.h) against brute force over every segment:
// fur on a sphere (tapered strands to a tip of radius 0), random rays; the closest hit's segment
// and t must be the brute force's exactly (the same curve_hit_segment; at a joint sphere either
// neighbour, at the same t), any-hit must agree on
// hit or miss. Node boxes shrunk by the largest radius are the negative control. Strands with
// NaN or negative radii are left out at the build.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "accel/curve_bvh_build.h"
#include "core/rng.h"

using namespace lantern;

namespace {

struct Fur {
    std::vector<float> points, radius;
    std::vector<int32_t> offsets{0};
};

Fur make_fur(int strands, int keys, uint64_t seed) {
    Fur f;
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    for (int s = 0; s < strands; ++s) {
        const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 n = vec3(r * cosf(phi), r * sinf(phi), z);
        const Vec3 bend = vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, -0.5f) * 0.3f;
        for (int k = 0; k < keys; ++k) {
            const float t = float(k) / float(keys - 1);
            const Vec3 p = n * (1.0f + 0.3f * t) + bend * (t * t);
            f.points.insert(f.points.end(), {p.x, p.y, p.z});
            f.radius.push_back(0.01f * (1.0f - t));
        }
        f.offsets.push_back(int32_t(f.radius.size()));
    }
    return f;
}

CurveBvhHit brute(const std::vector<CurveSeg>& segs, Vec3 o, Vec3 w, float tmax) {
    CurveBvhHit best{tmax, 0.0f, vec3(0.0f), -1};
    for (const CurveSeg& s : segs) {
        CurveHit h;
        if (curve_hit_segment(o, w, s.p0, s.r0, s.p1, s.r1, 0.0f, best.t, &h, s.flags))
            best = CurveBvhHit{h.t, h.u, h.n, s.index};
    }
    return best;
}

struct BvhTally {
    int hits = 0, wrong = 0, any_wrong = 0, ties = 0;
};

BvhTally compare(const CurveBvh& bvh, const std::vector<CurveSeg>& segs, int rays, uint64_t seed) {
    Pcg32 rng = Pcg32::for_path(seed, 1, 0);
    BvhTally t;
    for (int i = 0; i < rays; ++i) {
        const float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 o = vec3(r * cosf(phi), r * sinf(phi), z) * 3.0f;
        const Vec3 target = vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f,
                                 rng.uniform() - 0.5f) * 2.6f;
        const Vec3 w = normalize(target - o);
        const CurveBvhHit a = curve_bvh_intersect(bvh.view(), o, w, 0.0f, 10.0f);
        const CurveBvhHit b = brute(segs, o, w, 10.0f);
        if (b.seg >= 0) ++t.hits;
        // a tie: the joint sphere two neighbours share, hit at the same t by both (either is
        // right: the same point and radius)
        const bool tie = a.t == b.t && a.seg >= 0 && b.seg >= 0 && std::abs(a.seg - b.seg) == 1;
        if (tie) ++t.ties;
        else if (a.seg != b.seg || (b.seg >= 0 && a.t != b.t)) ++t.wrong;
        const CurveBvhHit any = curve_bvh_intersect(bvh.view(), o, w, 0.0f, 10.0f, true);
        if ((any.seg >= 0) != (b.seg >= 0)) ++t.any_wrong;
    }
    return t;
}

}  // namespace

TEST(CurveBvh, MatchesBruteForce) {
    Fur f = make_fur(1500, 7, 3);
    std::vector<CurveSeg> segs =
        curve_segments(f.points.data(), f.radius.data(), f.offsets.data(), 1500);
    ASSERT_EQ(segs.size(), 1500u * 6u);
    CurveBvh bvh = build_curve_bvh(segs);
    const BvhTally t = compare(bvh, segs, 3000, 9);
    std::printf("hits %d of 3000 rays (%d ties at joints), %zu nodes\n", t.hits, t.ties,
                bvh.nodes.size());
    EXPECT_LT(t.ties, t.hits / 50);
    EXPECT_GT(t.hits, 300);
    EXPECT_EQ(t.wrong, 0);
    EXPECT_EQ(t.any_wrong, 0);
    // negative control: boxes 0.01 (the largest radius) too small lose hits
    CurveBvh shrunk = bvh;
    for (CurveBvhNode& n : shrunk.nodes) {
        n.lo = n.lo + vec3(0.01f);
        n.hi = n.hi - vec3(0.01f);
    }
    const BvhTally c = compare(shrunk, segs, 3000, 9);
    EXPECT_GT(c.wrong, t.hits / 20) << "control: " << c.wrong << " wrong";
}

TEST(CurveBvh, BadRadiiAndEmpty) {
    Fur f = make_fur(10, 4, 5);
    f.radius[1] = std::nanf("");  // strand 0, segments 0 and 1
    f.radius[4] = -1.0f;          // strand 1, segment 0
    f.radius[8] = f.radius[9] = f.radius[10] = f.radius[11] = 0.0f;  // strand 2: no surface
    std::vector<CurveSeg> segs =
        curve_segments(f.points.data(), f.radius.data(), f.offsets.data(), 10);
    EXPECT_EQ(segs.size(), 30u - 2u - 1u - 3u);
    CurveBvh empty = build_curve_bvh({});
    const CurveBvhHit h = curve_bvh_intersect(empty.view(), vec3(0.0f), vec3(1.0f, 0.0f, 0.0f),
                                              0.0f, 10.0f);
    EXPECT_EQ(h.seg, -1);
}

// The traversal's fixed stack (kCurveBvhStack entries, 32: 128 B of a GPU thread's stack) must
// hold every tree the builder makes: each built tree's depth is the bound the static_assert
// checks for 2^31 segments (median splits), and a deeper one is refused at the build, by name.
TEST(CurveBvh, DepthWithinTheStack) {
    for (int strands : {1, 3, 250, 1500}) {
        Fur f = make_fur(strands, 7, 11);
        std::vector<CurveSeg> segs =
            curve_segments(f.points.data(), f.radius.data(), f.offsets.data(), strands);
        const CurveBvh bvh = build_curve_bvh(segs);
        EXPECT_EQ(bvh.depth, curve_bvh_depth_bound(int64_t(segs.size()))) << segs.size();
    }
    EXPECT_EQ(curve_bvh_depth_bound(4), 1);
    EXPECT_EQ(curve_bvh_depth_bound(9), 3);  // 9 -> 5 -> 3
    EXPECT_EQ(curve_bvh_depth_bound(INT32_MAX), 30);
    EXPECT_NO_THROW(curve_bvh_check_depth(kCurveBvhStack + 1));
    try {  // control: one level more than the stack holds
        curve_bvh_check_depth(kCurveBvhStack + 2);
        ADD_FAILURE() << "a tree deeper than the stack was accepted";
    } catch (const std::length_error& e) {
        EXPECT_NE(std::string(e.what()).find("kCurveBvhStack"), std::string::npos) << e.what();
    }
}
