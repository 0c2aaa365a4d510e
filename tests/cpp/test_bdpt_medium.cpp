// The bidirectional integrators' medium pieces (integrator/bdpt_medium.h): the throughput-free
// channel rule's free flights (expectations per channel; the scatter distances' histogram
// against the density the MIS quantities use, and the pass probability; a control with pt's
// throughput-weighted channels), and a segment's distance factors across pieces of media and
// vacuum against a simulation of the walk (forward), the reverse factor against the forward one
// of the reversed segment, and the medium vertex's encoding in the cache.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "backend/cpu/bvh_accel.h"
#include "core/rng.h"
#include "scene/scene.h"
#include "integrator/bdpt_medium.h"
#include "test_bsdf_helpers.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;
using lantern::test::MeanSe;
using lantern::test::mean_matches;

namespace {

Medium make_medium(Vec3 sigma_s, Vec3 sigma_a) {
    Medium m{};
    m.sigma_s = sigma_s;
    m.sigma_a = sigma_a;
    m.sigma_t = sigma_s + sigma_a;
    m.scatters = (sigma_s.x > 0.0f || sigma_s.y > 0.0f || sigma_s.z > 0.0f) ? 1u : 0u;
    m.g = 0.3f;
    m.outside = -1;
    return m;
}

struct Piece {
    const Medium* m;  // null: vacuum
    float len;
};

// The forward density per unit length of the segment's walk scattering at position x (and the
// probability of passing it all), by bdpt_medium.h.
double fwd_density(const std::vector<Piece>& pieces, double x) {
    MediumSegmentPdf seg = medium_segment_begin(false);
    double start = 0.0;
    for (const Piece& pc : pieces) {
        if (x < start + pc.len) {
            medium_segment_piece(seg, pc.m, float(x - start), true);
            return seg.fwd;
        }
        medium_segment_piece(seg, pc.m, pc.len, false);
        start += pc.len;
    }
    return 0.0;
}
double pass_probability(const std::vector<Piece>& pieces) {
    MediumSegmentPdf seg = medium_segment_begin(false);
    for (const Piece& pc : pieces) medium_segment_piece(seg, pc.m, pc.len, false);
    return seg.fwd;
}

// The walk: each piece draws its own flight (channel probabilities pmf, or the rule's); returns
// the scatter position, or -1 when it passes everything.
double walk(const std::vector<Piece>& pieces, Pcg32& rng, const Vec3* pmf) {
    double start = 0.0;
    for (const Piece& pc : pieces) {
        if (pc.m && pc.m->scatters) {
            const float uc = rng.uniform(), ud = rng.uniform();
            const MediumStep st = pmf ? medium_sample_distance(*pc.m, pc.len, *pmf, uc, ud)
                                      : bdpt_medium_flight(*pc.m, pc.len, uc, ud);
            if (st.scattered) return start + st.t;
        }
        start += pc.len;
    }
    return -1.0;
}

// Histogram of the walk's scatter positions (bins over the segment, a cell for passing)
// against fwd_density and pass_probability: chi-square p-value.
double walk_chi2(const std::vector<Piece>& pieces, const Vec3* pmf, int n, int bins = 60) {
    double total = 0.0;
    for (const Piece& pc : pieces) total += pc.len;
    std::vector<double> obs(bins + 1, 0.0), expd(bins + 1, 0.0);
    Pcg32 rng = Pcg32::for_path(29, 3, 0);
    for (int k = 0; k < n; ++k) {
        const double x = walk(pieces, rng, pmf);
        obs[x < 0.0 ? bins : std::min(bins - 1, int(x / total * bins))] += 1.0;
    }
    const int sub = 400;
    const double w = total / bins;
    for (int b = 0; b < bins; ++b) {
        double acc = 0.0;
        for (int j = 0; j < sub; ++j) acc += fwd_density(pieces, w * (b + (j + 0.5) / sub));
        expd[b] = acc * w / sub * n;
    }
    expd[bins] = pass_probability(pieces) * n;
    double chi2 = 0.0, pe = 0.0, po = 0.0;
    int cells = 0;
    for (int b = 0; b <= bins; ++b) {
        pe += expd[b];
        po += obs[b];
        if (pe < 5.0 && b < bins) continue;
        if (pe > 0.0) {
            chi2 += (po - pe) * (po - pe) / pe;
            ++cells;
        } else if (po > 0.0) {
            return 0.0;  // an impossible event happened
        }
        pe = po = 0.0;
    }
    const int dof = std::max(1, cells - 1);
    const double p = lantern::test::chi2_upper_tail(chi2, dof);
    std::printf("walk chi2 %.1f dof %d p %.3g\n", chi2, dof, p);
    return p;
}

}  // namespace

