// Medium vertices for the bidirectional integrators (bdpt, lvc, cis; issue 29 item 3,
// docs/volumes.md "Medium vertices in the bidirectional integrators"): the pieces their stages
// share, host+device, no state. Homogeneous media only (heterogeneous media stay with pt).
//
// - The channel rule. pt draws a free-flight channel with probabilities from the path's
//   throughput, which the reverse pdf of a vertex (the density with which the other sub-path
//   would have made it) cannot know. Here the channel is uniform over RGB in both directions:
//   the density of a scatter at distance t is the mean over channels of sigma_t,c exp(-sigma_t,c
//   t), the probability of passing a piece of length t the mean of exp(-sigma_t,c t). A medium
//   that does not scatter is attenuated without sampling (factor 1 in every pdf).
// - Distance factors of a segment. A segment between two vertices crosses pieces of media
//   (volume boundaries are passed through, not vertices); each piece draws its own flight. The
//   area (volume) density of the vertex a segment reaches is p_w(direction) x F / d^2, where F,
//   the segment's distance factor at that end, is the product of the pass probabilities of the
//   pieces before the last, times the last piece's scatter density (a medium vertex) or its
//   pass probability times |cos| (a surface). The reverse density of the vertex the segment
//   left has the same form with the pieces in the other order. MediumSegmentPdf accumulates
//   both ends' factors (without the cosines) piece by piece.
// - In the recursive MIS quantities (bdpt_common.h), the cosine at the far end of a traced
//   segment becomes |cos| x F_fwd (F_fwd alone at a medium vertex), and the cosine at the near
//   end (SmallVCM's cos_out at the scatter) becomes |cos| x F_rev (F_rev at a medium vertex):
//   F_rev is known only when the segment has been traced, and since it multiplies dVC alone it
//   is applied then (bdpt_medium_hit_update).
// - A medium vertex in the light vertex cache (LightVertex, still 104 bytes): tri = -2 - medium
//   (surfaces have tri >= 0; the same convention as a heterogeneous medium's ShadePoint), both
//   normals zero, material kMediumVertexMaterial, front 0, bary16 0, coat_n 0.
// - At a medium vertex the "BSDF" is the Henyey-Greenstein phase function (its sampling pdf
//   equals its value, and it is symmetric: the reverse pdf is the forward one); there is no
//   cosine at a medium end of a connection or of a light tracing splat.
#pragma once

#include "integrator/bdpt_common.h"
#include "integrator/bidir_linking_medium.h"
#include "integrator/bdpt_motion.h"
#include "integrator/medium_motion.h"
#include "integrator/pt_volume.h"
#include "scene/medium.h"

