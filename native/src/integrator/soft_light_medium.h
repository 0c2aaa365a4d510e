// Soft-falloff point/spot lights' light paths in scenes with homogeneous media (bdpt, lvc, cis;
// docs/lvc_notes.md "Soft-falloff point and spot lights", "In media"). The route of
// soft_light_path.h with media on it: the path leaves the centre c along w and draws its
// flights piece by piece as every light path does (bdpt_medium_stages.h), so its first vertex
// x1 is a surface or a medium vertex; there it samples y0 on the disk D(x1) facing x1 and
// traces x1 -> y0 through the media (the transmittance, not V, on the shadow ray).
//
// - The light path's density of x1: pick p(w) / (pi r^2) |cos_x1,c| / |x1 - c|^2 F(c -> x1),
//   F the segment's distance factor at x1 (pass probabilities of the pieces crossed, times the
//   last piece's scatter density at a medium vertex, where there is no cosine); F = 0 where a
//   surface other than a volume boundary lies between c and x1 (V(c, x1)).
// - The flux at x1: L atten cos_y0 T(y0 -> x1) [sigma_s at a medium vertex] [|cos_x1,y0| at a
//   surface] / |y0 - x1|^2 over that density: the flights' throughput is replaced by
//   T(y0 -> x1) [sigma_s] / F (homogeneous media: F is the flights' exact density, so this is
//   what the pieces' weights T(c -> x1) [sigma_s] / F become with the light's own segment).
// - The s = 0 technique (a camera path from x1 hits y0) passes every piece of x1 -> y0: its
//   factor (the shadow segment's far-end factor) takes the place of the c -> x1 segment's
//   near-end factor in dVC.
// Heterogeneous media: no (the tracking's weight estimates T(c -> x1) / p, and T(y0 -> x1) /
// T(c -> x1) has no unbiased estimate here): scene_lights.cpp starts no such path there.
// Host only: on the device these lights start no light paths (HostScene's soft_light_paths), so
// their light-path density is 0 and the functions below return 0 / invalid without tracing.
#pragma once

#include "integrator/bdpt_medium.h"
#include "integrator/soft_light_path.h"