// ---- The rule's flights stay unbiased per channel: E[weight | passed] = T(L), E[weight |
// scattered] = sigma_s / sigma_t (1 - T(L)), each within its standard error ----
TEST(BdptMedium, FlightExpectationsPerChannel) {
    const Medium m = make_medium(vec3(0.3f, 0.9f, 1.6f), vec3(0.2f, 0.1f, 0.4f));
    const float len = 1.3f;
    MeanSe pass[3], scat[3];
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    for (int k = 0; k < 2000000; ++k) {
        const float uc = rng.uniform(), ud = rng.uniform();
        const MediumStep st = bdpt_medium_flight(m, len, uc, ud);
        const float w[3] = {st.weight.x, st.weight.y, st.weight.z};
        for (int c = 0; c < 3; ++c) {
            pass[c].add(st.scattered ? 0.0 : w[c]);
            scat[c].add(st.scattered ? w[c] : 0.0);
        }
    }
    const float st_[3] = {m.sigma_t.x, m.sigma_t.y, m.sigma_t.z};
    const float ss[3] = {m.sigma_s.x, m.sigma_s.y, m.sigma_s.z};
    const double z = lantern::test::z_bonferroni(6);
    for (int c = 0; c < 3; ++c) {
        const double tr = std::exp(-double(st_[c]) * len);
        auto a = mean_matches(pass[c], tr, z);
        auto b = mean_matches(scat[c], ss[c] / st_[c] * (1.0 - tr), z);
        std::printf("channel %d: pass %s; scatter %s\n", c, a.message(), b.message());
        EXPECT_TRUE(a) << "channel " << c;
        EXPECT_TRUE(b) << "channel " << c;
    }
}

// ---- The densities the MIS quantities use are the densities the flights have: one medium;
// a segment of medium, vacuum, a second medium, an absorbing medium (not sampled) and the first
// medium again. Control: pt's throughput-weighted channel choice has another density ----
TEST(BdptMedium, SegmentForwardFactorMatchesTheWalk) {
    const Medium a = make_medium(vec3(0.4f, 0.9f, 1.5f), vec3(0.1f, 0.2f, 0.05f));
    const Medium b = make_medium(vec3(2.0f, 0.3f, 0.7f), vec3(0.0f, 0.5f, 0.2f));
    const Medium absorb = make_medium(vec3(0.0f), vec3(0.6f, 0.2f, 0.9f));
    const std::vector<Piece> one = {{&a, 1.7f}};
    const std::vector<Piece> many = {
        {&a, 0.6f}, {nullptr, 0.5f}, {&b, 0.8f}, {&absorb, 0.3f}, {&a, 0.9f}};
    const int n = 400000;
    EXPECT_GT(walk_chi2(one, nullptr, n), 1e-3);
    EXPECT_GT(walk_chi2(many, nullptr, n), 1e-3);
    // the pass probability by itself (the last cell above, pooled with nothing)
    {
        Pcg32 rng = Pcg32::for_path(31, 0, 0);
        MeanSe passed;
        for (int k = 0; k < 10 * n; ++k) passed.add(walk(many, rng, nullptr) < 0.0 ? 1.0 : 0.0);
        auto r = mean_matches(passed, pass_probability(many), lantern::test::z_bonferroni(1));
        std::printf("pass probability: %s\n", r.message());
        EXPECT_TRUE(r);
    }
    // control: channels weighted by a throughput (pt's rule) do not have this density
    const Vec3 pmf = medium_channel_pmf(vec3(0.1f, 0.3f, 1.0f));
    EXPECT_LT(walk_chi2(many, &pmf, n), 1e-3);
}

