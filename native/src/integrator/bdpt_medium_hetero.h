// Heterogeneous media in the bidirectional integrators (bdpt, lvc, cis; docs/volumes.md
// "Heterogeneous and emissive media in bdpt, lvc, cis and lt"): free flights by tracking against
// the medium's majorant (scene/medium_hetero.h's medium_track), transmittance of connecting
// segments by ratio tracking, and MIS with a deterministic stand-in for the tracking's pdf.
// Included by bdpt_medium.h after medium_segment_piece; host+device, no state.
//
// - The stand-in. A tracking's free-flight density has no closed form (it needs the
//   transmittance), but the balance (and power) heuristic is a partition of unity for any
//   per-vertex densities q that are deterministic functions of the path, as long as every
//   technique evaluates the same q: the weights still sum to one wherever they are evaluated,
//   and each technique's contribution is its weight times an unbiased estimate of f / p (the
//   tracking's weight), so the sum is unbiased. The q of a piece of heterogeneous medium of
//   length t from o along d: the optical depth tau_c = sigma_t0,c t + sigma_t,c x (density
//   integrated by an 8-point midpoint rule over the piece); pass = mean_c exp(-tau_c);
//   a scatter at its far end x: mean_c sigma_t,c(x) exp(-tau_c) (the homogeneous formula with
//   the collision density at x). The midpoint nodes of the reversed piece are the same points,
//   so the reverse factor of a vertex is the forward factor of the reversed segment (to float
//   rounding: tests/cpp/test_bdpt_medium_hetero.cpp); density programs are evaluated with one
//   fixed direction (hetero_standin_dir), so one that reads the incoming direction keeps it so.
// - Homogeneous media keep their exact pdfs (medium_segment_piece): medium_segment_piece_at
//   dispatches on Medium::hetero, so scenes without heterogeneous media keep their bits.
#pragma once

