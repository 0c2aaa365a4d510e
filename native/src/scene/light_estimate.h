// What one local light gives a point, for the light tree's choice between two leaves
// (scene/light_tree.h): the unshadowed irradiance (luminance) on the receiver's side, exact for
// a polygon (area light, emissive triangle: Lambert's formula over the part above the receiver's
// horizon) and for a disk or sphere above the horizon (point lights), smoothly clipped where it
// straddles it. Zero behind a one-sided light's plane; n = 0 (a point that transmits) counts the
// light as if the receiver faced it.
#pragma once

#include "core/sampling.h"
#include "scene/scene_view.h"

namespace lantern {

// Irradiance (per unit radiance) at the origin from the planar polygon v[0..count) (relative to
// the point, count <= 4), clipped to the half-space dot(n, x) >= 0: (1/2) sum_j angle_j (n . g_j)
// with g_j the unit normal of the plane through the origin and edge j [Lambert; Arvo 1995].
// Out of line on the device: its unrolled atan2f loop was inlined at every light tree estimate
// (a sixth of pt's shade kernel for ptxas; docs/cuda_backend.md, "Build time").
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline float polygon_irradiance(const Vec3* v, int count, Vec3 n) {
    Vec3 c[8];
    int m = 0;
    for (int j = 0; j < count; ++j) {  // Sutherland-Hodgman against the receiver's plane
        const Vec3 a = v[j], b = v[(j + 1) % count];
        const float da = dot(n, a), db = dot(n, b);
        if (da >= 0.0f) c[m++] = a;
        if ((da >= 0.0f) != (db >= 0.0f)) {
            const float t = da / (da - db);
            c[m++] = a + (b - a) * t;
        }
    }
    if (m < 3) return 0.0f;
    float sum = 0.0f;
    for (int j = 0; j < m; ++j) {
        const Vec3 a = c[j], b = c[(j + 1) % m];
        const float la = length(a), lb = length(b);
        if (!(la > 0.0f) || !(lb > 0.0f)) continue;
        const Vec3 g = cross(a, b);
        const float lg = length(g);
        if (!(lg > 0.0f)) continue;
        const float angle = atan2f(lg, dot(a, b));  // between the two directions, well-conditioned
        sum += angle * dot(n, g) / lg;
    }
    return 0.5f * fabsf(sum);
}

// A source of angular radius asin(sin_u) about a direction at cosine cos_i from the normal: the
// share of its normal-incidence irradiance the receiver gets, cos_i when it is wholly above the
// horizon, (cos_i + sin_u)^2 / (4 sin_u) where the horizon cuts it (continuous, zero when it has
// set), as for a sphere light [Snyder 1996].
LANTERN_HD inline float horizon_clipped_cosine(float cos_i, float sin_u) {
    if (cos_i >= sin_u) return cos_i;
    if (cos_i <= -sin_u) return 0.0f;
    const float t = cos_i + sin_u;
    return t * t / (4.0f * sin_u);
}

// Unshadowed irradiance (luminance) that light l gives point p with normal n (0: both sides);
// -1 for a light this does not model (spot, distant): the caller keeps the bound.
LANTERN_HD inline float light_irradiance_estimate(const SceneView& s, const Light& l, Vec3 p,
                                                  Vec3 n) {
    const bool two_sided = n.x == 0.0f && n.y == 0.0f && n.z == 0.0f;
    switch (l.type) {
    case kLightArea: {
        const Vec3 c = l.frame.origin() - p, axis = -l.frame.axis(2);
        if (!(dot(c, axis) < 0.0f)) return 0.0f;  // behind the emitting side, or in its plane
        const Vec3 x = l.frame.axis(0) * l.half_x, y = l.frame.axis(1) * l.half_y;
        const Vec3 v[4] = {c - x - y, c + x - y, c + x + y, c - x + y};
        // an ellipse: its bounding rectangle's irradiance times the areas' ratio
        const float shape = l.shape == kShapeEllipse ? 0.25f * kPi : 1.0f;
        const float lum = l.area > 0.0f ? l.tree_energy / l.area : 0.0f;  // radiance
        return lum * shape * polygon_irradiance(v, 4, two_sided ? normalize(c) : n);
    }
    case kLightTriangle: {
        const uint32_t* t = s.indices + 3 * l.triangle;
        const Vec3 v[3] = {s.positions[t[0]] - p, s.positions[t[1]] - p, s.positions[t[2]] - p};
        const Vec3 c = (v[0] + v[1] + v[2]) * (1.0f / 3.0f);
        const float lum = l.area > 0.0f ? l.tree_energy / l.area : 0.0f;  // both sides emit
        return lum * polygon_irradiance(v, 3, two_sided ? normalize(c) : n);
    }
    case kLightPoint: {
        const Vec3 w = l.position - p;
        const float d2 = length_sq(w), r2 = l.radius * l.radius;
        const float lum = l.tree_energy;  // intensity, W/sr
        if (!l.soft_falloff && d2 <= r2) return lum / fmaxf(r2, 1e-20f);  // inside the sphere
        if (!(d2 > 0.0f)) return lum / fmaxf(r2, 1e-20f);
        // Blender's soft falloff: I / (d^2 + r^2) at normal incidence; a sphere: I / d^2
        const float e = lum / (l.soft_falloff ? d2 + r2 : d2);
        if (two_sided) return e;
        const float d = sqrtf(d2);
        const float sin_u = l.soft_falloff ? l.radius / sqrtf(d2 + r2) : l.radius / d;
        return e * horizon_clipped_cosine(dot(n, w) / d, sin_u);
    }
    default:
        return -1.0f;
    }
}

}  // namespace lantern