// ---- The reverse factor at the near end is the forward factor of the reversed segment (the
// other sub-path walks it the other way), whether the near end is a surface or a medium vertex;
// and the single-piece values in closed form ----
TEST(BdptMedium, SegmentReverseFactorIsTheReversedWalk) {
    const Medium a = make_medium(vec3(0.4f, 0.9f, 1.5f), vec3(0.1f, 0.2f, 0.05f));
    const Medium b = make_medium(vec3(2.0f, 0.3f, 0.7f), vec3(0.0f, 0.5f, 0.2f));
    const Medium absorb = make_medium(vec3(0.0f), vec3(0.6f, 0.2f, 0.9f));
    const std::vector<std::vector<Piece>> segments = {
        {{&a, 1.1f}},
        {{&a, 0.6f}, {nullptr, 0.5f}, {&b, 0.8f}},
        {{&b, 0.2f}, {&absorb, 0.3f}, {&a, 0.9f}, {nullptr, 2.0f}},
    };
    for (size_t k = 0; k < segments.size(); ++k) {
        const auto& pieces = segments[k];
        for (int start_medium = 0; start_medium < 2; ++start_medium) {
            if (start_medium && !(pieces[0].m && pieces[0].m->scatters)) continue;
            for (int end_medium = 0; end_medium < 2; ++end_medium) {
                const Piece& last = pieces.back();
                if (end_medium && !(last.m && last.m->scatters)) continue;
                MediumSegmentPdf f = medium_segment_begin(start_medium != 0);
                for (size_t j = 0; j < pieces.size(); ++j)
                    medium_segment_piece(f, pieces[j].m, pieces[j].len,
                                         end_medium && j + 1 == pieces.size());
                MediumSegmentPdf r = medium_segment_begin(end_medium != 0);
                for (size_t j = pieces.size(); j-- > 0;)
                    medium_segment_piece(r, pieces[j].m, pieces[j].len,
                                         start_medium && j == 0);
                EXPECT_NEAR(f.rev, r.fwd, 1e-6f * r.fwd) << "segment " << k;
                EXPECT_NEAR(f.fwd, r.rev, 1e-6f * f.fwd) << "segment " << k;
                EXPECT_GT(f.fwd, 0.0f);
                EXPECT_GT(f.rev, 0.0f);
            }
        }
    }
    // one piece, closed form: mean of sigma_t exp(-sigma_t t) and of exp(-sigma_t t)
    const float t = 0.75f;
    const double sc = (0.5 * std::exp(-0.5 * t) + 1.1 * std::exp(-1.1 * t) +
                       1.55 * std::exp(-1.55 * t)) / 3.0;
    const double ps = (std::exp(-0.5 * t) + std::exp(-1.1 * t) + std::exp(-1.55 * t)) / 3.0;
    MediumSegmentPdf s = medium_segment_begin(true);
    medium_segment_piece(s, &a, t, true);
    EXPECT_NEAR(s.fwd, sc, 1e-6 * sc);
    EXPECT_NEAR(s.rev, sc, 1e-6 * sc);
    s = medium_segment_begin(false);
    medium_segment_piece(s, &a, t, true);
    EXPECT_NEAR(s.fwd, sc, 1e-6 * sc);
    EXPECT_NEAR(s.rev, ps, 1e-6 * ps);
    // control: the reverse factor is not the forward one where the ends differ
    EXPECT_GT(std::fabs(s.rev - s.fwd), 0.05 * sc);
    // a medium that does not scatter samples nothing: factor 1 both ways
    s = medium_segment_begin(false);
    medium_segment_piece(s, &absorb, t, false);
    EXPECT_EQ(s.fwd, 1.0f);
    EXPECT_EQ(s.rev, 1.0f);
}

