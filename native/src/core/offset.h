// Self-intersection avoidance: one rule for every backend (Waechter & Binder, "A Fast and
// Robust Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6). The point moves
// along the geometric normal by a few ulps, or by a fixed epsilon near the origin. The paper's
// constants assume a scene of about unit size; `scale` (SceneView::offset_scale, min(1, scene
// radius)) shrinks the near-origin region and its epsilon with the scene, so a millimetre-sized
// scene is not offset by 1/65536 m (about 1% of it).
#pragma once

#include <cstring>

#include "core/math.h"

namespace lantern {

LANTERN_HD inline float offset_component(float p, float n, float scale = 1.0f) {
    constexpr float kOrigin = 1.0f / 32.0f;
    constexpr float kFloatScale = 1.0f / 65536.0f;
    constexpr float kIntScale = 256.0f;
    if (fabsf(p) < kOrigin * scale) return p + kFloatScale * scale * n;
    int32_t bits;
    memcpy(&bits, &p, sizeof bits);
    int32_t of = int32_t(kIntScale * n);
    bits += (p < 0.0f) ? -of : of;
    float r;
    memcpy(&r, &bits, sizeof r);
    return r;
}

// p moved off the surface with geometric normal ng, to the side of direction w.
LANTERN_HD inline Vec3 offset_ray_origin(Vec3 p, Vec3 ng, Vec3 w, float scale = 1.0f) {
    Vec3 n = dot(ng, w) < 0.0f ? -ng : ng;
    return {offset_component(p.x, n.x, scale), offset_component(p.y, n.y, scale),
            offset_component(p.z, n.z, scale)};
}

}  // namespace lantern
