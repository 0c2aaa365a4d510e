// EmbreeAccel's two levels: each mesh a child scene built once (its opaque and alpha-tested
// geometries, as the flat scene has them), placed by an instance geometry in one top scene per
// ray kind (camera rays see only camera-visible meshes, shadow rays only shadow casters). A move
// sets one instance's transform and commits the top scenes again; no child is rebuilt.
#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "accel/tlas_build.h"
#include "backend/cpu/embree_accel.h"
#include "backend/cpu/embree_internal.h"

namespace lantern {

#if LANTERN_HAVE_EMBREE

void EmbreeAccel::build_instanced(const SceneView& s, const std::vector<MeshRange>& meshes) {
    const EmbreeApi& e = embree_api();
    auto dev = static_cast<RTCDevice>(device_);
    two_level_ = true;
    const size_t n = meshes.size();
    // motion blur: a moving mesh's child holds it in object space (motion_base's inverse), its
    // instance interpolates the object-to-world steps as the core does (scene/motion.h: Embree's
    // quaternion decomposition is the same T R U, slerped and lerped)
    std::vector<const ObjectMotion*> moving(n, nullptr);
    SceneView local = s;
    if (s.motion.num_objects > 0) {
        size_t nv = 0;
        for (const MeshRange& m : meshes) nv = std::max(nv, size_t(m.vert_begin + m.vert_count));
        motion_positions_.assign(s.positions, s.positions + nv);
        for (int j = 0; j < s.motion.num_objects; ++j) {
            const ObjectMotion& o = s.motion.objects[j];
            if (o.mesh < 0 || size_t(o.mesh) >= n) continue;
            moving[o.mesh] = &o;
            const MeshRange& m = meshes[o.mesh];
            for (int v = m.vert_begin; v < m.vert_begin + m.vert_count; ++v)
                motion_positions_[v] = o.base_inv.point(s.positions[v]);
        }
        local.positions = motion_positions_.data();
    }
    std::vector<const Built*> all(n, nullptr);
    for (size_t k = 0; k < n; ++k) {
        const MeshRange& m = meshes[k];
        children_.push_back(std::make_unique<Built>(
            build(moving[k] ? local : s, 0, m.tri_begin, m.tri_begin + m.tri_count, true)));
        ++bottom_builds_;
        all[k] = children_.back().get();
    }
    static const float kIdentity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    auto make_top = [&](Top& top, uint8_t need_flag) {
        RTCScene scene = e.newScene(dev);
        top.scene = scene;
        e.setSceneFlags(scene, RTCSceneFlags(RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST));
        e.setSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
        top.geom.assign(n, nullptr);
        top.child.assign(n, nullptr);
        for (size_t k = 0; k < n; ++k) {
            const MeshRange& m = meshes[k];
            int with = 0;
            for (int t = m.tri_begin; t < m.tri_begin + m.tri_count; ++t)
                with += !need_flag || (s.tri_flags[t] & need_flag) ? 1 : 0;
            if (with == 0) continue;
            const Built* child = all[k];
            if (with < m.tri_count) {  // a mesh with mixed flags: its own child for this kind
                children_.push_back(std::make_unique<Built>(
                    build(moving[k] ? local : s, need_flag, m.tri_begin,
                          m.tri_begin + m.tri_count, true)));
                ++bottom_builds_;
                child = children_.back().get();
            }
            if (child->prim_to_tri.empty()) continue;
            RTCGeometry g = e.newGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE);
            e.setGeometryInstancedScene(g, static_cast<RTCScene>(child->scene));
            if (const ObjectMotion* o = moving[k]) {
                e.setGeometryTimeStepCount(g, unsigned(o->num_steps));
                for (int i = 0; i < o->num_steps; ++i) {
                    const MotionStep& st = s.motion.steps[o->first_step + i];
                    RTCQuaternionDecomposition qd;
                    rtcInitQuaternionDecomposition(&qd);
                    rtcQuaternionDecompositionSetQuaternion(&qd, st.q[3], st.q[0], st.q[1],
                                                            st.q[2]);
                    rtcQuaternionDecompositionSetScale(&qd, st.u[0], st.u[3], st.u[5]);
                    rtcQuaternionDecompositionSetSkew(&qd, st.u[1], st.u[2], st.u[4]);
                    rtcQuaternionDecompositionSetTranslation(&qd, st.t[0], st.t[1], st.t[2]);
                    e.setGeometryTransformQuaternion(g, unsigned(i), &qd);
                }
            } else {
                e.setGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, kIdentity);
            }
            e.commitGeometry(g);
            const uint32_t id = e.attachGeometry(scene, g);
            if (top.geom_mesh.size() <= id) top.geom_mesh.resize(id + 1, -1);
            top.geom_mesh[id] = int32_t(k);
            top.geom[k] = g;
            top.child[k] = child;
        }
        e.commitScene(scene);
    };
    bool any_hidden = false, any_no_shadow = false;
    for (int t = 0; t < s.num_triangles; ++t) {
        any_hidden |= !(s.tri_flags[t] & kVisibleCamera);
        any_no_shadow |= !(s.tri_flags[t] & kCastShadow);
    }
    make_top(top_all_, 0);
    if (any_hidden) { make_top(top_camera_, kVisibleCamera); has_camera_ = true; }
    if (any_no_shadow) { make_top(top_shadow_, kCastShadow); has_shadow_ = true; }
}