// ---- The recursion's update at a medium vertex is SmallVCM's with the distance factors in
// place of the cosines: dVCM = d^2 / (p_w F_fwd), and a reverse factor that reaches dVC only ----
TEST(BdptMedium, HitUpdateAndVertexEncoding) {
    MediumSegmentPdf seg{0.4f, 0.25f, kSegPieceDone};
    float dvcm = 2.0f, dvc = 3.0f;
    bdpt_medium_hit_update(dvcm, dvc, 1.5f, 1.0f, seg, true);
    EXPECT_FLOAT_EQ(dvcm, 2.0f * mis(1.5f * 1.5f) / mis(0.4f));
    EXPECT_FLOAT_EQ(dvc, 3.0f * mis(0.25f) / mis(0.4f));
    float m0 = 0.5f, c0 = 0.7f;
    bdpt_medium_scatter_update(m0, c0, 0.2f);
    EXPECT_FLOAT_EQ(m0, mis(1.0f / 0.2f));
    EXPECT_FLOAT_EQ(c0, mis(1.0f / 0.2f) * (0.7f * mis(0.2f) + 0.5f));
    const LightVertex v = lv_make_medium(vec3(1.0f, 2.0f, 3.0f), vec3(0.0f, 0.0f, 1.0f),
                                         vec3(0.5f), 1.0f, 2.0f, 7, 12, 3);
    EXPECT_TRUE(lv_is_medium(v));
    EXPECT_EQ(lv_medium(v), 7);
    EXPECT_EQ(v.material, kMediumVertexMaterial);
    LightVertex surf = v;
    surf.tri = 0;
    EXPECT_FALSE(lv_is_medium(surf));
    surf.tri = -1;
    EXPECT_FALSE(lv_is_medium(surf));
    // the phase function is symmetric: the reverse pdf is the forward one
    const Medium a = make_medium(vec3(1.0f), vec3(0.0f));
    const Vec3 wo = normalize(vec3(0.2f, 0.5f, -0.8f)), wi = normalize(vec3(-0.6f, 0.1f, 0.3f));
    EXPECT_FLOAT_EQ(bdpt_medium_phase(a, wo, wi), bdpt_medium_phase(a, wi, wo));
    EXPECT_FLOAT_EQ(bdpt_medium_phase(a, wo, wi), hg_phase(a.g, dot(-wo, wi)));
}

// ---- MIS stays exact: on a path light - medium vertex - surface - medium vertex - camera whose
// segments each cross a scattering medium, vacuum and a second scattering medium, the weights
// the recursion gives every technique (s = 0: the camera path hits the light; s = 1: next-event
// estimation; s = 2, 3: connections; t = 1: light tracing), with the distance factors applied
// as bdpt_medium.h prescribes, equal the power heuristic over the techniques' path densities
// computed vertex by vertex (area and volume densities, distance sampling included). Counts 1
// (bdpt's r, n_lt with lt_direct 1). Control: without the deferred reverse factor (the near
// end's distance factor of a segment) the weights do not match. ----
namespace {

struct MisPath {
    static constexpr int n = 4;  // x0 light ... x4 camera
    Vec3 x[n + 1];
    Vec3 nrm[n + 1];  // zero at medium vertices and the camera
    bool medium[n + 1];
    Medium a, b;
    float g = 0.35f;
    float pe_a, pd_a;  // x0's area densities: emission (pick included), next-event estimation
    Vec3 cam_axis;

