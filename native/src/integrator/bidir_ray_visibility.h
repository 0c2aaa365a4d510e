// Object and lamp ray visibility by kind (Diffuse, Glossy, Transmission, Volume Scatter) in the
// bidirectional integrators' surface stages (bdpt, lvc, cis), as pt has it (pt_ray_visibility.h).
//
// R: the meshes and lamps hidden from some kind (a mesh's tri_rays, a lamp's light_rays lacking
// a kind; an emissive triangle of such a mesh is an R light). In pt's terms a path x0 (camera)
// x1 .. xk (light) has the integrand f times, per segment xi xi+1 (i >= 1), the visibility of
// the kind of xi's scattering. A path is *restricted* when some segment xi xi+1 (i >= 1) meets
// a surface of R inside or at its light-side end xi+1, or ends on an R light. An unrestricted
// path sees the ordinary scene on every segment: the usual techniques and weights. A restricted
// one is made by pt's two techniques alone, with pt's weights and kind rules:
//   - the camera pass's bounce rays are pt's: they pass a triangle hidden from their kind (the
//     same segment goes on, its last vertex's MIS state kept) and the slot's path becomes
//     restricted (kRayRestricted in PathState::ray_kind, set once) when a bounce ray passes or
//     lands on an R surface; from then on s >= 2 is 0 and s = 1, s = 0 take pt's weights;
//   - s = 1 to an R light, and s = 0 on an R lamp (lamps are not opaque: the path goes on
//     unrestricted past it), take pt's weights, pt_light_hidden / the lamp's kinds deciding;
//   - connections keep the ordinary query, which stops at an R surface on the segment;
//   - the light pass starts no sub-path on an R light, and a light vertex on an R surface is
//     splatted (t = 1: the camera segment ends there; its own object at the camera-side end of
//     the next segment does not matter) but neither stored nor continued.
// In media (homogeneous and heterogeneous; bdpt_medium_stages.h) the same rule with pt's medium
// rules: a camera medium vertex's bounce ray is of kind kRayKindVolume (Volume Scatter alone)
// and passes what is hidden from it, its segment's flight going on past the passed surface (a
// piece more of the same segment, as past a volume boundary; pt starts a new segment there: a
// free flight is memoryless); its next event skips a light hidden from Volume Scatter; s = 0
// skips a lamp hidden from the ray's kind. Restricted paths and R lights take pt's weights
// exactly, without the flights' factors (pt's hold none): s = 0 pt_emission_weight, s = 1
// 1 / (1 + w_light) queued with both factor parts 0 (bidir_rays_pt_nee), at a surface vertex
// in fog too. A light sub-path's medium vertex is never restricted (its segment was traced with
// the ordinary query, which stops at an R surface).
// Where only lamps without kinds set light_rays (Cast Shadow off), nothing here changes a bit.
// A subsurface walk is no segment (its rays see every surface, as pt's): its entry is the
// light-side end of the segment that reaches it, its exit the camera-side end of its diffuse
// continuation (bdpt_sss.h bdpt_sss_exit; the light pass: bdpt_sss_light.h), in media too. lt
// and the combinations allocation.cpp bidir_visibility_reason names stay pt's.
#pragma once

#include "integrator/pt.h"  // pt_emission_weight, pt_light_pdf_w
#include "integrator/pt_ray_visibility.h"

namespace lantern {

// The restricted bit of PathState::ray_kind beside the kinds (bdpt's camera pass).
constexpr uint8_t kRayRestricted = 0x80;

LANTERN_HD inline bool bidir_rays_on(const SceneView& s) { return s.rays_hidden != 0; }

// Whether triangle (or strand segment: tri_rays holds its object's kinds there) tri is an R
// surface.
LANTERN_HD inline bool bidir_tri_restricted(const SceneView& s, int tri) {
    return s.tri_rays && tri >= 0 && (s.tri_rays[tri] & kRayKindsAll) != kRayKindsAll;
}

// Whether light li is an R light (a lamp hidden from some kind, or an emissive triangle of an
// R mesh).
LANTERN_HD inline bool bidir_light_restricted(const SceneView& s, int li) {
    if (li < 0) return false;
    const Light& l = s.lights[li];
    if (l.type == kLightTriangle) return bidir_tri_restricted(s, l.triangle);
    return s.light_rays && (s.light_rays[li] & kRayKindsAll) != kRayKindsAll;
}

// Whether camera slot i's path is restricted (its current vertex's prefix).
LANTERN_HD inline bool bidir_restricted(const SceneView& s, const PathState& ps, int i) {
    return s.tri_rays && ps.ray_kind && (ps.ray_kind[i] & kRayRestricted) != 0;
}

// Whether slot i's next event of light li takes pt's weights (w_camera 0; in media its far
// part queued as 0 too: pt's weight holds no flight factor): a restricted path, an R light.
LANTERN_HD inline bool bidir_rays_pt_nee(const SceneView& s, const PathState& ps, int i, int li) {
    return bidir_restricted(s, ps, i) || bidir_light_restricted(s, li);
}

// Whether emission of light li found by slot i's bounce ray takes pt's weight: a restricted
// path, or an R light.
LANTERN_HD inline bool bidir_rays_pt_weight(const SceneView& s, const PathState& ps, int i,
                                            int li) {
    return ps.depth[i] > 1 && (bidir_restricted(s, ps, i) || bidir_light_restricted(s, li));
}

// pt's weight of emission of light li that slot i's bounce ray (origin o, direction d) found at
// distance t (normal n; infinite lights: d alone): pt_emission_weight with pt_light_pdf_w's
// density from the last real vertex (a ray that passed hidden surfaces starts past it), at
// `time` (a moving emitter's: the path's). Out of line on the device (LANTERN_DEVICE_NOINLINE):
// the light pick's and density's locals stay out of the kernels' frames.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline float bidir_rays_emission_weight(const SceneView& s, const PathState& ps, int i,
                                                   int li, Vec3 o, Vec3 d, float t, Vec3 n,
                                                   float time) {
    const Light& l = s.lights[li];
    const float pdf = l.type == kLightWorld ? world_pdf_w(s, d)
                      : l.type == kLightSun ? light_pdf_w(l, vec3(0.0f), d, kInf, vec3(0.0f))
                                            : pt_light_pdf_w(s, ps, i, l, o, d, t, n, time);
    return pt_emission_weight(s, ps, i, li, pdf);
}

// The kind of the next bounce ray of slot i, its restricted bit kept.
LANTERN_HD inline void bidir_set_ray_kind(const SceneView& s, const PathState& ps, int i,
                                          uint8_t kind) {
    if (bidir_rays_on(s) && ps.ray_kind)
        ps.ray_kind[i] = uint8_t((ps.ray_kind[i] & kRayRestricted) | kind);
}

}  // namespace lantern
