#include "backend/cpu/curve_accel.h"

#include <stdexcept>

#include "backend/cpu/embree_curves.h"

namespace lantern {

#if LANTERN_HAVE_EMBREE
namespace {
// Entries only, as accel/curve_hit.h: a hit whose normal does not face the ray is dropped.
void curve_front_filter(const RTCFilterFunctionNArguments* args) {
    for (unsigned k = 0; k < args->N; ++k) {
        if (args->valid[k] != -1) continue;
        const unsigned n = args->N;
        const float nx = RTCHitN_Ng_x(args->hit, n, k), ny = RTCHitN_Ng_y(args->hit, n, k),
                    nz = RTCHitN_Ng_z(args->hit, n, k);
        const float dx = RTCRayN_dir_x(args->ray, n, k), dy = RTCRayN_dir_y(args->ray, n, k),
                    dz = RTCRayN_dir_z(args->ray, n, k);
        if (nx * dx + ny * dy + nz * dz >= 0.0f) args->valid[k] = 0;
    }
}
}  // namespace

struct CurveAccel::Embree {
    const EmbreeApi& e = embree_api();
    RTCDevice device = nullptr;
    RTCScene scene[3] = {nullptr, nullptr, nullptr};
    ~Embree() {
        for (RTCScene sc : scene)
            if (sc) e.releaseScene(sc);
        if (device) e.releaseDevice(device);
    }
};
#else
struct CurveAccel::Embree {};
#endif

CurveAccel::CurveAccel(const SceneView& s, bool use_embree, std::vector<std::string>& warnings) {
    first_prim_ = s.num_triangles;
    steps_ = s.curves.keys.num_steps;
    const int n = s.curves.num_segs;
    // which strands each kind of ray sees (scene/scene_curves.cpp's flags)
    bool all = true;
    for (int k = 0; k < n && all; ++k) {
        const uint8_t f = s.tri_flags[first_prim_ + k];
        all = (f & kVisibleCamera) && (f & kCastShadow);
    }
    distinct_ = all ? 1 : 3;
    for (int kind = 0; kind < distinct_; ++kind) {
        std::vector<CurveSeg>& v = by_kind_[kind];
        for (int k = 0; k < n; ++k) {
            const uint8_t f = s.tri_flags[first_prim_ + k];
            if (kind == 0 && distinct_ == 3 && !(f & kVisibleCamera)) continue;
            if (kind == 2 && !(f & kCastShadow)) continue;
            v.push_back(s.curves.segs[k]);  // index: the segment's place in the scene
        }
    }
    if (use_embree) {
#if LANTERN_HAVE_EMBREE
        embree_ = std::make_unique<Embree>();
        embree_->device = embree_->e.newDevice(nullptr);
        if (!embree_->device) throw std::runtime_error("Embree: no device for the strands");
        for (int kind = 0; kind < distinct_; ++kind) {
            RTCScene sc = embree_->e.newScene(embree_->device);
            embree_->scene[kind] = sc;
            if (!by_kind_[kind].empty())
                embree_attach_curves(embree_->e, embree_->device, sc, by_kind_[kind].data(),
                                     by_kind_[kind].size(), curve_front_filter, s.curves.keys);
            embree_->e.commitScene(sc);
        }
        return;
#else
        throw std::runtime_error("Embree is not built in");
#endif
    }
    for (int kind = 0; kind < distinct_; ++kind)
        bvh_[kind] = build_curve_bvh(by_kind_[kind], s.curves.keys);  // (moving: all steps)
    (void)warnings;
}

CurveAccel::~CurveAccel() = default;

int CurveAccel::kind_index(RayKind kind) const {
    if (distinct_ == 1) return 0;
    return kind == RayKind::kCamera ? 0 : (kind == RayKind::kShadow ? 2 : 1);
}

void CurveAccel::closer(const Ray& r, RayKind kind, HitRecord* h) const {
    const float tmax = h->prim >= 0 ? h->t : r.tmax;
    if (!(tmax > r.tmin)) return;
    const int ki = kind_index(kind);
#if LANTERN_HAVE_EMBREE
    if (embree_) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh{};
        rh.ray.org_x = r.o.x, rh.ray.org_y = r.o.y, rh.ray.org_z = r.o.z;
        rh.ray.dir_x = r.d.x, rh.ray.dir_y = r.d.y, rh.ray.dir_z = r.d.z;
        rh.ray.tnear = r.tmin;
        rh.ray.tfar = fminf(tmax, 1.8e18f);
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.time = embree_curve_time(r.time, steps_);  // moving strands (motion blur)
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        embree_->e.intersect1(embree_->scene[ki], &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return;
        *h = HitRecord{rh.ray.tfar, first_prim_ + by_kind_[ki][rh.hit.primID].index,
                       {rh.hit.u, 0.0f}};
        return;
    }
#endif
    const CurveBvhHit c = curve_bvh_intersect(bvh_[ki].view(), r.o, r.d, r.tmin, tmax, false,
                                              r.time);
    if (c.seg < 0) return;
    *h = HitRecord{c.t, first_prim_ + c.seg, {c.u, 0.0f}};
}

bool CurveAccel::occluded(const Ray& r) const {
    const int ki = kind_index(RayKind::kShadow);
#if LANTERN_HAVE_EMBREE
    if (embree_) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRay ray{};
        ray.org_x = r.o.x, ray.org_y = r.o.y, ray.org_z = r.o.z;
        ray.dir_x = r.d.x, ray.dir_y = r.d.y, ray.dir_z = r.d.z;
        ray.tnear = r.tmin;
        ray.tfar = fminf(r.tmax, 1.8e18f);
        ray.mask = 0xFFFFFFFFu;
        ray.time = embree_curve_time(r.time, steps_);
        embree_->e.occluded1(embree_->scene[ki], &ctx, &ray);
        return ray.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
    }
#endif
    return curve_bvh_intersect(bvh_[ki].view(), r.o, r.d, r.tmin, r.tmax, true, r.time).seg >= 0;
}

}  // namespace lantern