    float dist(int i, int j) const { return length(x[j] - x[i]); }
    Vec3 dir(int i, int j) const { return normalize(x[j] - x[i]); }
    float cosf_(int j, int i) const {  // |cos| at x_j towards x_i (1 at a medium vertex)
        return (medium[j] || j == n) ? 1.0f : std::fabs(dot(nrm[j], dir(j, i)));
    }
    // the sampling density at vertex j of the direction to `to` given the other neighbour
    float pdf_dir(int j, int from, int to) const {
        const Vec3 wo = dir(j, from), wi = dir(j, to);
        if (medium[j]) return hg_phase(g, dot(-wo, wi));
        return std::fabs(dot(wi, nrm[j])) * kInvPi * (0.7f + 0.3f * dot(wo, wi));
    }
    float emit_dir_pdf() const { return std::fabs(dot(dir(0, 1), nrm[0])) * kInvPi; }
    float camera_pdf_w(Vec3 d) const {
        const float c = dot(d, cam_axis);
        return 1.0f / (0.01f * c * c * c);
    }
    // segment i (x_i -> x_{i+1}): 35 % in a, 30 % vacuum, 35 % in b
    MediumSegmentPdf seg(int i) const {
        const float d = dist(i, i + 1);
        MediumSegmentPdf s = medium_segment_begin(medium[i]);
        medium_segment_piece(s, &a, 0.35f * d, false);
        medium_segment_piece(s, nullptr, 0.3f * d, false);
        medium_segment_piece(s, &b, 0.35f * d, medium[i + 1]);
        return s;
    }
};

MisPath make_mis_path() {
    MisPath p;
    p.x[0] = vec3(0.0f, 0.0f, 3.0f);
    p.nrm[0] = vec3(0.0f, 0.0f, -1.0f);
    p.x[1] = vec3(0.4f, 0.3f, 1.9f);
    p.x[2] = vec3(1.1f, -0.2f, 0.0f);
    p.nrm[2] = normalize(vec3(0.1f, 0.05f, 1.0f));
    p.x[3] = vec3(1.8f, 0.6f, 1.2f);
    p.x[4] = vec3(3.5f, 1.5f, 2.0f);
    for (int j = 0; j <= MisPath::n; ++j) p.medium[j] = (j == 1 || j == 3);
    p.nrm[1] = p.nrm[3] = p.nrm[4] = vec3(0.0f);
    p.a = make_medium(vec3(0.4f, 0.9f, 1.5f), vec3(0.1f, 0.2f, 0.05f));
    p.b = make_medium(vec3(2.0f, 0.3f, 0.7f), vec3(0.0f, 0.5f, 0.2f));
    p.pe_a = 0.3f / 0.5f;  // pick 0.3 of a light of area 0.5
    p.pd_a = 0.6f / 0.5f;  // next-event pick 0.6
    p.cam_axis = normalize(p.x[3] - p.x[4] + vec3(0.1f, -0.2f, 0.0f));
    return p;
}

// The explicit power-heuristic weights of techniques s = 0 .. n (s light vertices).
std::vector<double> explicit_weights(const MisPath& p) {
    const int n = MisPath::n;
    auto lden = [&](int j) {  // light side's density of x_j, j >= 1
        const double pw = j == 1 ? p.emit_dir_pdf() : p.pdf_dir(j - 1, j - 2, j);
        const double d = p.dist(j - 1, j);
        return pw * p.seg(j - 1).fwd * p.cosf_(j, j - 1) / (d * d);
    };
    auto cden = [&](int j) {  // camera side's density of x_j, j <= n - 1
        const double pw = j == n - 1 ? p.camera_pdf_w(p.dir(n, n - 1)) : p.pdf_dir(j + 1, j + 2, j);
        const double d = p.dist(j, j + 1);
        return pw * p.seg(j).rev * p.cosf_(j, j + 1) / (d * d);
    };
    std::vector<double> ps(n + 1);
    for (int s = 0; s <= n; ++s) {
        double v = s == 0 ? 1.0 : (s == 1 ? p.pd_a : p.pe_a);
        for (int j = 1; j < s; ++j) v *= lden(j);
        for (int j = std::max(s, 0); j < n; ++j) v *= cden(j);
        ps[s] = v;
    }
    double sum = 0.0;
    for (double v : ps) sum += v * v;
    for (double& v : ps) v = v * v / sum;
    return ps;
}

// The weights by the recursion (the stages' formulas, bdpt_light.h / bdpt_camera.h, with the
// medium factors); deferred false: the control that forgets the near end's factor.
std::vector<double> recursive_weights(const MisPath& p, bool deferred) {
    const int n = MisPath::n;
    auto hit = [&](float& dvcm, float& dvc, int j, int from, MediumSegmentPdf s) {
        if (!deferred) s.rev = 1.0f;
        bdpt_medium_hit_update(dvcm, dvc, p.dist(from, j), p.cosf_(j, from), s, true);
    };
    auto scatter = [&](float& dvcm, float& dvc, int j, int from, int to) {
        const float fwd = p.pdf_dir(j, from, to), rev = p.pdf_dir(j, to, from);
        if (p.medium[j]) {
            bdpt_medium_scatter_update(dvcm, dvc, fwd);
        } else {
            BsdfSample b{};
            b.pdf_fwd_w = fwd;
            b.pdf_rev_w = rev;
            b.valid = true;
            bdpt_scatter_update(dvcm, dvc, b, p.cosf_(j, to));
        }
    };
    auto flip = [](MediumSegmentPdf s) {  // the segment walked the other way
        return MediumSegmentPdf{s.rev, s.fwd, s.flags};
    };
    // light sub-path: (dvcm, dvc) at x_1 .. x_{n-1}
    float ly_m[n], ly_c[n];
    {
        const float pdf_emit = p.pe_a * p.emit_dir_pdf();
        float dvcm = mis(p.pd_a / pdf_emit), dvc = mis(p.cosf_(0, 1) / pdf_emit);
        for (int j = 1; j < n; ++j) {
            hit(dvcm, dvc, j, j - 1, p.seg(j - 1));
            ly_m[j] = dvcm;
            ly_c[j] = dvc;
            if (j + 1 < n) scatter(dvcm, dvc, j, j - 1, j + 1);
        }
    }
    // camera sub-path: (dvcm, dvc) at x_{n-1} .. x_0
    float cz_m[n], cz_c[n];
    {
        float dvcm = mis(1.0f / p.camera_pdf_w(p.dir(n, n - 1))), dvc = 0.0f;
        for (int j = n - 1; j >= 0; --j) {
            hit(dvcm, dvc, j, j + 1, flip(p.seg(j)));
            cz_m[j] = dvcm;
            cz_c[j] = dvc;
            if (j > 0) scatter(dvcm, dvc, j, j + 1, j - 1);
        }
    }
    std::vector<double> w(n + 1);
    const float pdf_emit0 = p.pe_a * p.emit_dir_pdf();
    // s = 0: the camera path reaches x0
    w[0] = 1.0 / (1.0 + mis(p.pd_a) * cz_m[0] + mis(pdf_emit0) * cz_c[0]);
    // s = 1: next-event estimation from x1 (shadow segment 0 walked from x1)
    {
        const MediumSegmentPdf s0 = p.seg(0);
        const float d2 = p.dist(0, 1) * p.dist(0, 1);
        const float bsdf_fwd = p.pdf_dir(1, 2, 0), bsdf_rev = p.pdf_dir(1, 0, 2);
        const float pdf_light_w = p.pd_a * d2 / p.cosf_(0, 1);
        const float w_light = mis((deferred ? s0.rev : 1.0f) * bsdf_fwd / pdf_light_w);
        const float pdf_lp = pdf_emit0 * p.cosf_(1, 0) * s0.fwd / d2;
        const float w_camera = mis(pdf_lp / p.pd_a) * (cz_m[1] + cz_c[1] * mis(bsdf_rev));
        w[1] = 1.0 / (w_light + 1.0 + w_camera);
    }
    // s = 2 .. n - 1: connect y = x_{s-1} and z = x_s over segment s - 1
    for (int s = 2; s < n; ++s) {
        const int y = s - 1, z = s;
        const MediumSegmentPdf sg = p.seg(y);
        const float d2 = p.dist(y, z) * p.dist(y, z);
        const float pdf_cam_a = p.pdf_dir(z, z + 1, y) * p.cosf_(y, z) *
                                (deferred ? sg.rev : 1.0f) / d2;
        const float pdf_light_a = p.pdf_dir(y, y - 1, z) * p.cosf_(z, y) * sg.fwd / d2;
        const float w_light = mis(pdf_cam_a) * (ly_m[y] + ly_c[y] * mis(p.pdf_dir(y, z, y - 1)));
        const float w_camera =
            mis(pdf_light_a) * (cz_m[z] + cz_c[z] * mis(p.pdf_dir(z, y, z + 1)));
        w[s] = 1.0 / (w_light + 1.0 + w_camera);
    }
    // t = 1: light tracing from y = x_{n-1}
    {
        const int y = n - 1;
        const MediumSegmentPdf sg = p.seg(y);
        const float d2 = p.dist(y, n) * p.dist(y, n);
        const float camera_pdf_a = p.camera_pdf_w(p.dir(n, y)) * p.cosf_(y, n) *
                                   (deferred ? sg.rev : 1.0f) / d2;
        w[n] = 1.0 / (1.0 + mis(camera_pdf_a) * (ly_m[y] + ly_c[y] * mis(p.pdf_dir(y, n, y - 1))));
    }
    return w;
}

}  // namespace

