#include "backend/cpu/embree_accel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "backend/cpu/embree_internal.h"
#include "backend/cpu/embree_loader.h"
#include "scene/alpha.h"
#include "scene/scene_limits.h"

namespace lantern {

// ---- Rays Embree can take ----
// Embree asserts (SIGABRT) unless every origin and direction component is within
// FLT_LARGE = 1.844e18 and tnear, tfar are not NaN (scene/scene_limits.h). Every triangle lies
// within kMaxCoordinate, so a ray that starts outside that cube is moved, in double, to where it
// enters `box` (the triangles' bounds, padded; `shift` is added back to the hit distance): close
// enough that Embree's float tests still find the scene (from the cube's face a 1e17 m quad was
// missed). One that misses the box misses the scene. Non-finite rays and directions that large
// are refused. False: nothing to trace. Rays that start within the cube are passed unchanged.
bool EmbreeAccel::prepare(const Ray& r, const Vec3 box[2], float o[3], float* tnear,
                          float* tfar, float* shift) {
    const float d[3] = {r.d.x, r.d.y, r.d.z};
    const float org[3] = {r.o.x, r.o.y, r.o.z};
    for (int k = 0; k < 3; ++k)
        if (!(std::fabs(d[k]) <= kMaxCoordinate) || !std::isfinite(org[k])) return false;
    if (!(r.tmax >= 0.0f)) return false;  // NaN or negative
    *tnear = r.tmin >= 0.0f ? r.tmin : 0.0f;
    *tfar = r.tmax;
    *shift = 0.0f;
    if (within_limit(r.o)) {
        for (int k = 0; k < 3; ++k) o[k] = org[k];
        return true;
    }
    // slab test against the box in double
    const double lim = double(kMaxCoordinate);
    double t0 = 0.0, t1 = double(r.tmax);
    int enter = -1;      // the axis whose face the ray enters through
    double face = 0.0;   // and that face's coordinate
    for (int k = 0; k < 3; ++k) {
        const double lo = double(box[0][k]), hi = double(box[1][k]);
        if (!(lo <= hi)) return false;  // an empty scene
        if (d[k] == 0.0f) {
            if (org[k] < lo || org[k] > hi) return false;
            continue;
        }
        const double a = (lo - double(org[k])) / double(d[k]),
                     b = (hi - double(org[k])) / double(d[k]);
        const double near = std::min(a, b);
        if (near > t0) {
            t0 = near;
            enter = k;
            face = d[k] > 0.0f ? lo : hi;
        }
        t1 = std::min(t1, std::max(a, b));
    }
    if (!(t0 <= t1) || t0 >= double(r.tmax)) return false;
    for (int k = 0; k < 3; ++k) {
        // the entry face exactly: org + t0 d there is a difference of two numbers of 1e19
        const double p = k == enter ? face : double(org[k]) + t0 * double(d[k]);
        o[k] = float(std::min(lim, std::max(-lim, p)));
    }
    *shift = float(t0);
    *tnear = float(std::max(0.0, double(*tnear) - t0));
    *tfar = float(double(r.tmax) - t0);
    return true;
}

void grow_far_ray_bounds(Vec3 box[2], const Vec3 b[2]) {
    if (!(b[0].x <= b[1].x)) return;
    const float pad = 1e-3f * max_component(b[1] - b[0]) + 1e-3f;
    box[0] = {std::fmin(box[0].x, b[0].x - pad), std::fmin(box[0].y, b[0].y - pad),
              std::fmin(box[0].z, b[0].z - pad)};
    box[1] = {std::fmax(box[1].x, b[1].x + pad), std::fmax(box[1].y, b[1].y + pad),
              std::fmax(box[1].z, b[1].z + pad)};
}

void far_ray_bounds(const SceneView& s, Vec3 box[2]) {
    box[0] = vec3(kInf);
    box[1] = vec3(-kInf);
    for (int t = 0; t < s.num_triangles; ++t) {
        const Vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
                   c = s.positions[s.indices[3 * t + 2]];
        const double a2 = triangle_area2(a, b, c);
        if (!(a2 > 0.0) || !std::isfinite(a2)) continue;  // what the accelerators leave out
        for (const Vec3& p : {a, b, c}) {
            box[0] = {std::fmin(box[0].x, p.x), std::fmin(box[0].y, p.y), std::fmin(box[0].z, p.z)};
            box[1] = {std::fmax(box[1].x, p.x), std::fmax(box[1].y, p.y), std::fmax(box[1].z, p.z)};
        }
    }
    if (!(box[0].x <= box[1].x)) return;  // no usable triangle: every far ray misses
    const float pad = 1e-3f * max_component(box[1] - box[0]) + 1e-3f;
    box[0] = box[0] - vec3(pad);
    box[1] = box[1] + vec3(pad);
}

#if LANTERN_HAVE_EMBREE
namespace {

void on_error(void* user, RTCError code, const char* msg) {
    auto* w = static_cast<std::vector<std::string>*>(user);
    if (w && w->size() < 64) w->push_back(std::string("Embree error ") +
                                          std::to_string(int(code)) + ": " + (msg ? msg : ""));
}

bool finite_triangle(const SceneView& s, int t) {
    for (int k = 0; k < 3; ++k) {
        if (!is_finite(s.positions[s.indices[3 * t + k]])) return false;
    }
    return true;
}

// Zero area (repeated or collinear vertices): no normal, never a meaningful hit. In double:
// in float the test overflows for edges over ~4e9 m and took such triangles for degenerate.
bool degenerate_triangle(const SceneView& s, int t) {
    Vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
         c = s.positions[s.indices[3 * t + 2]];
    const double a2 = triangle_area2(a, b, c);
    return !(a2 > 0.0) || !std::isfinite(a2);
}

bool usable_triangle(const SceneView& s, int t) {
    return finite_triangle(s, t) && !degenerate_triangle(s, t);
}

}  // namespace

EmbreeAccel::EmbreeAccel(const SceneView& s, std::vector<std::string>& warnings,
                         const std::vector<MeshRange>* meshes) {
    const EmbreeApi& e = embree_api();
    device_ = e.newDevice(nullptr);
    if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");
    e.setDeviceErrorFunction(static_cast<RTCDevice>(device_), on_error, &warnings);
    int nonfinite = 0, degenerate = 0;
    for (int t = 0; t < s.num_triangles; ++t) {
        if (!finite_triangle(s, t)) ++nonfinite;
        else if (degenerate_triangle(s, t)) ++degenerate;
    }
    far_ray_bounds(s, box_);
    if (nonfinite) {
        warnings.push_back(std::to_string(nonfinite) +
                           " triangle(s) with non-finite vertices were left out");
    }
    if (degenerate) {
        warnings.push_back(std::to_string(degenerate) +
                           " degenerate (zero-area) triangle(s) were left out");
    }
    bool any_hidden = false, any_no_shadow = false, any_bound = false;
    for (int t = 0; t < s.num_triangles; ++t) {
        any_hidden |= !(s.tri_flags[t] & kVisibleCamera);
        any_no_shadow |= !(s.tri_flags[t] & kCastShadow);
        any_bound |= (s.tri_flags[t] & (kCastShadow | kVolumeBoundary)) ==
                     (kCastShadow | kVolumeBoundary);
    }
    if (meshes) {
        build_instanced(s, *meshes);
        return;
    }
    all_ = build(s, 0);
    bottom_builds_ = 1;
    if (any_hidden) { camera_ = build(s, kVisibleCamera); has_camera_ = true; }
    if (any_no_shadow) { shadow_ = build(s, kCastShadow); has_shadow_ = true; }
    if (any_bound) { collect_ = build(s, kCastShadow, 0, -1, false, true); has_collect_ = true; }
}

namespace {

// Unindexed copy: three vertices per triangle (Embree pads the buffer itself).
RTCGeometry make_geometry(const EmbreeApi& e, RTCDevice dev, const SceneView& s,
                          const int32_t* tris, size_t n) {
    RTCGeometry g = e.newGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(e.setNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
    auto* idx = static_cast<uint32_t*>(e.setNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), n));
    if (!v || !idx) {
        e.releaseGeometry(g);
        throw std::runtime_error("Embree: out of memory building the scene");
    }
    for (size_t k = 0; k < n; ++k) {
        int t = tris[k];
        for (int j = 0; j < 3; ++j) {
            Vec3 p = s.positions[s.indices[3 * t + j]];
            v[9 * k + 3 * j + 0] = p.x;
            v[9 * k + 3 * j + 1] = p.y;
            v[9 * k + 3 * j + 2] = p.z;
            idx[3 * k + j] = uint32_t(3 * k + j);
        }
    }
    return g;
}

// Deformation blur: a deforming mesh's child geometry (instanced: its triangles all of one mesh,
// in its object space) takes one vertex buffer per step, Embree lerping them at the ray's time
// as the core does (scene/motion.h deform_triangle); its instance places it.
void set_deform_steps(const EmbreeApi& e, RTCGeometry g, const SceneView& s, const int32_t* tris,
                      size_t n) {
    if (n == 0 || s.motion.num_objects == 0) return;
    const ObjectMotion* o = object_motion_of(s.motion, tris[0]);
    const DeformMesh* dm = o ? deform_of(s.motion, *o) : nullptr;
    if (!dm) return;
    e.setGeometryTimeStepCount(g, unsigned(dm->num_steps));
    for (int k = 0; k < dm->num_steps; ++k) {
        auto* v = static_cast<float*>(e.setNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, unsigned(k), RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
        if (!v) {
            e.releaseGeometry(g);
            throw std::runtime_error("Embree: out of memory building the scene");
        }
        for (size_t i = 0; i < n; ++i) {
            const Vec3* c = s.motion.deform_corners + dm->first +
                            3 * (k * dm->tri_count + (tris[i] - dm->tri_begin));
            for (int j = 0; j < 3; ++j) {
                const Vec3 p = o->base_inv.point(c[j]);
                v[9 * i + 3 * j + 0] = p.x;
                v[9 * i + 3 * j + 1] = p.y;
                v[9 * i + 3 * j + 2] = p.z;
            }
        }
    }
}

// Intersect and occluded filter of alpha-tested geometry: rejects the hits that alpha passes.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
    const auto* f = static_cast<const EmbreeAccel::AlphaFilter*>(args->geometryUserPtr);
    const unsigned n = args->N;
    for (unsigned i = 0; i < n; ++i) {
        if (args->valid[i] != -1) continue;
        int32_t tri = f->prim_to_tri[RTCHitN_primID(args->hit, n, i)];
        Vec2 bary{RTCHitN_u(args->hit, n, i), RTCHitN_v(args->hit, n, i)};
        Vec3 o{RTCRayN_org_x(args->ray, n, i), RTCRayN_org_y(args->ray, n, i),
               RTCRayN_org_z(args->ray, n, i)};
        Vec3 d{RTCRayN_dir_x(args->ray, n, i), RTCRayN_dir_y(args->ray, n, i),
               RTCRayN_dir_z(args->ray, n, i)};
        if (f->instanced) {  // the ray is in the instance's space: alpha sees the world's
            const auto* w = reinterpret_cast<const EmbreeWorldContext*>(args->context);
            o = {w->o[0], w->o[1], w->o[2]};
            d = {w->d[0], w->d[1], w->d[2]};
        }
        if (!alpha_stops(f->s, tri, bary, o, d)) args->valid[i] = 0;
    }
}

// Occluded filter of occluded_collect's volume-boundary geometries (flat scenes): a hit (past
// the alpha test, for the alpha-tested one) is recorded and rejected, so the query goes on;
// out of room, accepted (the query stops, out->n is -1).
template <bool kAlpha>
void collect_filter(const RTCFilterFunctionNArguments* args) {
    const auto* f = static_cast<const EmbreeAccel::AlphaFilter*>(args->geometryUserPtr);
    BoundaryHits* out = reinterpret_cast<const EmbreeCollectContext*>(args->context)->out;
    const unsigned n = args->N;
    for (unsigned i = 0; i < n; ++i) {
        if (args->valid[i] != -1) continue;
        const int32_t tri = f->prim_to_tri[RTCHitN_primID(args->hit, n, i)];
        const Vec2 bary{RTCHitN_u(args->hit, n, i), RTCHitN_v(args->hit, n, i)};
        if (kAlpha) {
            const Vec3 o{RTCRayN_org_x(args->ray, n, i), RTCRayN_org_y(args->ray, n, i),
                         RTCRayN_org_z(args->ray, n, i)};
            const Vec3 d{RTCRayN_dir_x(args->ray, n, i), RTCRayN_dir_y(args->ray, n, i),
                         RTCRayN_dir_z(args->ray, n, i)};
            if (!alpha_stops(f->s, tri, bary, o, d)) {
                args->valid[i] = 0;
                continue;
            }
        }
        // (the candidate's distance is in the ray's tfar while its filter runs)
        if (out && out->add(tri, RTCRayN_tfar(args->ray, n, i), bary)) args->valid[i] = 0;
    }
}

}  // namespace

