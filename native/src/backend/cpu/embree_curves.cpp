#include "backend/cpu/embree_curves.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace lantern {

#if LANTERN_HAVE_EMBREE
unsigned embree_attach_curves(const EmbreeApi& e, RTCDevice device, RTCScene scene,
                              const CurveSeg* segs, size_t count, RTCFilterFunctionN filter,
                              CurveKeys keys) {
    // joined segments share their joint's vertex, so that Embree finds each one's neighbours
    // at index - 1 and index + 2 (RTC_CURVE_FLAG_NEIGHBOR_*: no sphere at the joint)
    std::vector<float> verts;
    std::vector<uint32_t> first(count);
    std::vector<uint8_t> flags(count, 0);
    verts.reserve(8 * count);
    auto push = [&](Vec3 p, float r) {
        verts.insert(verts.end(), {p.x, p.y, p.z, r});
    };
    for (size_t i = 0; i < count; ++i) {
        const CurveSeg& s = segs[i];
        const bool joined = (s.flags & kCurveJoinStart) && i > 0 &&
                            (segs[i - 1].flags & kCurveJoinEnd) && segs[i - 1].p1.x == s.p0.x &&
                            segs[i - 1].p1.y == s.p0.y && segs[i - 1].p1.z == s.p0.z &&
                            segs[i - 1].r1 == s.r0;
        if (joined) {
            flags[i] |= RTC_CURVE_FLAG_NEIGHBOR_LEFT;
            flags[i - 1] |= RTC_CURVE_FLAG_NEIGHBOR_RIGHT;
        } else {
            push(s.p0, s.r0);
        }
        first[i] = uint32_t(verts.size() / 4 - 1);
        push(s.p1, s.r1);
    }
    RTCGeometry g = e.newGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    bool moves = false;
    for (size_t i = 0; i < count && keys.num_steps > 1 && !moves; ++i)
        moves = (segs[i].flags & kCurveMoves) != 0;
    const unsigned steps = moves ? unsigned(keys.num_steps) : 1u;
    if (moves) e.setGeometryTimeStepCount(g, steps);
    for (unsigned st = 1; st < steps; ++st) {  // the same layout at every step (slot st)
        std::vector<float> at;
        at.reserve(verts.size());
        for (size_t i = 0; i < count; ++i) {
            const CurveSeg k = (segs[i].flags & kCurveMoves)
                                   ? keys.keys[size_t(st) * size_t(keys.num_segs) +
                                               size_t(segs[i].index)]
                                   : segs[i];
            if (!(flags[i] & RTC_CURVE_FLAG_NEIGHBOR_LEFT))
                at.insert(at.end(), {k.p0.x, k.p0.y, k.p0.z, k.r0});
            at.insert(at.end(), {k.p1.x, k.p1.y, k.p1.z, k.r1});
        }
        auto* v = static_cast<float*>(e.setNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, st,
                                                             RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                                             at.size() / 4));
        std::copy(at.begin(), at.end(), v);
    }
    if (moves) {  // step 0: the keys' first step (the frame's segments are some other step)
        size_t w = 0;
        for (size_t i = 0; i < count; ++i) {
            const CurveSeg k = (segs[i].flags & kCurveMoves)
                                   ? keys.keys[size_t(segs[i].index)]
                                   : segs[i];
            if (!(flags[i] & RTC_CURVE_FLAG_NEIGHBOR_LEFT)) {
                verts[w++] = k.p0.x, verts[w++] = k.p0.y, verts[w++] = k.p0.z, verts[w++] = k.r0;
            }
            verts[w++] = k.p1.x, verts[w++] = k.p1.y, verts[w++] = k.p1.z, verts[w++] = k.r1;
        }
    }
    auto* v = static_cast<float*>(e.setNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                                         verts.size() / 4));
    auto* idx = static_cast<uint32_t*>(e.setNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t), count));
    auto* fl = static_cast<uint8_t*>(e.setNewGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0,
                                                           RTC_FORMAT_UCHAR, sizeof(uint8_t),
                                                           count));
    std::copy(verts.begin(), verts.end(), v);
    std::copy(first.begin(), first.end(), idx);
    std::copy(flags.begin(), flags.end(), fl);
    if (filter) {
        e.setGeometryIntersectFilterFunction(g, filter);
        e.setGeometryOccludedFilterFunction(g, filter);
    }
    e.commitGeometry(g);
    const unsigned id = e.attachGeometry(scene, g);
    e.releaseGeometry(g);
    return id;
}
#endif

}  // namespace lantern