namespace lantern {

constexpr int kHeteroQuadrature = 8;  // midpoint nodes of the stand-in's optical depth

// The direction the stand-in evaluates density programs with (a program may read the incoming
// direction): one fixed direction, so that a piece and its reverse read the same values.
LANTERN_HD inline Vec3 hetero_standin_dir() { return Vec3{0.0f, 0.0f, 1.0f}; }

// The stand-in's optical depth per channel over [0, t] from o along d (t finite).
LANTERN_HD inline Vec3 hetero_optical_depth(const SceneView& s, const Medium& m, int32_t med,
                                            Vec3 o, Vec3 d, float t) {
    float den = 0.0f;
    const float h = t * (1.0f / float(kHeteroQuadrature));
    if (medium_has_color(s, m)) {  // a colour grid: the coefficients' own channels at the nodes
        Vec3 tau = vec3(0.0f);
        for (int k = 0; k < kHeteroQuadrature; ++k) {
            const MediumCoeffs c = medium_coeffs_at(s, m, med, o + d * (h * (float(k) + 0.5f)),
                                                    hetero_standin_dir());
            tau = tau + (c.sigma_a + c.sigma_s) * h;
        }
        return tau;
    }
    for (int k = 0; k < kHeteroQuadrature; ++k)
        den += medium_density(s, m, med, o + d * (h * (float(k) + 0.5f)), hetero_standin_dir());
    return (m.sigma_a0 + m.sigma_s0) * t + (m.sigma_a + m.sigma_s) * (den * h);
}

// The stand-in's collision density per unit length at x, given the optical depth to it.
LANTERN_HD inline float hetero_scatter_q(const SceneView& s, const Medium& m, int32_t med,
                                         Vec3 x, Vec3 tr) {
    const MediumCoeffs c = medium_coeffs_at(s, m, med, x, hetero_standin_dir());
    const Vec3 st = c.sigma_a + c.sigma_s;
    return (st.x * tr.x + st.y * tr.y + st.z * tr.z) * (1.0f / 3.0f);
}

// One piece of length t of heterogeneous medium med from o along d: medium_segment_piece with
// the stand-in (scatter: the segment ends inside this piece at a medium vertex at t).
LANTERN_HD inline void medium_segment_piece_hetero(MediumSegmentPdf& seg, const SceneView& s,
                                                   int32_t med, Vec3 o, Vec3 d, float t,
                                                   bool scatter) {
    const Medium& m = s.media[med];
    const bool first = (seg.flags & kSegPieceDone) == 0;
    const bool start_medium = first && (seg.flags & kSegStartMedium);
    seg.flags |= kSegPieceDone;
    if (!m.scatters) {  // nothing sampled: factor 1 both ways (and no medium vertex)
        if (scatter) seg.fwd = 0.0f;
        if (start_medium) seg.rev = 0.0f;
        return;
    }
    if (!(t < kInf)) {  // never passed (an open mesh: its density to infinity is unknown)
        seg.fwd = 0.0f;
        seg.rev = 0.0f;
        return;
    }
    const Vec3 tau = hetero_optical_depth(s, m, med, o, d, t);
    const Vec3 tr{expf(-tau.x), expf(-tau.y), expf(-tau.z)};
    const float pass = (tr.x + tr.y + tr.z) * (1.0f / 3.0f);
    seg.fwd *= scatter ? hetero_scatter_q(s, m, med, o + d * t, tr) : pass;
    seg.rev *= start_medium ? hetero_scatter_q(s, m, med, o, tr) : pass;
}

// A piece of the slot's segment in medium med (-1: vacuum) from o along d, of length t:
// homogeneous media by their exact pdfs, heterogeneous by the stand-in.
LANTERN_HD inline void medium_segment_piece_at(MediumSegmentPdf& seg, const SceneView& s,
                                               int32_t med, Vec3 o, Vec3 d, float t,
                                               bool scatter) {
    const Medium* m = med >= 0 ? &s.media[med] : nullptr;
    if (m && m->hetero)
        medium_segment_piece_hetero(seg, s, med, o, d, t, scatter);
    else
        medium_segment_piece(seg, m, t, scatter);
}

// A free flight over [0, t_end] from o along d in heterogeneous medium med by spectral tracking
// (channels weighted by beta: the tracking's own rule, which the MIS weights do not read), from
// the tracking block of the path's stream (medium_tracking_rng, slot 0; rng moves on by one).
LANTERN_HD inline MediumStep bdpt_hetero_flight(const SceneView& s, int32_t med, Vec3 o, Vec3 d,
                                                float t_end, Vec3 beta, Rng& rng) {
    Rng tr = medium_tracking_rng(rng, 0);
    rng.uniform();  // the next segment's tracking starts a block of its own
    const HeteroStep h = medium_track(
        s, s.media[med], med, o, d, t_end, beta, tr, [](float, Vec3, float) {},
        [](float, float, Vec3) {});
    return MediumStep{h.t, h.scattered, h.weight};
}

// The transmittance of a piece of a connecting segment: ratio tracking in heterogeneous media
// (numbers from track), Beer-Lambert in homogeneous ones.
LANTERN_HD inline Vec3 medium_piece_transmittance(const SceneView& s, int32_t med, Vec3 o, Vec3 d,
                                                  float t, Rng& track) {
    const Medium& m = s.media[med];
    return m.hetero ? medium_ratio_tracking(s, m, med, o, d, t, track)
                    : medium_transmittance(m, t);
}

// The stream a connection's ratio tracking draws from: the camera path's tracking block 2
// (block 1 is its next-event shadow ray's, as in pt), 256 numbers per connection j.
LANTERN_HD inline Rng bdpt_conn_tracking_rng(const Rng& path, int j) {
    Rng r = medium_tracking_rng(path, 2);
#ifdef LANTERN_RNG_PCG
    r.state = mix64(r.state + (uint64_t(j) << 8));  // (the PCG build: a stream per j)
    r.next();
#else
    r.dim += uint32_t(j) << 8;
#endif
    return r;
}

}  // namespace lantern