EmbreeAccel::Built EmbreeAccel::build(const SceneView& s, uint8_t need_flag, int begin,
                                      int end, bool instanced, bool split_bounds) {
    const EmbreeApi& e = embree_api();
    auto dev = static_cast<RTCDevice>(device_);
    Built b;
    RTCScene scene = e.newScene(dev);
    b.scene = scene;
    e.setSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    e.setSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    std::vector<int32_t> alpha, bound_alpha;
    if (end < 0) end = s.num_triangles;
    for (int t = begin; t < end; ++t) {
        if (need_flag && !(s.tri_flags[t] & need_flag)) continue;
        if (!usable_triangle(s, t)) continue;
        if (split_bounds && (s.tri_flags[t] & kVolumeBoundary)) {
            (s.tri_flags[t] & kAlphaTested ? bound_alpha : b.bound_tris).push_back(t);
            continue;
        }
        if (s.tri_flags[t] & kAlphaTested) alpha.push_back(t);
        else b.prim_to_tri.push_back(t);
    }
    const size_t n = b.prim_to_tri.size();
    if (n > 0) {
        RTCGeometry g = make_geometry(e, dev, s, b.prim_to_tri.data(), n);
        if (instanced) set_deform_steps(e, g, s, b.prim_to_tri.data(), n);
        e.commitGeometry(g);
        e.attachGeometry(scene, g);
        e.releaseGeometry(g);
    }
    if (!alpha.empty()) {
        b.alpha_base = n;
        b.prim_to_tri.insert(b.prim_to_tri.end(), alpha.begin(), alpha.end());
        b.filter.reset(new AlphaFilter{s, b.prim_to_tri.data() + n, instanced});
        RTCGeometry g = make_geometry(e, dev, s, alpha.data(), alpha.size());
        if (instanced) set_deform_steps(e, g, s, alpha.data(), alpha.size());
        e.setGeometryUserData(g, b.filter.get());
        e.setGeometryIntersectFilterFunction(g, alpha_filter);
        e.setGeometryOccludedFilterFunction(g, alpha_filter);
        e.commitGeometry(g);
        b.alpha_geom = e.attachGeometry(scene, g);
        e.releaseGeometry(g);
    }
    // split_bounds: the boundaries, opaque then alpha-tested, each a geometry whose occluded
    // filter records them (collect_filter)
    const size_t nb = b.bound_tris.size();
    b.bound_tris.insert(b.bound_tris.end(), bound_alpha.begin(), bound_alpha.end());
    for (int a = 0; a < 2; ++a) {
        const size_t first = a ? nb : 0, count = a ? b.bound_tris.size() - nb : nb;
        if (count == 0) continue;
        b.bound_filter[a].reset(new AlphaFilter{s, b.bound_tris.data() + first, false});
        RTCGeometry g = make_geometry(e, dev, s, b.bound_tris.data() + first, count);
        e.setGeometryUserData(g, b.bound_filter[a].get());
        e.setGeometryOccludedFilterFunction(g, a ? collect_filter<true> : collect_filter<false>);
        e.commitGeometry(g);
        e.attachGeometry(scene, g);
        e.releaseGeometry(g);
    }
    e.commitScene(scene);
    return b;
}

