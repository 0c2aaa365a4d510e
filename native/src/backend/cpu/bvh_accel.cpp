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

BvhAccel::BvhAccel(const SceneView& s, int threads, std::vector<std::string>& warnings,
                   const std::vector<MeshRange>* meshes)
    : s_(s) {
    if (meshes) {
        two_level_ = true;
        build_tlas_scene(tl_, s, *meshes, threads, warnings);
        tl_view_ = tl_.view();
    } else {
        BvhBuildOptions opt;
        opt.threads = threads;
        bvh_ = build_bvh(s, opt, warnings);
    }
    far_ray_bounds(s, box_);
    view_ = bvh_.view();
    for (int t = 0; t < s.num_triangles && s.tri_flags; ++t) {
        if (s.tri_flags[t] & kAlphaTested) {
            any_alpha_ = true;
            break;
        }
    }
}

// The ray Embree would see (EmbreeAccel::prepare()); false: nothing to trace. Rays within range
// come back unchanged, so ordinary scenes keep their bits.
bool BvhAccel::guard(const Ray& r, Ray* out, float* shift) const {
    float o[3];
    if (!EmbreeAccel::prepare(r, box_, o, &out->tmin, &out->tmax, shift)) return false;
    out->o = {o[0], o[1], o[2]};
    out->d = r.d;
    out->time = r.time;
    return true;
}

HitRecord BvhAccel::intersect(const Ray& ray, RayKind kind) const {
    Ray r;
    float shift = 0.0f;
    if (!guard(ray, &r, &shift)) return {ray.tmax, -1, {0, 0}};
    const uint32_t need = need_for(kind);
    BvhHit h;
    if (two_level_) {
        h = any_alpha_ ? tlas_intersect(tl_view_, r, need, BvhAlphaTest{s_, r})
                       : tlas_intersect(tl_view_, r, need);
    } else {
        h = any_alpha_ ? bvh_intersect(view_, r, need, BvhAlphaTest{s_, r})
                       : bvh_intersect(view_, r, need);
    }
    if (h.prim < 0) return {ray.tmax, -1, {0, 0}};
    return {shift > 0.0f ? float(double(h.t) + shift) : h.t, h.prim, h.uv};
}

bool BvhAccel::occluded(const Ray& ray) const {
    Ray r;
    float shift = 0.0f;
    if (!guard(ray, &r, &shift))
        return !is_finite(ray.o) || !is_finite(ray.d) || !(ray.tmax >= 0.0f);
    if (two_level_) {
        return any_alpha_ ? tlas_occluded(tl_view_, r, kBvhNeedShadow, BvhAlphaTest{s_, r})
                          : tlas_occluded(tl_view_, r, kBvhNeedShadow);
    }
    return any_alpha_ ? bvh_occluded(view_, r, kBvhNeedShadow, BvhAlphaTest{s_, r})
                      : bvh_occluded(view_, r, kBvhNeedShadow);
}

bool BvhAccel::occluded_collect(const Ray& ray, BoundaryHits* out) const {
    out->n = 0;
    if (two_level_) {  // (no gathering traversal of two levels: the caller's loop)
        out->n = -1;
        return false;
    }
    Ray r;
    float shift = 0.0f;
    if (!guard(ray, &r, &shift))
        return !is_finite(ray.o) || !is_finite(ray.d) || !(ray.tmax >= 0.0f);
    const bool blocked = any_alpha_ ? bvh_occluded_collect(view_, r, out, BvhAlphaTest{s_, r})
                                    : bvh_occluded_collect(view_, r, out);
    if (!blocked && shift > 0.0f)
        for (int k = 0; k < out->n; ++k) out->t[k] = float(double(out->t[k]) + shift);
    return blocked;
}

bool BvhAccel::move(int k, const Transform& to_world) {
    if (!two_level_ || !set_instance_transform(tl_, k, to_world)) return false;
    build_tlas(tl_);
    tl_view_ = tl_.view();
    Vec3 b[2];
    instance_world_box(tl_, k, b);
    grow_far_ray_bounds(box_, b);
    return true;
}

}  // namespace lantern
