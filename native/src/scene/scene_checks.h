// The input checks that HostScene's parts share (scene.cpp, scene_lights.cpp,
// scene_materials.cpp, scene_meshes.cpp): a scalar or colour clamped to its range with a
// fallback for NaN, a camera's or light's rotation without its scale. Host only.
#pragma once

#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace lantern {

// A scalar input: clamped to [lo, hi] when finite, `fallback` when NaN or infinite.
inline float finite_in(float v, float lo, float hi, float fallback) {
    return std::isfinite(v) ? std::min(std::max(v, lo), hi) : fallback;
}

inline Vec3 sanitize_color(Vec3 c, float hi) {
    auto f = [hi](float v) { return finite_in(v, 0.0f, hi, 0.0f); };
    return {f(c.x), f(c.y), f(c.z)};
}

// Rotation part of a row-major 4x4 with its scale removed (Gram-Schmidt on the columns).
inline Transform rigid(const float m[16]) {
    Transform t = transform_from_rows(m);
    Vec3 x = normalize(t.axis(0));
    Vec3 y = t.axis(1) - x * dot(t.axis(1), x);
    y = normalize(y);
    Vec3 z = cross(x, y);
    if (dot(z, t.axis(2)) < 0.0f) z = -z;
    Vec3 cols[3] = {x, y, z};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) t.m[r][c] = cols[c][r];
    }
    return t;
}

}  // namespace lantern
