#include "backend/cpu/embree_accel.h"

#include <stdexcept>

#include "backend/cpu/embree_loader.h"
#include "scene/alpha.h"

namespace lantern {

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

// Zero area (repeated or collinear vertices): no normal, never a meaningful hit.
bool degenerate_triangle(const SceneView& s, int t) {
    Vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
         c = s.positions[s.indices[3 * t + 2]];
    float a2 = length_sq(cross(b - a, c - a));
    return !(a2 > 0.0f) || !is_finite(a2);
}

bool usable_triangle(const SceneView& s, int t) {
    return finite_triangle(s, t) && !degenerate_triangle(s, t);
}

}  // namespace

EmbreeAccel::EmbreeAccel(const SceneView& s, std::vector<std::string>& warnings) {
    const EmbreeApi& e = embree_api();
    device_ = e.newDevice(nullptr);
    if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");
    e.setDeviceErrorFunction(static_cast<RTCDevice>(device_), on_error, &warnings);
    int nonfinite = 0, degenerate = 0;
    for (int t = 0; t < s.num_triangles; ++t) {
        if (!finite_triangle(s, t)) ++nonfinite;
        else if (degenerate_triangle(s, t)) ++degenerate;
    }
    if (nonfinite) {
        warnings.push_back(std::to_string(nonfinite) +
                           " triangle(s) with non-finite vertices were left out");
    }
    if (degenerate) {
        warnings.push_back(std::to_string(degenerate) +
                           " degenerate (zero-area) triangle(s) were left out");
    }
    bool any_hidden = false, any_no_shadow = false;
    for (int t = 0; t < s.num_triangles; ++t) {
        any_hidden |= !(s.tri_flags[t] & kVisibleCamera);
        any_no_shadow |= !(s.tri_flags[t] & kCastShadow);
    }
    all_ = build(s, 0);
    if (any_hidden) { camera_ = build(s, kVisibleCamera); has_camera_ = true; }
    if (any_no_shadow) { shadow_ = build(s, kCastShadow); has_shadow_ = true; }
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
        if (!alpha_stops(f->s, tri, bary, o, d)) args->valid[i] = 0;
    }
}

}  // namespace

EmbreeAccel::Built EmbreeAccel::build(const SceneView& s, uint8_t need_flag) {
    const EmbreeApi& e = embree_api();
    auto dev = static_cast<RTCDevice>(device_);
    Built b;
    RTCScene scene = e.newScene(dev);
    b.scene = scene;
    e.setSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    e.setSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    std::vector<int32_t> alpha;
    for (int t = 0; t < s.num_triangles; ++t) {
        if (need_flag && !(s.tri_flags[t] & need_flag)) continue;
        if (!usable_triangle(s, t)) continue;
        if (s.tri_flags[t] & kAlphaTested) alpha.push_back(t);
        else b.prim_to_tri.push_back(t);
    }
    const size_t n = b.prim_to_tri.size();
    if (n > 0) {
        RTCGeometry g = make_geometry(e, dev, s, b.prim_to_tri.data(), n);
        e.commitGeometry(g);
        e.attachGeometry(scene, g);
        e.releaseGeometry(g);
    }
    if (!alpha.empty()) {
        b.alpha_base = n;
        b.prim_to_tri.insert(b.prim_to_tri.end(), alpha.begin(), alpha.end());
        b.filter.reset(new AlphaFilter{s, b.prim_to_tri.data() + n});
        RTCGeometry g = make_geometry(e, dev, s, alpha.data(), alpha.size());
        e.setGeometryUserData(g, b.filter.get());
        e.setGeometryIntersectFilterFunction(g, alpha_filter);
        e.setGeometryOccludedFilterFunction(g, alpha_filter);
        e.commitGeometry(g);
        b.alpha_geom = e.attachGeometry(scene, g);
        e.releaseGeometry(g);
    }
    e.commitScene(scene);
    return b;
}

EmbreeAccel::~EmbreeAccel() {
    if (!embree_available()) return;
    const EmbreeApi& e = embree_api();
    for (Built* b : {&all_, &camera_, &shadow_}) {
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
    const Built& b = for_kind(kind);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = r.o.x; rh.ray.org_y = r.o.y; rh.ray.org_z = r.o.z;
    rh.ray.dir_x = r.d.x; rh.ray.dir_y = r.d.y; rh.ray.dir_z = r.d.z;
    rh.ray.tnear = r.tmin;
    rh.ray.tfar = r.tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    embree_api().intersect1(static_cast<RTCScene>(b.scene), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {r.tmax, -1, {0, 0}};
    return {rh.ray.tfar, b.tri(rh.hit.geomID, rh.hit.primID), {rh.hit.u, rh.hit.v}};
}

bool EmbreeAccel::occluded(const Ray& r) const {
    const Built& b = for_kind(RayKind::kShadow);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray;
    ray.org_x = r.o.x; ray.org_y = r.o.y; ray.org_z = r.o.z;
    ray.dir_x = r.d.x; ray.dir_y = r.d.y; ray.dir_z = r.d.z;
    ray.tnear = r.tmin;
    ray.tfar = r.tmax;
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    embree_api().occluded1(static_cast<RTCScene>(b.scene), &ctx, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}
#else
EmbreeAccel::EmbreeAccel(const SceneView&, std::vector<std::string>&) {
    throw std::runtime_error("Lantern was built without Embree: the CPU backend is unavailable");
}
EmbreeAccel::~EmbreeAccel() = default;
HitRecord EmbreeAccel::intersect(const Ray& r, RayKind) const { return {r.tmax, -1, {0, 0}}; }
bool EmbreeAccel::occluded(const Ray&) const { return false; }
#endif

}  // namespace lantern