void EmbreeAccel::release_instanced() {
    const EmbreeApi& e = embree_api();
    for (Top* top : {&top_all_, &top_camera_, &top_shadow_}) {
        for (void* g : top->geom)
            if (g) e.releaseGeometry(static_cast<RTCGeometry>(g));
        if (top->scene) e.releaseScene(static_cast<RTCScene>(top->scene));
        *top = Top{};
    }
    for (auto& c : children_)
        if (c->scene) e.releaseScene(static_cast<RTCScene>(c->scene));
    children_.clear();
}

const EmbreeAccel::Top& EmbreeAccel::top_for_kind(RayKind kind) const {
    if (kind == RayKind::kCamera && has_camera_) return top_camera_;
    if (kind == RayKind::kShadow && has_shadow_) return top_shadow_;
    return top_all_;
}

bool EmbreeAccel::move(int k, const float to_world[12], const Vec3 world_box[2]) {
    if (!two_level_ || k < 0 || size_t(k) >= top_all_.geom.size()) return false;
    const EmbreeApi& e = embree_api();
    for (Top* top : {&top_all_, &top_camera_, &top_shadow_}) {
        if (!top->scene) continue;
        if (top->geom[k]) {
            auto g = static_cast<RTCGeometry>(top->geom[k]);
            e.setGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, to_world);
            e.commitGeometry(g);
        }
        e.commitScene(static_cast<RTCScene>(top->scene));
    }
    grow_far_ray_bounds(box_, world_box);
    return true;
}

HitRecord EmbreeAccel::intersect_instanced(const Ray& r, RayKind kind) const {
    const Top& top = top_for_kind(kind);
    float o[3], tnear, tfar, shift;
    if (!prepare(r, box_, o, &tnear, &tfar, &shift)) return {r.tmax, -1, {0, 0}};
    EmbreeWorldContext wc;
    rtcInitIntersectContext(&wc.ctx);
    std::memcpy(wc.o, o, sizeof(o));
    wc.d[0] = r.d.x, wc.d[1] = r.d.y, wc.d[2] = r.d.z;
    RTCRayHit rh;
    rh.ray.org_x = o[0]; rh.ray.org_y = o[1]; rh.ray.org_z = o[2];
    rh.ray.dir_x = r.d.x; rh.ray.dir_y = r.d.y; rh.ray.dir_z = r.d.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.time = r.time;  // motion blur: moving instances at the path's time
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    embree_api().intersect1(static_cast<RTCScene>(top.scene), &wc.ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.instID[0] >= top.geom_mesh.size())
        return {r.tmax, -1, {0, 0}};
    const Built* child = top.child[top.geom_mesh[rh.hit.instID[0]]];
    const float t = shift > 0.0f ? float(double(rh.ray.tfar) + shift) : rh.ray.tfar;
    return {t, child->tri(rh.hit.geomID, rh.hit.primID), {rh.hit.u, rh.hit.v}};
}

bool EmbreeAccel::occluded_instanced(const Ray& r) const {
    const Top& top = top_for_kind(RayKind::kShadow);
    float o[3], tnear, tfar, shift;
    if (!prepare(r, box_, o, &tnear, &tfar, &shift))
        return !is_finite(r.o) || !is_finite(r.d) || !(r.tmax >= 0.0f);
    EmbreeWorldContext wc;
    rtcInitIntersectContext(&wc.ctx);
    std::memcpy(wc.o, o, sizeof(o));
    wc.d[0] = r.d.x, wc.d[1] = r.d.y, wc.d[2] = r.d.z;
    RTCRay ray;
    ray.org_x = o[0]; ray.org_y = o[1]; ray.org_z = o[2];
    ray.dir_x = r.d.x; ray.dir_y = r.d.y; ray.dir_z = r.d.z;
    ray.tnear = tnear;
    ray.tfar = tfar;
    ray.time = r.time;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    embree_api().occluded1(static_cast<RTCScene>(top.scene), &wc.ctx, &ray);
    return ray.tfar < 0.0f;
}

#else
void EmbreeAccel::build_instanced(const SceneView&, const std::vector<MeshRange>&) {}
void EmbreeAccel::release_instanced() {}
#endif

}  // namespace lantern
