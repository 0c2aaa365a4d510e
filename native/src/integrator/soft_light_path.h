// Light sub-paths from soft-falloff point and spot lights of radius r > 0 (Blender's default: a
// disk of radius r through the centre c that faces each receiver). A path leaves c along w
// (uniform sphere, or the spot's cone) and finds its first vertex x1; then it samples y0 on the
// disk D(x1) facing x1 (area density 1 / (pi r^2), as next-event estimation does) and tests
// y0 -> x1. The light path's area density of x1 is p(w) |cos_x1| / |x1 - c|^2 times V(c, x1): the
// camera side's weights (next event, a hit on the disk) test V(c, x1) with a ray of their own.
// Scenes with media start no such paths (scene_lights.cpp). docs/lvc_notes.md, "Soft-falloff".
#pragma once

#include "core/offset.h"
#include "integrator/light_path.h"

namespace lantern {

// A stage's own ray queries: the executor's Rays with the kinds of the light pass's rays
// (closest hits of RayKind indirect) and of shadow rays. no_centre_test (tests only,
// SessionSettings::soft_visibility off): V(c, x) taken as 1, the biased negative control.
template <class Rays, class Kind>
struct StageRays {
    Rays rays;
    Kind indirect, shadow;
    bool no_centre_test;
    float time = 0.0f;  // motion blur: the path's shutter time, every query's (motion_blur.md)
    LANTERN_HD bool blocked(const Ray& r, bool shadow_ray) const {
        Ray q = r;
        q.time = time;
        return rays.occluded(q, shadow_ray ? shadow : indirect);
    }
    // the closest hit of a ray of the light pass's kind at the path's time (the route from a
    // soft light's centre through media, soft_light_medium.h)
    LANTERN_HD auto closest_indirect(const Ray& r) const {
        Ray q = r;
        q.time = time;
        return rays.closest(q, indirect);
    }
    LANTERN_HD StageRays at(float t) const {  // the same queries at time t
        StageRays c = *this;
        c.time = t;
        return c;
    }
};
template <class Rays, class Kind>
inline StageRays<Rays, Kind> stage_rays(const Rays& r, Kind indirect, Kind shadow,
                                        bool no_centre_test = false) {
    return StageRays<Rays, Kind>{r, indirect, shadow, no_centre_test};
}

// Solid-angle density of leaving the centre along unit w.
LANTERN_HD inline float soft_light_dir_pdf(const Light& l, Vec3 w) {
    if (l.type == kLightSpot)
        return dot(w, -l.frame.axis(2)) >= l.cos_half_spot ? pdf_uniform_cone(l.cos_half_spot)
                                                           : 0.0f;
    return 0.25f * kInvPi;
}

// The emission sample of a soft-falloff light: p = c, direction w; pdf_emit = p(w) / (pi r^2)
// (y0's density on D(x1) times w's), pdf_direct = 1 / (pi r^2). cos_light is 1 here: the first
// hit multiplies in cos_y0 |x1 - c|^2 / |y0 - x1|^2 and the cone (soft_light_first_hit).
LANTERN_HD inline EmissionSample sample_soft_emission(const Light& l, Vec2 u_dir) {
    EmissionSample es{};
    float pdf_dir = 0.0f;
    if (l.type == kLightSpot) {
        Frame f = Frame::from_normal(-l.frame.axis(2));
        es.d = f.to_world(sample_uniform_cone(u_dir, l.cos_half_spot, &pdf_dir));
    } else {
        es.d = sample_uniform_sphere(u_dir, &pdf_dir);
    }
    es.p = l.position;
    es.n = vec3(0.0f);
    es.le = l.radiance;
    es.pdf_direct = 1.0f / (kPi * l.radius * l.radius);
    es.pdf_emit = pdf_dir * es.pdf_direct;
    es.cos_light = 1.0f;
    es.finite = true;
    es.valid = es.pdf_emit > 0.0f && !is_black(es.le) && is_finite(es.d);
    return es;
}

// V(c, x): does a ray from the centre reach x (geometric normal ng) unblocked, as the light
// pass's rays see the scene? Out of line on the device (LANTERN_DEVICE_NOINLINE): the BVH
// traversal's stack is then a frame of its own, not in the camera NEE's and shade kernel's
// frames under every other call they make.
template <class SR>
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool soft_light_sees(const SceneView& s, const SR& sr, const Light& l, Vec3 x,
                                       Vec3 ng) {
    Vec3 to_c = l.position - x;
    const float d = length(to_c);
    if (!(d > 0.0f)) return false;
    if (sr.no_centre_test) return true;
    to_c = to_c / d;
    const Vec3 o = offset_ray_origin(x, ng, to_c, s.offset_scale);
    const Vec3 seg = l.position - o;
    const float len = length(seg);
    return !sr.blocked(Ray{o, len > 0.0f ? seg / len : to_c, 0.0f, len * (1.0f - 1e-4f)}, false);
}

// The light path's area density of x (geometric normal ng) as its first vertex, with the light
// pick and y0's density 1 / (pi r^2): emit_pick p(w) / (pi r^2) |cos| / |x - c|^2 V(c, x); zero
// where the light starts no paths (emit_pick_pdf 0) or the cone misses x.
template <class SR>
LANTERN_HD inline float soft_light_path_pdf_a(const SceneView& s, const SR& sr, const Light& l,
                                              Vec3 x, Vec3 ng) {
    if (!(l.emit_pick_pdf > 0.0f)) return 0.0f;
    Vec3 w = x - l.position;
    const float d2 = length_sq(w);
    if (!(d2 > 0.0f)) return 0.0f;
    w = w / sqrtf(d2);
    const float pdf_w = soft_light_dir_pdf(l, w);
    if (!(pdf_w > 0.0f)) return 0.0f;
    const float pdf_a = l.emit_pick_pdf * pdf_w / (kPi * l.radius * l.radius) *
                        fabsf(dot(w, ng)) / d2;
    if (!(pdf_a > 0.0f)) return 0.0f;
    return soft_light_sees(s, sr, l, x, ng) ? pdf_a : 0.0f;
}

// What the first hit x1 (triangle point p, geometric normal ng) of a soft-falloff light's path
// takes from its light: y0 on D(x1), the direction wi of the light arriving at x1 (y0 -> x1),
// the spot cone's factor along it and cos_light = cos_y0 |x1 - c|^2 / |y0 - x1|^2, the factor
// the flux and dVC of the path take in place of the usual cosine at the light.
struct SoftFirstHit {
    Vec3 wi;
    float atten;
    float cos_light;
    bool valid;  // false: y0 is blocked from x1, or the cone sends nothing along wi
};

template <class SR>
LANTERN_HD inline SoftFirstHit soft_light_first_hit(const SceneView& s, const SR& sr,
                                                    const Light& l, Vec3 p, Vec3 ng, Vec2 u) {
    SoftFirstHit r{vec3(0.0f), 0.0f, 0.0f, false};
    Vec3 n0 = p - l.position;
    const float dc = length(n0);
    if (!(dc > 0.0f)) return r;
    n0 = n0 / dc;
    const Frame f = Frame::from_normal(n0);
    const Vec2 q = sample_concentric_disk(u);
    const Vec3 y0 = l.position + (f.s * q.x + f.t * q.y) * l.radius;
    Vec3 wi = p - y0;
    const float dy = length(wi);
    if (!(dy > 0.0f)) return r;
    wi = wi / dy;
    const float cos_y0 = dot(wi, n0);
    const float atten = l.type == kLightSpot ? spot_attenuation(l, wi) : 1.0f;
    if (!(cos_y0 > 0.0f) || !(atten > 0.0f)) return r;
    // the shadow ray next-event estimation would cast from x1 to y0
    const Vec3 o = offset_ray_origin(p, ng, -wi, s.offset_scale);
    const Vec3 seg = y0 - o;
    const float len = length(seg);
    if (sr.blocked(Ray{o, len > 0.0f ? seg / len : -wi, 0.0f, len * (1.0f - 1e-4f)}, true))
        return r;
    r.wi = wi;
    r.atten = atten;
    r.cos_light = cos_y0 * (dc * dc) / (dy * dy);
    r.valid = r.cos_light > 0.0f && is_finite(r.cos_light);
    return r;
}


// ---- lt: lines through the light's ball (docs/lvc_notes.md, "the line route") ----
// Light tracing has no other technique to cover the x1 that c does not see, so its paths
// sample a line instead: w as above, then the footprint q uniform on the disk of radius r
// perpendicular to w through c, traced from where it enters the ball B(c, r). Its first hit
// x1 takes y0 = the line's crossing of D(x1)'s plane, valid when it lies in the disk and before
// x1: the pair (y0, x1) has density pick p(w) / (pi r^2) cos_y0 |cos_x1| / |y0 - x1|^2 (the line
// measure), so each path carries the constant flux L atten(w) pi r^2 / (pick p(w)), and the
// segment y0 -> x1 is free by construction. Exact where no geometry lies inside B(c, r)
// (a hit there could hide a later valid x1 of the same line): check_light_tracing refuses that.
LANTERN_HD inline EmissionSample sample_soft_line(const Light& l, Vec2 u_pos, Vec2 u_dir) {
    EmissionSample es = sample_soft_emission(l, u_dir);  // w, pdf_emit = p(w) / (pi r^2)
    if (!es.valid) return es;
    const Frame f = Frame::from_normal(es.d);
    const Vec2 q = sample_concentric_disk(u_pos);
    const Vec3 off = (f.s * q.x + f.t * q.y) * l.radius;
    const float h = safe_sqrt(l.radius * l.radius - length_sq(off));
    es.p = l.position + off - es.d * h;  // where the line enters the ball
    if (l.type == kLightSpot) es.le = es.le * spot_attenuation(l, es.d);  // along w: y0 -> x1
    es.valid = !is_black(es.le);
    return es;
}

// Whether the first hit x1 = o + t w of a line from sample_soft_line (o: its entry point) has
// its y0 on D(x1) before x1.
LANTERN_HD inline bool soft_line_hit_valid(const Light& l, Vec3 o, Vec3 w, float t) {
    Vec3 n0 = o + w * t - l.position;
    const float dc = length(n0);
    if (!(dc > 0.0f)) return false;
    n0 = n0 / dc;
    const float cos_y0 = dot(w, n0);
    if (!(cos_y0 > 0.0f)) return false;
    const float s0 = dot(l.position - o, n0) / cos_y0;  // y0 = o + s0 w
    if (!(s0 >= 0.0f && s0 < t)) return false;
    return length_sq(o + w * s0 - l.position) <= l.radius * l.radius;
}

}  // namespace lantern
