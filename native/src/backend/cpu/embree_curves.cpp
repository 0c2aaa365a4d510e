#include "backend/cpu/embree_curves.h"

#include <cstdint>

namespace lantern {

#if LANTERN_HAVE_EMBREE
unsigned embree_attach_curves(const EmbreeApi& e, RTCDevice device, RTCScene scene,
                              const CurveSeg* segs, size_t count, RTCFilterFunctionN filter) {
    RTCGeometry g = e.newGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    auto* v = static_cast<float*>(e.setNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT4, 4 * sizeof(float),
                                                         2 * count));
    auto* idx = static_cast<uint32_t*>(e.setNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t), count));
    for (size_t i = 0; i < count; ++i) {
        const CurveSeg& s = segs[i];
        const float a[8] = {s.p0.x, s.p0.y, s.p0.z, s.r0, s.p1.x, s.p1.y, s.p1.z, s.r1};
        for (int k = 0; k < 8; ++k) v[8 * i + k] = a[k];
        idx[i] = uint32_t(2 * i);
    }
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