namespace lantern {

// F(c -> x): the distance factor at x of the light path's segment from the centre of l to x
// (ng: x's geometric normal; zero: x is a medium vertex), traced from c through the volume
// boundaries as the light pass's rays see the scene (at the path's time, sr.time: motion blur);
// 0 where anything else blocks it.
// sr.no_centre_test (tests only, soft_visibility off): 1, F and V(c, x) both left out (the
// biased negative control of the weights in media).
template <class SR>
LANTERN_HD inline float soft_route_factor(const SceneView& s, const SR& sr, const Light& l,
                                          Vec3 x, Vec3 ng) {
#ifdef __CUDA_ARCH__
    return 0.0f;
#else
    if (sr.no_centre_test) return 1.0f;
    const bool at_medium = is_black(ng);
    Vec3 to_c = l.position - x;
    const float dc = length(to_c);
    if (!(dc > 0.0f)) return 0.0f;
    to_c = to_c / dc;
    const Vec3 target = at_medium ? x : offset_ray_origin(x, ng, to_c, s.offset_scale);
    Vec3 o = l.position;
    Vec3 d = target - o;
    const float len = length(d);
    if (!(len > 0.0f)) return 0.0f;
    d = d / len;
    float tmax = at_medium ? len : len * (1.0f - 1e-4f);
    const int li = int(&l - s.lights);
    int32_t med = s.light_medium ? s.light_medium[li] : s.world_medium;
    MediumSegmentPdf seg = medium_segment_begin(false);
    for (int k = 0; k < 256; ++k) {  // boundaries crossed (bdpt_medium_shadow's bound)
        const auto h = sr.closest_indirect(Ray{o, d, 0.0f, tmax});
        const bool hit = h.prim >= 0 && h.t < tmax;
        Vec3 fo = o, fd = d;  // (a moving volume's density: its exported frame)
        medium_frame_ray(s, med, sr.time, &fo, &fd);
        medium_segment_piece_at(seg, s, med, fo, fd, hit ? h.t : tmax, !hit && at_medium);
        if (!hit) return seg.fwd;
        if (!(s.tri_flags[h.prim] & kVolumeBoundary)) return 0.0f;
        const BoundarySide b = boundary_side_at(s, int(h.prim), h.uv, d, sr.time);  // (moving)
        med = medium_across(s, h.prim, b.front, med);
        const Vec3 next = offset_ray_origin(o + d * h.t, b.ng, d, s.offset_scale);
        tmax = fmaxf(tmax - dot(next - o, d), 0.0f);
        o = next;
    }
    return 0.0f;
#endif
}

// soft_light_path_pdf_a in a scene with media: the light path's density of x (ng zero: a
// medium vertex, no cosine) as its first vertex, F(c -> x) and V(c, x) in it.
template <class SR>
LANTERN_HD inline float soft_light_path_pdf_a_medium(const SceneView& s, const SR& sr,
                                                     const Light& l, Vec3 x, Vec3 ng) {
    if (!(l.emit_pick_pdf > 0.0f)) return 0.0f;
    Vec3 w = x - l.position;
    const float d2 = length_sq(w);
    if (!(d2 > 0.0f)) return 0.0f;
    w = w / sqrtf(d2);
    const float pdf_w = soft_light_dir_pdf(l, w);
    if (!(pdf_w > 0.0f)) return 0.0f;
    const float cos_x = is_black(ng) ? 1.0f : fabsf(dot(w, ng));
    const float pdf_a = l.emit_pick_pdf * pdf_w / (kPi * l.radius * l.radius) * cos_x / d2;
    if (!(pdf_a > 0.0f)) return 0.0f;
    const float r = pdf_a * soft_route_factor(s, sr, l, x, ng);
    return is_finite(r) ? r : 0.0f;
}

// The first vertex x1 = p of a soft light's path in media (ng zero: a medium vertex): y0 on
// D(x1), the direction wi (y0 -> x1), the cone's factor and cos_light as soft_light_first_hit;
// the transmittance of x1 -> y0 through the media, the factor pass of that segment at y0 (the
// s = 0 technique's flight) and the medium on y0's side of x1 (med_front: on the side ng
// faces, med_back: the other; equal at a medium vertex).
struct SoftFirstHitMedium {
    SoftFirstHit hit;
    Vec3 tr;
    float pass;
    int32_t medium;
};

template <class SR>
LANTERN_HD inline SoftFirstHitMedium soft_light_first_hit_medium(const SceneView& s,
                                                                 const SR& sr, const Light& l,
                                                                 Vec3 p, Vec3 ng,
                                                                 int32_t med_front,
                                                                 int32_t med_back, Vec2 u) {
    SoftFirstHitMedium r{SoftFirstHit{vec3(0.0f), 0.0f, 0.0f, false}, vec3(0.0f), 0.0f, -1};
#ifndef __CUDA_ARCH__
    const bool at_medium = is_black(ng);
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
    r.medium = at_medium || dot(-wi, ng) > 0.0f ? med_front : med_back;
    const Vec3 o = at_medium ? p : offset_ray_origin(p, ng, -wi, s.offset_scale);
    const Vec3 seg = y0 - o;
    const float len = length(seg);
    const MediumShadow sh = bdpt_medium_shadow(s, sr.rays, sr.shadow, o,
                                               len > 0.0f ? seg / len : -wi,
                                               len * (1.0f - 1e-4f), r.medium, at_medium, false,
                                               nullptr, medium_ray_time(s, sr.time));
    if (is_black(sh.tr) || !(sh.seg.fwd > 0.0f)) return r;
    r.tr = sh.tr;
    r.pass = sh.seg.fwd;
    r.hit.wi = wi;
    r.hit.atten = atten;
    r.hit.cos_light = cos_y0 * (dc * dc) / (dy * dy);
    r.hit.valid = r.hit.cos_light > 0.0f && is_finite(r.hit.cos_light);
#endif
    return r;
}

}  // namespace lantern
