// Light sampling and evaluation with Cycles' conventions (measured with bpy 5.0.1): area light
// radiance P/(pi A) from its front; point/spot intensity P/(4 pi) W/sr with radiance I/(pi r^2)
// on a disk of radius r facing the shaded point (Blender's default "soft falloff": irradiance
// I/(d^2 + r^2)) or on a sphere of radius r (soft falloff off); sun: radiance S/(pi sin^2 a) over
// a cone of half-angle a, so the irradiance on a perpendicular surface is S; mesh emission C*S
// from both sides.
#pragma once

#include "bsdf/principled.h"
#include "core/sampling.h"
#include "scene/alpha.h"
#include "scene/material_program.h"
#include "scene/scene_view.h"

namespace lantern {

// Radiance of an emissive triangle's light at barycentrics bc: its material's emission texture
// there, else the constant radiance (an area-uniform sample of a textured emitter stays
// unbiased: only le varies; light selection uses the texture's mean).
// An emitter of coverage a < 1 (Alpha) gives a of its emission: a ray stops at it with
// probability a (alpha.h), so that is what a camera or BSDF ray sees of it, and what Cycles
// renders; next-event estimation and light paths take it here (difftest D22: 1/a too bright).
LANTERN_HD inline Vec3 triangle_emission(const SceneView& s, const Light& l, Vec2 bc) {
    const Material& m = s.materials[s.tri_material[l.triangle]];
    const float a = alpha_at(s, l.triangle, bc);
    if (!(m.tex_flags & (kTexEmission | kTexProgram))) return l.radiance * a;
    // a node-graph emitter is seen along its normal here (the receiver is not known)
    const uint32_t* idx = s.indices + 3 * l.triangle;
    const Vec3 ng = normalize(cross(s.positions[idx[1]] - s.positions[idx[0]],
                                    s.positions[idx[2]] - s.positions[idx[0]]));
    return material_emission_at(s, m, l.triangle, bc, ng) * a;
}

// What an emissive triangle's layers (a Principled coat or sheen) let out towards the camera
// at cosine cos_l with its normal (bsdf/principled.h principled_emission_through).
LANTERN_HD inline Vec3 triangle_emission_through(const SceneView& s, const Light& l, float cos_l) {
    return principled_emission_through(s.materials[s.tri_material[l.triangle]], cos_l);
}

struct LightSample {
    Vec3 wi;         // unit direction from the reference point towards the light
    float dist;      // distance to the sampled point (kInf for sun and world)
    Vec3 le;         // radiance arriving along -wi (for delta lights: intensity / dist^2)
    float pdf_w;     // solid-angle pdf of wi given this light (1 for delta lights)
    Vec3 p_light;    // sampled point (finite lights)
    Vec3 n_light;    // its geometric normal (zero for points, sun, world)
    bool delta;
    bool valid;
};

// ---- The world: its environment map (SceneView::env), or a constant radiance ----
// Radiance from world direction d (pointing away from the scene).
LANTERN_HD inline Vec3 world_radiance(const SceneView& s, const Light& l, Vec3 d) {
    return s.env.width > 0 ? env_radiance(s.env, d) : l.radiance;
}

// Solid-angle pdf of direction d when next-event estimation samples the world.
LANTERN_HD inline float world_pdf_w(const SceneView& s, Vec3 d) {
    return s.env.width > 0 ? env_pdf_w(s.env, d) : 0.25f * kInvPi;
}

// A direction towards the world, its solid-angle pdf and radiance; false for no sample.
LANTERN_HD inline bool world_sample(const SceneView& s, const Light& l, Vec2 u, Vec3* d,
                                    float* pdf_w, Vec3* le) {
    if (s.env.width > 0) return env_sample(s.env, u, d, pdf_w, le);
    *d = sample_uniform_sphere(u, pdf_w);
    *le = l.radiance;
    return true;
}

LANTERN_HD inline float smoothstep01(float t) {
    t = clampf(t, 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

// Cycles 4.x spot cone: smoothstep over (cos - cos_half) / ((1 - cos_half) * blend).
LANTERN_HD inline float spot_attenuation(const Light& l, Vec3 dir_from_light) {
    Vec3 axis = -l.frame.axis(2);
    float c = dot(dir_from_light, axis);
    if (c <= l.cos_half_spot) return 0.0f;
    if (l.spot_smooth <= 0.0f) return 1.0f;
    return smoothstep01((c - l.cos_half_spot) / l.spot_smooth);
}

LANTERN_HD inline Vec3 triangle_vertex(const SceneView& s, int tri, int k) {
    return s.positions[s.indices[3 * tri + k]];
}

// Triangle tri's edges' cross product (b - a) x (c - a), its corners as exported: its geometric
// normal unnormalized (twice its area long; the sign of its dot with a ray's direction says
// which side the ray meets), and that normal unit length. The shadow loops' re-offset past a
// passed surface or a crossed boundary (bidir_medium_blocked, pt_shadow_linked_query,
// pt_boundary_side) take it from here.
LANTERN_HD inline Vec3 triangle_cross(const SceneView& s, int tri) {
    const Vec3 a = triangle_vertex(s, tri, 0), b = triangle_vertex(s, tri, 1),
               c = triangle_vertex(s, tri, 2);
    return cross(b - a, c - a);
}

LANTERN_HD inline Vec3 triangle_geometric_normal(const SceneView& s, int tri) {
    return normalize(triangle_cross(s, tri));
}

// ---- A moving emitter (motion blur, docs/motion_blur.md "A moving emitter") ----
// An emissive triangle where its mesh is at shutter time `time`: its corners (a deforming
// mesh's lerped in its exported frame, then the object's matrix at that time, as the ray
// queries and motion_surface place it) and its area there; `moved` false (corners as exported,
// area l.area) where its mesh does not move. Sampling (sample_light, sample_emission) and the
// densities (light_area_at) take the area from this one function, so that they agree bit for
// bit. Out of line: a moving light's corners stay out of its callers' frames (pt's chunk kernel
// is near the device's stack cap); scenes without moving meshes never call it.
struct MovedTriangle {
    Vec3 v[3];
    float area;
    bool moved;
};
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline MovedTriangle light_triangle_at(const SceneView& s, const Light& l, float time) {
    MovedTriangle r;
    for (int j = 0; j < 3; ++j) r.v[j] = triangle_vertex(s, l.triangle, j);
    r.area = l.area;
    r.moved = false;
    const ObjectMotion* o = object_motion_of(s.motion, l.triangle);
    if (!o) return r;
    if (const DeformMesh* dm = deform_of(s.motion, *o))
        deform_triangle(s.motion, *dm, l.triangle, time, r.v);
    const Transform m = object_motion_to_world(s.motion, *o, time);
    for (int j = 0; j < 3; ++j) r.v[j] = m.point(r.v[j]);
    r.area = 0.5f * length(cross(r.v[1] - r.v[0], r.v[2] - r.v[0]));
    r.moved = true;
    return r;
}

// The area of light l at shutter time `time` (a moving emissive triangle's there; else l.area),
// for the densities of what sample_light and sample_emission drew at that time.
LANTERN_HD inline float light_area_at(const SceneView& s, const Light& l, float time) {
    if (l.type != kLightTriangle || s.motion.num_objects == 0) return l.area;
    return light_triangle_at(s, l, time).area;
}

// Ray / sphere: nearest t in (tmin, tmax) or -1.
LANTERN_HD inline float intersect_sphere(Vec3 o, Vec3 d, Vec3 c, float r, float tmin, float tmax) {
    Vec3 oc = o - c;
    float b = dot(oc, d);
    float cc = dot(oc, oc) - r * r;
    float disc = b * b - cc;
    if (disc < 0.0f) return -1.0f;
    float sq = sqrtf(disc);
    float t = -b - sq;
    if (t <= tmin) t = -b + sq;
    return (t > tmin && t < tmax) ? t : -1.0f;
}

// Point on an area light for local coordinates (a, b) in [-1, 1]^2 (rectangle) or the disk.
LANTERN_HD inline Vec3 area_point(const Light& l, Vec2 u) {
    Vec2 q;
    if (l.shape == kShapeEllipse) {
        q = sample_concentric_disk(u);
    } else {
        q = {2.0f * u.x - 1.0f, 2.0f * u.y - 1.0f};
    }
    return l.frame.origin() + l.frame.axis(0) * (q.x * l.half_x) + l.frame.axis(1) * (q.y * l.half_y);
}

// ---- Solid-angle sampling of a rectangular area light (Urena, Fajardo & King 2013, "An
// area-preserving parametrization for spherical rectangles"): the rectangle as seen from p is a
// spherical rectangle of solid angle S, sampled uniformly (pdf 1/S), so that next-event
// estimation's pdf follows the light's solid angle instead of its area (Cycles does the same).
// Where S is tiny the two differ little and S's float cancellation (about 1e-6 sr) would
// matter, and next to the light's plane the parametrization degenerates: there, and behind the
// emitting side, the light keeps area sampling. The choice is a function of (l, p) alone, so
// sample_light and light_pdf_w make the same one.
struct SphericalRect {
    Vec3 o, x, y, z;            // reference point; the rectangle's axes and emitting normal
    float x0, x1, y0, y1, z0;   // the rectangle in that frame: [x0, x1] x [y0, y1] at z = z0 < 0
    float b0, b1, k, solid_angle;
};

constexpr float kRectMinSolidAngle = 1e-2f;  // sr; below it, area sampling
constexpr float kRectMinPlaneDist = 1e-3f;   // of the light's larger half extent

// The spherical rectangle of rectangular light l seen from p; false where l is not a rectangle
// or area sampling is kept (see above).
LANTERN_HD inline bool spherical_rect(const Light& l, Vec3 p, SphericalRect* r) {
    if (l.type != kLightArea || l.shape != kShapeRectangle) return false;
    const Vec3 ex = l.frame.axis(0), ey = l.frame.axis(1), n = -l.frame.axis(2);
    const Vec3 corner = l.frame.origin() - ex * l.half_x - ey * l.half_y;
    const Vec3 d = corner - p;
    const float h = -dot(d, n);  // height of p above the emitting side
    if (!(h > kRectMinPlaneDist * fmaxf(l.half_x, l.half_y))) return false;
    r->o = p;
    r->x = ex;
    r->y = ey;
    r->z = n;  // from the light towards p; the light lies at z0 = -h
    r->x0 = dot(d, ex);
    r->y0 = dot(d, ey);
    r->z0 = -h;
    r->x1 = r->x0 + 2.0f * l.half_x;
    r->y1 = r->y0 + 2.0f * l.half_y;
    const float z0 = r->z0;
    // normals of the planes through p and each edge (in the local frame), then the angles
    // between neighbouring ones: the spherical rectangle's interior angles
    const Vec3 n0 = normalize(vec3(0.0f, z0, -r->y0));
    const Vec3 n1 = normalize(vec3(-z0, 0.0f, r->x1));
    const Vec3 n2 = normalize(vec3(0.0f, -z0, r->y1));
    const Vec3 n3 = normalize(vec3(z0, 0.0f, -r->x0));
    const float g0 = acosf(clampf(-dot(n0, n1), -1.0f, 1.0f));
    const float g1 = acosf(clampf(-dot(n1, n2), -1.0f, 1.0f));
    const float g2 = acosf(clampf(-dot(n2, n3), -1.0f, 1.0f));
    const float g3 = acosf(clampf(-dot(n3, n0), -1.0f, 1.0f));
    r->b0 = n0.z;
    r->b1 = n2.z;
    r->k = 2.0f * kPi - g2 - g3;
    r->solid_angle = g0 + g1 - r->k;
    return r->solid_angle >= kRectMinSolidAngle && r->solid_angle < 2.0f * kPi;
}

// The point of the spherical rectangle for u in [0, 1)^2 (uniform in solid angle).
LANTERN_HD inline Vec3 spherical_rect_point(const SphericalRect& r, Vec2 u) {
    const float au = u.x * r.solid_angle + r.k;
    const float fu = (cosf(au) * r.b0 - r.b1) / sinf(au);
    float cu = copysignf(1.0f, fu) / sqrtf(fu * fu + r.b0 * r.b0);
    cu = clampf(cu, -1.0f, 1.0f);
    float xu = -(cu * r.z0) / safe_sqrt(1.0f - cu * cu);
    xu = clampf(xu, r.x0, r.x1);
    const float dd = sqrtf(xu * xu + r.z0 * r.z0);
    const float h0 = r.y0 / sqrtf(dd * dd + r.y0 * r.y0);
    const float h1 = r.y1 / sqrtf(dd * dd + r.y1 * r.y1);
    const float hv = h0 + u.y * (h1 - h0), hv2 = hv * hv;
    const float yv = hv2 < 1.0f - 1e-6f ? hv * dd / sqrtf(1.0f - hv2) : r.y1;
    return r.o + r.x * xu + r.y * clampf(yv, r.y0, r.y1) + r.z * r.z0;
}

// A soft-falloff disk (radius r, centre at distance d) seen from p: p lies on its axis, so it
// fills the cone of half-angle atan(r / d) about the direction to the centre; 1 - cos of that
// angle, r^2 / (h (h + d)) with h = sqrt(d^2 + r^2), without the cancellation of 1 - d / h.
LANTERN_HD inline float soft_disk_one_minus_cos(float d2, float r2) {
    const float h = sqrtf(d2 + r2);
    return r2 / (h * (h + sqrtf(d2)));
}

// The area density on the disk facing p (a soft-falloff light's, centre c) of the point that
// next-event estimation from p reaches along unit wi: the cone's 1 / (2 pi (1 - cos)) times
// cos_y / |p - y|^2, with cos_y = dot(wi, (c - p) / d) and |p - y| = d / cos_y. What the
// bidirectional weights need where a light path made that point (light_path.h).
LANTERN_HD inline float soft_cone_area_pdf(const Light& l, Vec3 p, Vec3 wi) {
    const Vec3 to_c = l.position - p;
    const float d2 = length_sq(to_c);
    if (!(d2 > 0.0f)) return 0.0f;
    const float cos_y = dot(wi, to_c) / sqrtf(d2);
    if (!(cos_y > 0.0f)) return 0.0f;
    return cos_y * cos_y * cos_y / (2.0f * kPi * soft_disk_one_minus_cos(d2, l.radius * l.radius) *
                                    d2);
}

// Next-event estimation of a soft-falloff disk (every integrator's): its point is drawn
// uniformly in the solid angle the disk subtends, not uniformly over its area. Its radiance is
// constant, so the estimate of its light (phase function or BSDF times cosine aside) is exact;
// by area the estimate at a point d << r from the centre would weigh the disk's middle by
// r^2 / d^2 (relative second moment ~ r^2 / (8 d^2)), whose integral along a ray through the
// bulb diverges: the fireflies in fog around a lamp (docs/volumes.md). Light paths that start
// on such a disk take y0 by area (soft_light_path.h); their weights use soft_cone_area_pdf.
// `time`: the path's shutter time (motion blur: a moving emissive triangle is sampled where it
// is then; read only in scenes whose meshes move).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline LightSample sample_light(const SceneView& s, const Light& l, Vec3 p, Vec2 u,
                                           float time) {
    LightSample ls{};
    ls.valid = false;
    ls.delta = false;
    switch (l.type) {
    case kLightPoint:
    case kLightSpot: {
        Vec3 to_c = l.position - p;
        float d2 = length_sq(to_c);
        if (!(d2 > 0.0f)) return ls;
        float d = sqrtf(d2);
        Vec3 dir = to_c / d;
        float atten = l.type == kLightSpot ? spot_attenuation(l, -dir) : 1.0f;
        if (l.radius <= 0.0f) {
            if (atten <= 0.0f) return ls;
            ls.wi = dir;
            ls.dist = d;
            ls.le = l.intensity * (atten / d2);
            ls.pdf_w = 1.0f;
            ls.delta = true;
            ls.p_light = l.position;
        } else if (l.soft_falloff) {
            // the disk facing p, uniform in the cone it subtends (cos from 1 - a, a in [0, omc])
            const float omc = soft_disk_one_minus_cos(d2, l.radius * l.radius);
            const float a = u.x * omc;
            const float cos_t = 1.0f - a, sin_t = safe_sqrt(a * (2.0f - a));
            const float phi = 2.0f * kPi * u.y;
            Frame f = Frame::from_normal(dir);
            const Vec3 w = f.to_world(Vec3{sin_t * cosf(phi), sin_t * sinf(phi), cos_t});
            const float t = d / cos_t;  // to the disk's plane through the centre
            if (!(t > 0.0f) || !(t < kInf)) return ls;
            ls.wi = w;
            ls.dist = t;
            ls.pdf_w = 1.0f / (2.0f * kPi * omc);
            if (!(ls.pdf_w > 0.0f) || !(ls.pdf_w < kInf)) return ls;
            ls.p_light = p + w * t;
            ls.n_light = -dir;
            ls.le = l.radiance * (l.type == kLightSpot ? spot_attenuation(l, -w) : 1.0f);
        } else if (d2 <= l.radius * l.radius) {
            // inside the sphere light: its far side, uniform over directions; no spot cone
            // (Cycles: a receiver inside a sphere light sees its whole inner surface, unshaped)
            Vec3 w = sample_uniform_sphere(u, &ls.pdf_w);
            float t = intersect_sphere(p, w, l.position, l.radius, 0.0f, kInf);
            if (!(t > 0.0f)) return ls;
            ls.wi = w;
            ls.dist = t;
            ls.p_light = p + w * t;
            ls.n_light = normalize(ls.p_light - l.position);
            ls.le = l.radiance;
        } else {
            Frame f = Frame::from_normal(dir);
            Vec3 w = f.to_world(sample_sphere_solid_angle(u, d2, l.radius, &ls.pdf_w));
            if (!(ls.pdf_w > 0.0f)) return ls;
            float t = intersect_sphere(p, w, l.position, l.radius, 0.0f, kInf);
            if (t < 0.0f) t = dot(to_c, w);  // grazing: numerical miss of the silhouette
            ls.wi = w;
            ls.dist = t;
            ls.p_light = p + w * t;
            ls.n_light = normalize(ls.p_light - l.position);
            ls.le = l.radiance * (l.type == kLightSpot ? spot_attenuation(l, -w) : 1.0f);
        }
        ls.valid = true;
        return ls;
    }
    case kLightArea: {
        SphericalRect sr;
        const bool by_solid_angle = spherical_rect(l, p, &sr);
        Vec3 q = by_solid_angle ? spherical_rect_point(sr, u) : area_point(l, u);
        Vec3 to = q - p;
        float d2 = length_sq(to);
        if (!(d2 > 0.0f)) return ls;
        float d = sqrtf(d2);
        Vec3 wi = to / d;
        Vec3 n = -l.frame.axis(2);
        float cos_l = -dot(wi, n);
        if (cos_l <= 0.0f) return ls;  // behind the emitting side
        ls.wi = wi;
        ls.dist = d;
        ls.le = l.radiance;
        ls.pdf_w = by_solid_angle ? 1.0f / sr.solid_angle : pdf_a_to_w(1.0f / l.area, d2, cos_l);
        ls.p_light = q;
        ls.n_light = n;
        ls.valid = true;
        return ls;
    }
    case kLightTriangle: {
        Vec3 a = triangle_vertex(s, l.triangle, 0), b = triangle_vertex(s, l.triangle, 1),
             c = triangle_vertex(s, l.triangle, 2);
        float area = l.area;
        if (s.motion.num_objects > 0) {  // a moving mesh's: where it is at the path's time
            const MovedTriangle mt = light_triangle_at(s, l, time);
            a = mt.v[0];
            b = mt.v[1];
            c = mt.v[2];
            area = mt.area;
        }
        Vec2 bc = sample_triangle(u);
        Vec3 q = a * (1.0f - bc.x - bc.y) + b * bc.x + c * bc.y;
        Vec3 to = q - p;
        float d2 = length_sq(to);
        if (!(d2 > 0.0f)) return ls;
        float d = sqrtf(d2);
        Vec3 wi = to / d;
        Vec3 n = normalize(cross(b - a, c - a));
        float cos_l = fabsf(dot(wi, n));
        if (cos_l <= 0.0f) return ls;
        ls.wi = wi;
        ls.dist = d;
        ls.le = triangle_emission(s, l, bc);
        ls.pdf_w = pdf_a_to_w(1.0f / area, d2, cos_l);
        ls.p_light = q;
        ls.n_light = dot(wi, n) < 0.0f ? n : -n;  // facing the reference point
        ls.valid = true;
        return ls;
    }
    case kLightSun: {
        Vec3 to_sun = -l.direction;
        ls.dist = kInf;
        if (l.cos_sun >= 1.0f) {
            ls.wi = to_sun;
            ls.le = l.intensity;  // irradiance
            ls.pdf_w = 1.0f;
            ls.delta = true;
        } else {
            Frame f = Frame::from_normal(to_sun);
            ls.wi = f.to_world(sample_uniform_cone(u, l.cos_sun, &ls.pdf_w));
            ls.le = l.radiance;
        }
        ls.valid = true;
        return ls;
    }
    case kLightWorld: {
        ls.dist = kInf;
        if (!world_sample(s, l, u, &ls.wi, &ls.pdf_w, &ls.le)) return ls;
        ls.valid = true;
        return ls;
    }
    default:
        return ls;
    }
}

// Solid-angle pdf with which sample_light would produce direction wi from p, for a light hit at
// distance t with surface normal n (area, sphere and triangle lights; the sun ignores t; the
// world's is world_pdf_w; a soft-falloff disk's: its cone, the same for every point on it).
LANTERN_HD inline float light_pdf_w(const Light& l, Vec3 p, Vec3 wi, float t, Vec3 n) {
    switch (l.type) {
    case kLightPoint:
    case kLightSpot: {
        if (l.radius <= 0.0f) return 0.0f;
        if (l.soft_falloff) {
            const float d2 = length_sq(l.position - p);
            if (!(d2 > 0.0f)) return 0.0f;
            return 1.0f / (2.0f * kPi * soft_disk_one_minus_cos(d2, l.radius * l.radius));
        }
        float d2 = length_sq(l.position - p);
        if (d2 <= l.radius * l.radius) return 1.0f / (4.0f * kPi);  // inside: uniform
        return pdf_uniform_cone(safe_sqrt(1.0f - l.radius * l.radius / d2));
    }
    case kLightArea: {
        SphericalRect sr;
        if (spherical_rect(l, p, &sr)) return 1.0f / sr.solid_angle;
        return pdf_a_to_w(1.0f / l.area, t * t, fabsf(dot(wi, n)));
    }
    case kLightTriangle:
        return pdf_a_to_w(1.0f / l.area, t * t, fabsf(dot(wi, n)));
    case kLightSun:
        if (l.cos_sun >= 1.0f) return 0.0f;
        return dot(wi, -l.direction) >= l.cos_sun ? pdf_uniform_cone(l.cos_sun) : 0.0f;
    default:  // the world: world_pdf_w, which reads the scene's environment map
        return 0.0f;
    }
}

// light_pdf_w for a light point found at the path's shutter time `time` (a moving emissive
// triangle's density from its area then: light_area_at).
LANTERN_HD inline float light_pdf_w_at(const SceneView& s, const Light& l, Vec3 p, Vec3 wi,
                                       float t, Vec3 n, float time) {
    if (l.type == kLightTriangle && s.motion.num_objects > 0)
        return pdf_a_to_w(1.0f / light_area_at(s, l, time), t * t, fabsf(dot(wi, n)));
    return light_pdf_w(l, p, wi, t, n);
}

// Radiance a ray along d sees when it hits a non-mesh light at distance t (< tmax), else zero.
// Lights are not opaque (as in Cycles): the path continues behind them.
struct LightHit {
    Vec3 le;
    float t;
    Vec3 n;
    bool hit;
};

LANTERN_HD inline LightHit intersect_light(const Light& l, Vec3 o, Vec3 d, float tmin, float tmax) {
    LightHit h{vec3(0.0f), 0.0f, vec3(0.0f), false};
    if (l.type == kLightPoint || l.type == kLightSpot) {
        if (l.radius <= 0.0f) return h;
        float t;
        Vec3 n;
        if (l.soft_falloff) {  // the disk facing the ray's origin
            n = normalize(o - l.position);
            float denom = dot(d, n);
            if (denom >= 0.0f) return h;
            t = dot(l.position - o, n) / denom;
            if (!(t > tmin && t < tmax)) return h;
            if (length_sq(o + d * t - l.position) > l.radius * l.radius) return h;
        } else {
            t = intersect_sphere(o, d, l.position, l.radius, tmin, tmax);
            if (t < 0.0f) return h;
            n = normalize(o + d * t - l.position);
        }
        // a ray from inside the sphere sees it unshaped by the spot cone, as sample_light
        const bool inside = !l.soft_falloff && length_sq(o - l.position) <= l.radius * l.radius;
        float atten = l.type == kLightSpot && !inside ? spot_attenuation(l, -d) : 1.0f;
        h = {l.radiance * atten, t, n, true};
        return h;
    }
    if (l.type == kLightArea) {
        Vec3 n = -l.frame.axis(2);
        float denom = dot(d, n);
        if (denom == 0.0f) return h;
        float t = dot(l.frame.origin() - o, n) / denom;
        if (!(t > tmin && t < tmax)) return h;
        Vec3 q = o + d * t - l.frame.origin();
        float a = dot(q, l.frame.axis(0)) / l.half_x, b = dot(q, l.frame.axis(1)) / l.half_y;
        bool inside = l.shape == kShapeEllipse ? (a * a + b * b <= 1.0f)
                                               : (fabsf(a) <= 1.0f && fabsf(b) <= 1.0f);
        if (!inside) return h;
        h.t = t;
        h.n = n;
        h.hit = true;
        h.le = denom < 0.0f ? l.radiance : vec3(0.0f);  // front side only
        return h;
    }
    return h;
}

}  // namespace lantern
