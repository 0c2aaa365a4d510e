// A volume's mesh that casts no shadow, in a scene with media (SceneView::no_shadow_objects 2),
// in the bidirectional integrators (bdpt, lvc, cis) as pt renders it: pt's shadow ray skips
// that volume, crossing it or from inside (the shadow query does not see its boundary;
// pt_volume.h shadow_medium: Cycles' rule, D61), while every other ray crosses it
// (docs/lvc_notes.md "Cast Shadow off"). With T, V the
// ordinary query's transmittance and visibility of x0 x1 and T', V' the shadow query's, pt's
// image is the integral of f (T' V' w_nee + T V w_bsdf) = the integral of f T V (the physical
// image: every technique, the usual weights) + the integral of f (T' V' - T V) w_nee, a signed
// term that only next-event estimation makes (bidir_no_shadow.h's split with T' != T). So s = 1
// traces both queries: c T V with the usual finish (the ordinary query's segment factors) plus
// c (T' V' - T V) at pt's weight (bidir_no_shadow_medium_c). Connections, s = 0, t = 1 and the
// light pass trace the physical scene as ever.
#pragma once

#include "integrator/bdpt_medium.h"
#include "integrator/bidir_no_shadow.h"

namespace lantern {

// s = 1's contribution given tr_shadow = T' V' (bdpt_medium_shadow with the shadow query):
// the ordinary query `indirect` traced through the media for T V. Out of line on the device
// (a second medium trace inlined would add its frame to every scene's shadow stage).
template <class Rays, class Kind>
#ifdef __CUDA_ARCH__
__noinline__
#endif
LANTERN_HD inline Vec3 bidir_no_shadow_boundary_c(const SceneView& s, const Rays& rays,
                                                  Kind indirect, const PathState& ps,
                                                  const BdptState& bs, int i, Vec3 tr_shadow,
                                                  float time) {
    const int32_t kind = bs.shadow_kind[i];
    Rng track = medium_tracking_rng(ps.rng[i], 1);  // the shadow query's numbers (correlated)
    const MediumShadow sh = bdpt_medium_shadow(
        s, rays, indirect, ps.shadow_o[i], ps.shadow_d[i], ps.shadow_tmax[i],
        ps.shadow_medium[i], (kind & kConnNearMedium) != 0, false, &track, time);
    const Vec3 c = ps.shadow_contrib[i];
    const Vec3 usual = is_black(sh.tr) ? vec3(0.0f)
                                       : bdpt_medium_finish_c(c, sh.tr, bs.shadow_wn[i],
                                                              bs.shadow_wf[i], kind,
                                                              bs.shadow_mom + i, sh.seg);
    return usual + bidir_no_shadow_medium_c(c, tr_shadow - sh.tr, bs.shadow_wn[i],
                                            bs.shadow_wf[i]);
}

}  // namespace lantern