EmbreeAccel::~EmbreeAccel() {
    if (!embree_available()) return;
    const EmbreeApi& e = embree_api();
    release_instanced();
    for (Built* b : {&all_, &camera_, &shadow_, &collect_}) {
        if (b->scene) e.releaseScene(static_cast<RTCScene>(b->scene));
    }
    if (device_) e.releaseDevice(static_cast<RTCDevice>(device_));
}

const EmbreeAccel::Built& EmbreeAccel::for_kind(RayKind kind) const {
    if (kind == RayKind::kCamera && has_camera_) return camera_;
    if (kind == RayKind::kShadow && has_shadow_) return shadow_;
    return all_;
}

HitRecord EmbreeAccel::intersect(const Ray& r, RayKind kind) const {
    if (two_level_) return intersect_instanced(r, kind);
    const Built& b = for_kind(kind);
    float o[3], tnear, tfar, shift;
    if (!prepare(r, box_, o, &tnear, &tfar, &shift)) return {r.tmax, -1, {0, 0}};
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = o[0]; rh.ray.org_y = o[1]; rh.ray.org_z = o[2];
    rh.ray.dir_x = r.d.x; rh.ray.dir_y = r.d.y; rh.ray.dir_z = r.d.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    embree_api().intersect1(static_cast<RTCScene>(b.scene), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {r.tmax, -1, {0, 0}};
    const float t = shift > 0.0f ? float(double(rh.ray.tfar) + shift) : rh.ray.tfar;
    return {t, b.tri(rh.hit.geomID, rh.hit.primID), {rh.hit.u, rh.hit.v}};
}

bool EmbreeAccel::occluded(const Ray& r) const {
    if (two_level_) return occluded_instanced(r);
    const Built& b = for_kind(RayKind::kShadow);
    float o[3], tnear, tfar, shift;
    if (!prepare(r, box_, o, &tnear, &tfar, &shift)) {
        // a segment outside everything is free; a non-finite one carries no light
        return !is_finite(r.o) || !is_finite(r.d) || !(r.tmax >= 0.0f);
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray;
    ray.org_x = o[0]; ray.org_y = o[1]; ray.org_z = o[2];
    ray.dir_x = r.d.x; ray.dir_y = r.d.y; ray.dir_z = r.d.z;
    ray.tnear = tnear;
    ray.tfar = tfar;
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    embree_api().occluded1(static_cast<RTCScene>(b.scene), &ctx, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

bool EmbreeAccel::occluded_collect(const Ray& r, BoundaryHits* out) const {
    out->n = 0;
    if (two_level_ || !has_collect_) {  // (two levels: the caller's loop; no boundary: none)
        if (two_level_) out->n = -1;
        return two_level_ ? false : occluded(r);
    }
    float o[3], tnear, tfar, shift;
    if (!prepare(r, box_, o, &tnear, &tfar, &shift))
        return !is_finite(r.o) || !is_finite(r.d) || !(r.tmax >= 0.0f);
    EmbreeCollectContext cc;
    rtcInitIntersectContext(&cc.ctx);
    cc.out = out;
    RTCRay ray;
    ray.org_x = o[0]; ray.org_y = o[1]; ray.org_z = o[2];
    ray.dir_x = r.d.x; ray.dir_y = r.d.y; ray.dir_z = r.d.z;
    ray.tnear = tnear;
    ray.tfar = tfar;
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    embree_api().occluded1(static_cast<RTCScene>(collect_.scene), &cc.ctx, &ray);
    if (ray.tfar < 0.0f) return true;  // blocked (or out of room: out->n -1)
    if (shift > 0.0f)
        for (int k = 0; k < out->n; ++k) out->t[k] = float(double(out->t[k]) + shift);
    return false;
}
#else
EmbreeAccel::EmbreeAccel(const SceneView&, std::vector<std::string>&,
                         const std::vector<MeshRange>*) {
    throw std::runtime_error("Lantern was built without Embree: the CPU backend is unavailable");
}
EmbreeAccel::~EmbreeAccel() = default;
HitRecord EmbreeAccel::intersect(const Ray& r, RayKind) const { return {r.tmax, -1, {0, 0}}; }
bool EmbreeAccel::occluded(const Ray&) const { return false; }
bool EmbreeAccel::occluded_collect(const Ray&, BoundaryHits* out) const {
    out->n = -1;
    return false;
}
bool EmbreeAccel::move(int, const float*, const Vec3*) { return false; }
#endif

}  // namespace lantern