TEST(BdptMedium, RecursiveWeightsAreThePowerHeuristic) {
    const MisPath p = make_mis_path();
    const std::vector<double> want = explicit_weights(p);
    const std::vector<double> got = recursive_weights(p, true);
    const std::vector<double> bad = recursive_weights(p, false);
    double sum = 0.0, worst_bad = 0.0;
    for (size_t s = 0; s < want.size(); ++s) {
        std::printf("s %zu: explicit %.6f recursive %.6f (control %.6f)\n", s, want[s], got[s],
                    bad[s]);
        EXPECT_NEAR(got[s], want[s], 1e-8 + 2e-3 * want[s]) << "technique s = " << s;
        sum += got[s];
        worst_bad = std::max(worst_bad, std::fabs(bad[s] - want[s]) / std::max(want[s], 1e-3));
    }
    EXPECT_NEAR(sum, 1.0, 1e-3);
    EXPECT_GT(worst_bad, 0.01) << "the control (no deferred reverse factor) matched";
    for (double v : want) EXPECT_GT(v, 1e-7);  // every technique takes part
}

// ---- A connecting segment traced through nested media (bdpt_medium_shadow): from vacuum into
// a scattering box, through a second box nested in it (coefficients summed) and out of it,
// ending at a medium vertex in the outer box. Its transmittance is Beer-Lambert over the
// pieces, its factors the products above; walked the other way, the two ends swap. Control: an
// opaque surface across the segment blocks it. ----
namespace {

struct AccelRays {
    const BvhAccel* b;
    HitRecord closest(const Ray& r, RayKind kind) const { return b->intersect(r, kind); }
};

}  // namespace