namespace lantern {

// ---- The throughput-free channel rule ----
LANTERN_HD inline Vec3 bdpt_medium_pmf() { return vec3(1.0f / 3.0f); }

// Density per unit length of a scatter at distance t into a piece of medium m.
LANTERN_HD inline float bdpt_medium_scatter_pdf(const Medium& m, float t) {
    if (!m.scatters) return 0.0f;
    const Vec3 tr = medium_transmittance(m, t);
    return (m.sigma_t.x * tr.x + m.sigma_t.y * tr.y + m.sigma_t.z * tr.z) * (1.0f / 3.0f);
}
// Probability that a flight passes a piece of length t (1 in a medium that does not scatter:
// nothing is sampled there).
LANTERN_HD inline float bdpt_medium_pass_pdf(const Medium& m, float t) {
    if (!m.scatters) return 1.0f;
    return medium_pass_pdf(m, bdpt_medium_pmf(), t);
}

// A free flight over a piece of length t_end by the channel rule (scene/medium.h's sampler with
// the uniform channel probabilities): weight sigma_s T(t) / scatter_pdf(t) at a scatter,
// T(t_end) / pass_pdf(t_end) past the piece.
LANTERN_HD inline MediumStep bdpt_medium_flight(const Medium& m, float t_end, float u_channel,
                                                float u_dist) {
    return medium_sample_distance(m, t_end, bdpt_medium_pmf(), u_channel, u_dist);
}

// ---- A segment's distance factors, piece by piece ----
enum MediumSegmentFlags : int32_t {
    kSegStartMedium = 1,  // the segment leaves a medium vertex
    kSegPieceDone = 2,    // at least one piece of it has been accumulated
};
struct MediumSegmentPdf {
    float fwd;  // F at the far end so far: pass probabilities of the finished pieces
    float rev;  // F at the near end
    int32_t flags;
};

LANTERN_HD inline MediumSegmentPdf medium_segment_begin(bool start_medium) {
    return MediumSegmentPdf{1.0f, 1.0f, start_medium ? int32_t(kSegStartMedium) : 0};
}

// One piece of length t in medium m (null: vacuum). scatter: the segment ends inside this piece
// at a medium vertex (t is the distance to it); the last piece of a segment ending at a surface
// is accumulated with scatter false.
LANTERN_HD inline void medium_segment_piece(MediumSegmentPdf& seg, const Medium* m, float t,
                                            bool scatter) {
    const bool first = (seg.flags & kSegPieceDone) == 0;
    seg.flags |= kSegPieceDone;
    if (!m || !m->scatters) {  // nothing sampled: factor 1 both ways (and no medium vertex)
        if (scatter) seg.fwd = 0.0f;
        if (first && (seg.flags & kSegStartMedium)) seg.rev = 0.0f;
        return;
    }
    const float pass = bdpt_medium_pass_pdf(*m, t);
    const float dens = (scatter || (first && (seg.flags & kSegStartMedium)))
                           ? bdpt_medium_scatter_pdf(*m, t)
                           : 0.0f;
    seg.fwd *= scatter ? dens : pass;
    seg.rev *= (first && (seg.flags & kSegStartMedium)) ? dens : pass;
}

}  // namespace lantern

#include "integrator/bdpt_medium_hetero.h"  // heterogeneous media: uses medium_segment_piece

