#include "accel/curve_query_build.h"

#include "scene/motion_build.h"

namespace lantern {

CurveQueryView CurveQuery::view() const {
    CurveQueryView v;
    for (int k = 0; k < kCurveKinds; ++k) v.bvh[k] = bvh[k].view();
    v.moving = moving_views.empty() ? nullptr : moving_views.data();
    v.num_moving = int32_t(moving_views.size());
    v.distinct = distinct;
    v.first_prim = first_prim;
    v.num_segs = num_segs;
    v.motion = motion;
    return v;
}

void curve_query_split(CurveQuery& q, const SceneView& s) {
    q.first_prim = s.num_triangles;
    q.num_segs = s.curves.num_segs;
    q.motion = s.motion;
    const int n = s.curves.num_segs;
    // which strands each kind of ray sees (scene/scene_curves.cpp's flags)
    bool all = true;
    for (int k = 0; k < n && all; ++k) {
        const uint8_t f = s.tri_flags[q.first_prim + k];
        all = (f & kVisibleCamera) && (f & kCastShadow);
    }
    q.distinct = all ? 1 : kCurveKinds;
    // the moving sets' segments go to their own structures (scene/curves.h's CurveSetMotion)
    std::vector<int32_t> set_of(size_t(n), -1);
    q.moving.clear();
    q.moving.resize(size_t(s.curves.num_sets));
    for (int j = 0; j < s.curves.num_sets; ++j) {
        const ObjectMotion& o = s.curves.sets[j].o;
        q.moving[j].set = &s.curves.sets[j];
        for (int k = o.tri_begin; k < o.tri_begin + o.tri_count && k < n; ++k) set_of[k] = j;
    }
    for (int kind = 0; kind < q.distinct; ++kind) {
        q.still[kind].clear();
        for (int k = 0; k < n; ++k) {
            const uint8_t f = s.tri_flags[q.first_prim + k];
            if (kind == 0 && q.distinct == kCurveKinds && !(f & kVisibleCamera)) continue;
            if (kind == 2 && !(f & kCastShadow)) continue;
            // index: the segment's place in the scene
            (set_of[k] < 0 ? q.still[kind] : q.moving[set_of[k]].segs[kind])
                .push_back(s.curves.segs[k]);
        }
    }
}

void curve_query_build(CurveQuery& q, const SceneView& s) {
    curve_query_split(q, s);
    for (int kind = 0; kind < q.distinct; ++kind)
        q.bvh[kind] = build_curve_bvh(q.still[kind], s.curves.keys);  // (moving: all steps)
    q.moving_views.clear();
    for (CurveQuery::Moving& m : q.moving) {
        Vec3 box[2] = {vec3(kInf), vec3(-kInf)};
        for (int kind = 0; kind < q.distinct; ++kind) {
            for (const CurveSeg& g : m.segs[kind]) {
                Vec3 a, b;
                curve_seg_bounds(g, s.curves.keys, &a, &b);
                box[0] = vec3(fminf(box[0].x, a.x), fminf(box[0].y, a.y), fminf(box[0].z, a.z));
                box[1] = vec3(fmaxf(box[1].x, b.x), fmaxf(box[1].y, b.y), fmaxf(box[1].z, b.z));
            }
            m.bvh[kind] = build_curve_bvh(m.segs[kind], s.curves.keys);
        }
        motion_world_box(q.motion, m.set->o, box, m.box);
        CurveMovingSet v;
        v.o = m.set->o;
        v.lo = m.box[0];
        v.hi = m.box[1];
        for (int kind = 0; kind < kCurveKinds; ++kind) v.bvh[kind] = m.bvh[kind].view();
        q.moving_views.push_back(v);
    }
}

namespace {
CurveBvhView copied_bvh(const CurveBvh& b, const CurveQueryCopy& copy, const CurveKeys& keys) {
    CurveBvhView v = b.view();
    v.nodes = b.nodes.empty() ? nullptr
                              : static_cast<const CurveBvhNode*>(
                                    copy(b.nodes.data(), b.nodes.size() * sizeof(CurveBvhNode)));
    v.segs = b.segs.empty() ? nullptr
                            : static_cast<const CurveSeg*>(
                                  copy(b.segs.data(), b.segs.size() * sizeof(CurveSeg)));
    v.keys = keys;
    return v;
}
}  // namespace

CurveQueryView curve_query_copied(const CurveQuery& q, const CurveQueryCopy& copy,
                                  const SceneView& copied) {
    CurveQueryView v = q.view();
    v.motion = copied.motion;
    for (int k = 0; k < kCurveKinds; ++k) v.bvh[k] = copied_bvh(q.bvh[k], copy, copied.curves.keys);
    std::vector<CurveMovingSet> sets(q.moving_views);
    for (size_t j = 0; j < sets.size(); ++j)
        for (int k = 0; k < kCurveKinds; ++k)
            sets[j].bvh[k] = copied_bvh(q.moving[j].bvh[k], copy, copied.curves.keys);
    v.moving = sets.empty() ? nullptr
                            : static_cast<const CurveMovingSet*>(
                                  copy(sets.data(), sets.size() * sizeof(CurveMovingSet)));
    return v;
}

}  // namespace lantern