TEST(BdptMedium, ShadowSegmentThroughNestedMedia) {
    const Vec3 so{0.3f, 0.6f, 0.2f}, sa{0.1f, 0.3f, 0.1f};  // outer: scattering, absorption
    const Vec3 si{1.2f, 0.4f, 0.5f}, ai{0.2f, 0.0f, 0.3f};  // inner
    auto scene = [&](bool blocker) {
        SceneInput in;
        in.width = 4;
        in.height = 4;
        MediumInput outer, inner;
        outer.name = "outer";
        outer.sigma_s = so;
        outer.sigma_a = sa;
        inner.name = "inner";
        inner.sigma_s = si;
        inner.sigma_a = ai;
        in.media = {outer, inner};
        MaterialInput mo, mi, wall;
        mo.name = "outer";
        mo.medium = 0;
        mo.volume_only = true;
        mi.name = "inner";
        mi.medium = 1;
        mi.volume_only = true;
        wall.name = "wall";
        in.materials = {mo, mi, wall};
        in.meshes.push_back(box_mesh({-2, -2, -5}, {2, 2, -1}, 0, "outer"));
        in.meshes.push_back(box_mesh({-1, -1, -3.5f}, {1, 1, -2.5f}, 1, "inner"));
        if (blocker)
            in.meshes.push_back(box_mesh({-0.5f, -0.5f, -2.2f}, {0.5f, 0.5f, -2.1f}, 2, "wall"));
        return in;
    };
    // the pieces' coefficients, from the inputs: outer; outer + inner (summed)
    const Medium m_out = make_medium(so, sa), m_in = make_medium(so + si, sa + ai);
    const Vec3 p0{0.2f, 0.1f, -0.5f}, p1{0.3f, -0.2f, -4.5f};
    const Vec3 d = normalize(p1 - p0);
    const float len = length(p1 - p0), per_z = len / 4.0f;  // length per unit of z
    const float l_out1 = 1.5f * per_z, l_in = 1.0f * per_z, l_out2 = 1.0f * per_z;
    const float want_fwd = bdpt_medium_pass_pdf(m_out, l_out1) * bdpt_medium_pass_pdf(m_in, l_in) *
                           bdpt_medium_scatter_pdf(m_out, l_out2);
    const float want_rev = bdpt_medium_pass_pdf(m_out, l_out1) * bdpt_medium_pass_pdf(m_in, l_in) *
                           bdpt_medium_pass_pdf(m_out, l_out2);
    const Vec3 want_tr = medium_transmittance(m_out, l_out1 + l_out2) *
                         medium_transmittance(m_in, l_in);
    for (int blocker = 0; blocker < 2; ++blocker) {
        const SceneInput in = scene(blocker != 0);
        HostScene hs(in);
        const SceneView s = hs.view();
        std::vector<std::string> w;
        BvhAccel accel(s, 2, w);
        const AccelRays rays{&accel};
        const int32_t outer_med = s.material_medium[0];
        // vacuum (a surface point) -> a medium vertex in the outer box
        const MediumShadow a = bdpt_medium_shadow(s, rays, RayKind::kShadow, p0, d, len, -1,
                                                  false, true);
        // and back: from the medium vertex to the surface point
        const MediumShadow b = bdpt_medium_shadow(s, rays, RayKind::kShadow, p1, -d, len,
                                                  outer_med, true, false);
        if (blocker) {  // control: an opaque wall inside the outer box
            EXPECT_TRUE(is_black(a.tr));
            EXPECT_TRUE(is_black(b.tr));
            continue;
        }
        std::printf("fwd %.6g (want %.6g) rev %.6g (want %.6g) tr %.6g %.6g %.6g\n", a.seg.fwd,
                    want_fwd, a.seg.rev, want_rev, a.tr.x, a.tr.y, a.tr.z);
        EXPECT_NEAR(a.seg.fwd, want_fwd, 2e-3f * want_fwd);
        EXPECT_NEAR(a.seg.rev, want_rev, 2e-3f * want_rev);
        EXPECT_NEAR(b.seg.fwd, want_rev, 2e-3f * want_rev);
        EXPECT_NEAR(b.seg.rev, want_fwd, 2e-3f * want_fwd);
        const float g[3] = {a.tr.x, a.tr.y, a.tr.z}, h[3] = {b.tr.x, b.tr.y, b.tr.z},
                    t[3] = {want_tr.x, want_tr.y, want_tr.z};
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(g[c], t[c], 2e-3f * t[c]) << "channel " << c;
            EXPECT_NEAR(h[c], t[c], 2e-3f * t[c]) << "channel " << c;
        }
        // control: the nesting forgotten (the inner box's own coefficients) is told apart
        const Medium m_alone = make_medium(si, ai);
        const float unnested = bdpt_medium_pass_pdf(m_out, l_out1) *
                               bdpt_medium_pass_pdf(m_alone, l_in) *
                               bdpt_medium_scatter_pdf(m_out, l_out2);
        EXPECT_GT(std::fabs(a.seg.fwd - unnested), 0.02f * want_fwd);
    }
}