namespace lantern {

// ---- The recursive MIS quantities ----
// At the vertex a traced segment of length dist reached: cos_in its |cos| with the incoming
// direction (1 at a medium vertex), seg the segment's factors. dist_sq_applies false where the
// first segment's d^2 does not enter dVCM (sun, world, an orthographic camera).
LANTERN_HD inline void bdpt_medium_hit_update(float& dvcm, float& dvc, float dist, float cos_in,
                                              const MediumSegmentPdf& seg, bool dist_sq_applies) {
    const float f = cos_in * seg.fwd;
    if (dist_sq_applies) dvcm *= mis(dist * dist);
    dvcm /= mis(f);
    dvc *= mis(seg.rev) / mis(f);
}

// After the phase function sampled the next direction at a medium vertex (pdf_w forward; the
// reverse is equal): SmallVCM's scatter update with no cosine at a medium point (the near end's
// distance factor comes with the next segment, bdpt_medium_hit_update).
LANTERN_HD inline void bdpt_medium_scatter_update(float& dvcm, float& dvc, float pdf_w) {
    dvc = mis(1.0f / pdf_w) * (dvc * mis(pdf_w) + dvcm);
    dvcm = mis(1.0f / pdf_w);
}

// ---- The slot's segment state (BdptState::seg_*) and the ends of a queued connection ----
// kConnNearFixed: the near end's part wn already holds its factor (a soft-falloff light's
// light-path density of a camera vertex, whose flights leave the light's centre, not the
// segment's far end: soft_light_medium.h); the segment's near factor does not scale it.
enum ConnKind : int32_t { kConnNearMedium = 1, kConnFarMedium = 2, kConnNearFixed = 128 };
// BdptSettings::moments: the queued contribution becomes moment channels at its finish
// (bdpt_medium_finish_c); pt's squared ratios a, b (BdptState::shadow_mom / conn_mom) scale with
// the near end's factor (kMomNear) or the far end's (kMomFar); kMomOwnB: b is the
// contribution's own technique (1, no factor: next-event estimation); kMomG: the queue holds
// g = bdpt_pt_factor(1, a, b) instead (a connection's Connection::pt_factor), which a common
// factor f of a and b scales by 1 / sqrt(f) (bdpt_pt_factor is of degree -1/2 in them).
enum MomentKind : int32_t { kMomOn = 4, kMomNear = 8, kMomFar = 16, kMomOwnB = 32, kMomG = 64 };

// A queued contribution carries the weight 1 / (1 + wn + wf) (factors 1); with the traced
// segment's factors it is 1 / (1 + wn F_near^2 + wf F_far^2): the ratio (bdpt_medium_stages.h).
// The queued contribution c through transmittance tr, its weight finished; with kMomOn in kind
// the moment channels of it (bdpt_moment), from pt's squared ratios mom = (a, b, u) with the
// segment's factors (u: the unit contribution over c, a cis pick's, bdpt_camera_connect).
LANTERN_HD inline Vec3 bdpt_medium_finish_c(Vec3 c, Vec3 tr, float wn, float wf, int32_t kind,
                                            const Vec3* mom, const MediumSegmentPdf& seg) {
    const float fn = (kind & kConnNearFixed) ? 1.0f : mis(seg.rev), ff = mis(seg.fwd);
    const float den = 1.0f + wn * fn + wf * ff;
    if (!(den > 0.0f)) return vec3(0.0f);
    const Vec3 cf = c * tr * ((1.0f + wn + wf) / den);
    if (!(kind & kMomOn) || !mom) return cf;
    const float f = (kind & kMomNear) ? fn : (kind & kMomFar) ? ff : 1.0f;
    if (kind & kMomG)  // (a cis pick's: pt's factor of its connection without the segment's)
        return bdpt_moment(cf, cf * mom->z,
                           mom->x < 0.0f ? -1.0f : f > 0.0f ? den * mom->x / sqrtf(f) : 0.0f);
    const float a = mom->x * f, b = (kind & kMomOwnB) ? 1.0f : mom->y * f;
    return bdpt_moment(cf, cf * mom->z, bdpt_pt_factor(den, a, b));
}

LANTERN_HD inline MediumSegmentPdf bdpt_seg_load(const BdptState& bs, int i) {
    return MediumSegmentPdf{bs.seg_fwd[i], bs.seg_rev[i], bs.seg_flags[i]};
}
LANTERN_HD inline void bdpt_seg_store(const BdptState& bs, int i, const MediumSegmentPdf& g) {
    bs.seg_fwd[i] = g.fwd;
    bs.seg_rev[i] = g.rev;
    bs.seg_flags[i] = g.flags;
}

// ---- Medium vertices in the cache ----
constexpr uint32_t kMediumVertexMaterial = 0xFFFFFFFFu;

LANTERN_HD inline bool lv_is_medium(const LightVertex& v) { return v.tri <= -2; }
LANTERN_HD inline int32_t lv_medium(const LightVertex& v) { return -2 - v.tri; }

LANTERN_HD inline LightVertex lv_make_medium(Vec3 p, Vec3 wo, Vec3 beta, float dvcm, float dvc,
                                             int32_t medium, int32_t path, int k) {
    LightVertex v;
    v.p = p;
    v.ng = vec3(0.0f);
    v.ns = vec3(0.0f);
    v.wo = wo;
    v.beta = beta;
    v.dvcm = dvcm;
    v.dvc = dvc;
    v.material = kMediumVertexMaterial;
    v.tri = -2 - medium;
    v.bary16 = 0u;
    v.tangent_angle = 0.0f;
    v.path = path;
    v.length = int16_t(k);
    v.front = 0;
    v.coat_n = 0u;
    v.dpt0 = 0.0f;
    v.dpt1 = 0.0f;
    return v;
}

// The phase function at a medium vertex between wo (unit, towards the previous vertex of its
// sub-path) and wi (unit, towards the next): f, and the pdfs of either direction given the other.
LANTERN_HD inline float bdpt_medium_phase(const Medium& m, Vec3 wo, Vec3 wi) {
    return hg_phase(m.g, -dot(wo, wi));
}


// ---- A connecting segment through media (next-event estimation, connections, light tracing's
// camera segments): its transmittance and both ends' distance factors, known only once the
// segment has been traced piece by piece through the volume boundaries it crosses. From o along
// d up to tmax, starting in medium med (-1: vacuum); start_medium / end_medium: the near / far
// end is a medium vertex. Zero transmittance when any surface but a volume boundary blocks it.
// Heterogeneous media: ratio tracking with numbers from *track (null: a fixed stream), the
// factors by the stand-in (bdpt_medium_hetero.h). time: the path's shutter time (motion blur:
// the segment's rays, and the volume boundaries it crosses, where they are then).
// blockers: a shadow-linked light's blocker sets (next-event estimation's segment, s = 1): a
// surface or boundary of a set outside them is passed as if absent, the medium unchanged
// (pt_shadow_loop's rule). ----
struct MediumShadow {
    Vec3 tr;
    MediumSegmentPdf seg;
};

template <class Rays, class Kind>
LANTERN_HD inline MediumShadow bdpt_medium_shadow(const SceneView& s, const Rays& rays, Kind kind,
                                                  Vec3 o, Vec3 d, float tmax, int32_t med,
                                                  bool start_medium, bool end_medium,
                                                  Rng* track = nullptr, float time = 0.0f,
                                                  uint64_t blockers = kAllReceivers,
                                                  bool shadow_media = false) {
    MediumShadow r{vec3(1.0f), medium_segment_begin(start_medium)};
    Rng fixed = medium_tracking_rng(Rng{}, 1);
    float t0 = 0.0f;  // past a passed strand: the query goes on from o beyond its entry
    for (int k = 0; k < 256; ++k) {  // boundaries crossed (a bound: never an endless loop)
        const auto h = rays.closest(Ray{o, d, t0, tmax, time}, kind);
        const bool hit = h.prim >= 0 && h.t < tmax;
        const float t = (hit ? h.t : tmax) - t0;  // this piece: from o + d t0, t long
        const int32_t sm = shadow_media ? shadow_medium(s, med) : med;
        const Medium* m = sm >= 0 ? &s.media[sm] : nullptr;
        if (m && m->hetero) {
            Vec3 fo = t0 > 0.0f ? o + d * t0 : o, fd = d;  // (a moving volume: its exported frame)
            medium_frame_ray(s, sm, time, &fo, &fd);
            r.tr = r.tr * medium_piece_transmittance(s, sm, fo, fd, t, track ? *track : fixed);
            medium_segment_piece_hetero(r.seg, s, sm, fo, fd, t, !hit && end_medium);
        } else {
            if (m) r.tr = r.tr * medium_transmittance(*m, t);
            medium_segment_piece(r.seg, m, t, !hit && end_medium);
        }
        if (!hit) return r;
        const bool passed = blockers != kAllReceivers && s.tri_shadow_set &&
                            !((blockers >> s.tri_shadow_set[h.prim]) & 1u);
        if ((!passed && !(s.tri_flags[h.prim] & kVolumeBoundary)) || is_black(r.tr)) break;
        // a strand passed: on from o past its entry (pt_shadow_loop's rule; a re-offset from a
        // grazing entry into a round strand found its surface again and again)
        if (h.prim >= s.num_triangles) {
            t0 = h.t + 1e-5f * fmaxf(h.t, s.offset_scale);
            continue;
        }
        t0 = 0.0f;
        const BoundarySide b = boundary_side_at(s, int(h.prim), h.uv, d, time);
        if (!passed) med = medium_across(s, h.prim, b.front, med);
        const Vec3 next = offset_ray_origin(o + d * h.t, b.ng, d, s.offset_scale);
        if (tmax < kInf) tmax = fmaxf(tmax - dot(next - o, d), 0.0f);
        o = next;
    }
    r.tr = vec3(0.0f);
    return r;
}

// The bidirectional sub-paths' crossing of volume boundary tri (the traced ray reached it): at
// path `path`'s time (bdpt_time) where meshes move (medium_motion.h), else pt's own.
LANTERN_HD inline void bdpt_cross_boundary(const SceneView& s, const BdptSettings& st,
                                           const PathState& ps, int i, int64_t path, int tri) {
    if (medium_rays_timed(s) && s.motion.num_objects > 0)
        cross_boundary_at(s, ps, i, tri, medium_ray_time(s, bdpt_time(st, path)));
    else
        pt_cross_boundary(s, ps, i, tri);
}

}  // namespace lantern
