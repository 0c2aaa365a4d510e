#include "backend/cpu/bvh_accel.h"

namespace lantern {

namespace {

uint32_t need_for(RayKind kind) {
    switch (kind) {
        case RayKind::kCamera: return kBvhNeedCamera;
        case RayKind::kShadow: return kBvhNeedShadow;
        default: return kBvhNeedIndirect;
    }
}

}  // namespace

BvhAccel::BvhAccel(const SceneView& s, int threads, std::vector<std::string>& warnings)
    : s_(s) {
    BvhBuildOptions opt;
    opt.threads = threads;
    bvh_ = build_bvh(s, opt, warnings);
    view_ = bvh_.view();
    for (int t = 0; t < s.num_triangles && s.tri_flags; ++t) {
        if (s.tri_flags[t] & kAlphaTested) {
            any_alpha_ = true;
            break;
        }
    }
}

HitRecord BvhAccel::intersect(const Ray& r, RayKind kind) const {
    const BvhHit h = any_alpha_ ? bvh_intersect(view_, r, need_for(kind), BvhAlphaTest{s_, r})
                                : bvh_intersect(view_, r, need_for(kind));
    return {h.t, h.prim, h.uv};
}

bool BvhAccel::occluded(const Ray& r) const {
    return any_alpha_ ? bvh_occluded(view_, r, kBvhNeedShadow, BvhAlphaTest{s_, r})
                      : bvh_occluded(view_, r, kBvhNeedShadow);
}

}  // namespace lantern
