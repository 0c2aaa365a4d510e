#include "backend/cpu/curve_accel.h"

#include <cmath>
#include <stdexcept>

#include "backend/cpu/embree_curves.h"

namespace lantern {

#if LANTERN_HAVE_EMBREE
namespace {
// Entries only, as accel/curve_hit.h: a hit whose normal does not face the ray is dropped (in an
// instance both are in its object space: the sign of n . d survives an affine map).
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

// Segment g (exported frame) in its object's space: points by base_inv, radii by its scale
// (uniform: the cube root of the determinant, as Cycles keeps a hair's radius under a uniform
// scale)
CurveSeg curve_in_object(const CurveSeg& g, const Transform& base_inv, float scale) {
    CurveSeg o = g;
    o.p0 = base_inv.point(g.p0);
    o.p1 = base_inv.point(g.p1);
    o.r0 = g.r0 * scale;
    o.r1 = g.r1 * scale;
    return o;
}
}  // namespace

struct CurveAccel::Embree {
    const EmbreeApi& e = embree_api();
    RTCDevice device = nullptr;
    RTCScene scene[3] = {nullptr, nullptr, nullptr};
    std::vector<RTCScene> children;  // the moving sets' object-space scenes
    // per kind, per geometry of its scene: the segments its primIDs index (the still strands'
    // or a moving set's, whose instance's geomID it is)
    std::vector<const std::vector<CurveSeg>*> geoms[3];
    ~Embree() {
        for (RTCScene sc : scene)
            if (sc) e.releaseScene(sc);
        for (RTCScene sc : children) e.releaseScene(sc);
        if (device) e.releaseDevice(device);
    }
};
#else
struct CurveAccel::Embree {};
#endif

CurveAccel::CurveAccel(const SceneView& s, bool use_embree, std::vector<std::string>& warnings) {
    steps_ = s.curves.keys.num_steps;
    if (use_embree) {
#if LANTERN_HAVE_EMBREE
        curve_query_split(q_, s);
        const int distinct_ = q_.distinct;
        std::vector<CurveSeg>* by_kind_ = q_.still;
        const std::vector<CurveQuery::Moving>& moving_ = q_.moving;
        embree_ = std::make_unique<Embree>();
        const EmbreeApi& e = embree_->e;
        embree_->device = e.newDevice(nullptr);
        if (!embree_->device) throw std::runtime_error("Embree: no device for the strands");
        auto note = [&](int kind, unsigned id, const std::vector<CurveSeg>* segs) {
            if (embree_->geoms[kind].size() <= id) embree_->geoms[kind].resize(id + 1, nullptr);
            embree_->geoms[kind][id] = segs;
        };
        for (int kind = 0; kind < distinct_; ++kind) {
            RTCScene sc = e.newScene(embree_->device);
            embree_->scene[kind] = sc;
            if (!by_kind_[kind].empty())
                note(kind,
                     embree_attach_curves(e, embree_->device, sc, by_kind_[kind].data(),
                                          by_kind_[kind].size(), curve_front_filter,
                                          s.curves.keys),
                     &by_kind_[kind]);
            for (const CurveQuery::Moving& m : moving_) {
                const std::vector<CurveSeg>& segs = m.segs[kind];
                if (segs.empty()) continue;
                // the set in object space, its keys (where it also deforms) likewise
                const ObjectMotion& o = m.set->o;
                const float* b = &o.base_inv.m[0][0];
                const float det = b[0] * (b[5] * b[10] - b[6] * b[9]) -
                                  b[1] * (b[4] * b[10] - b[6] * b[8]) +
                                  b[2] * (b[4] * b[9] - b[5] * b[8]);
                const float scale = std::cbrt(std::fabs(det));
                std::vector<CurveSeg> local(segs.size()), keys;
                const CurveKeys& ks = s.curves.keys;
                const int steps = ks.num_steps > 1 ? ks.num_steps : 0;
                if (steps) keys.resize(size_t(steps) * segs.size());
                for (size_t i = 0; i < segs.size(); ++i) {
                    local[i] = curve_in_object(segs[i], o.base_inv, scale);
                    local[i].index = int32_t(i);
                    for (int st = 0; st < steps; ++st) {
                        CurveSeg& k = keys[size_t(st) * segs.size() + i];
                        k = (segs[i].flags & kCurveMoves)
                                ? curve_in_object(ks.keys[size_t(st) * size_t(ks.num_segs) +
                                                          size_t(segs[i].index)],
                                                  o.base_inv, scale)
                                : local[i];
                        k.index = int32_t(i);
                        k.flags = segs[i].flags;
                    }
                }
                RTCScene child = e.newScene(embree_->device);
                embree_->children.push_back(child);
                embree_attach_curves(e, embree_->device, child, local.data(), local.size(),
                                     curve_front_filter,
                                     CurveKeys{keys.empty() ? nullptr : keys.data(), steps,
                                               int32_t(segs.size())});
                e.commitScene(child);
                RTCGeometry g = e.newGeometry(embree_->device, RTC_GEOMETRY_TYPE_INSTANCE);
                e.setGeometryInstancedScene(g, child);
                e.setGeometryTimeStepCount(g, unsigned(o.num_steps));
                for (int i = 0; i < o.num_steps; ++i) {  // as embree_instances.cpp's meshes
                    const MotionStep& st = s.motion.steps[o.first_step + i];
                    RTCQuaternionDecomposition qd;
                    rtcInitQuaternionDecomposition(&qd);
                    rtcQuaternionDecompositionSetQuaternion(&qd, st.q[3], st.q[0], st.q[1],
                                                            st.q[2]);
                    rtcQuaternionDecompositionSetScale(&qd, st.u[0], st.u[3], st.u[5]);
                    rtcQuaternionDecompositionSetSkew(&qd, st.u[1], st.u[2], st.u[4]);
                    rtcQuaternionDecompositionSetTranslation(&qd, st.t[0], st.t[1], st.t[2]);
                    e.setGeometryTransformQuaternion(g, unsigned(i), &qd);
                }
                e.commitGeometry(g);
                note(kind, e.attachGeometry(sc, g), &segs);
                e.releaseGeometry(g);
            }
            e.commitScene(sc);
        }
        (void)warnings;
        return;
#else
        throw std::runtime_error("Embree is not built in");
#endif
    }
    curve_query_build(q_, s);  // the built-in BVH: the host+device query's arrays
    view_ = q_.view();
    (void)warnings;
}

CurveAccel::~CurveAccel() = default;

int CurveAccel::kind_index(RayKind kind) const {
    if (q_.distinct == 1) return 0;
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
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        embree_->e.intersect1(embree_->scene[ki], &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return;
        // a moving set's hit: its instance is the top scene's geometry
        const unsigned top =
            rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
        if (top >= embree_->geoms[ki].size() || !embree_->geoms[ki][top]) return;
        *h = HitRecord{rh.ray.tfar, q_.first_prim + (*embree_->geoms[ki][top])[rh.hit.primID].index,
                       {rh.hit.u, 0.0f}};
        return;
    }
#endif
    const CurveBvhHit c = curve_query_closest(view_, r, ki, tmax);
    if (c.seg < 0) return;
    *h = HitRecord{c.t, view_.first_prim + c.seg, {c.u, 0.0f}};
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
    return curve_query_occluded(view_, r, ki);
}

}  // namespace lantern
