// The stand-in pdf of heterogeneous media in the bidirectional integrators
// (integrator/bdpt_medium_hetero.h, docs/volumes.md): the forward factor of a segment equals the
// reverse factor of the reversed segment (the property the MIS weights need: every technique
// evaluates the same function of the path), with a left-point quadrature as the negative
// control; and the stand-in is the exact homogeneous formula with the exact optical depth where
// the midpoint rule is exact (a density linear in position), with a 3 % control.
#include <gtest/gtest.h>

#include <cmath>

#include "integrator/bdpt_medium.h"

using namespace lantern;

namespace {

// A SceneView whose one program returns the position's x (kOpInput mode 0; the points below
// have x > 0) and one medium of that density with coefficients per unit density.
struct RampScene {
    NodeInstr code[1];
    MaterialProgram prog;
    Medium medium{};
    SceneView view{};
    RampScene(Vec3 sigma_a, Vec3 sigma_s) {
        code[0] = NodeInstr{};
        code[0].op = kOpInput;
        code[0].mode = 0;
        code[0].dim = 3;
        prog = MaterialProgram{0, 1, 0, 0, kTargetDensity, 0};
        medium.sigma_a = sigma_a;
        medium.sigma_s = sigma_s;
        medium.sigma_t = sigma_a + sigma_s;
        medium.scatters = 1u;
        medium.hetero = 1;
        medium.density_prog = 0;
        medium.density_grid = -1;
        medium.majorant = 100.0f;
        view.programs = &prog;
        view.program_code = code;
        view.media = &medium;
        view.num_media = 1;
    }
};

struct Ends {
    float fwd, rev;
};

// One piece from a to b (both ends medium vertices when `vertices`, else surfaces).
Ends piece(const SceneView& s, Vec3 a, Vec3 b, bool vertices) {
    const float t = length(b - a);
    MediumSegmentPdf seg = medium_segment_begin(vertices);
    medium_segment_piece_at(seg, s, 0, a, (b - a) / t, t, vertices);
    return Ends{seg.fwd, seg.rev};
}

const Vec3 kA{0.3f, 0.1f, -0.2f}, kB{2.1f, 0.9f, 0.4f};

}  // namespace

TEST(BdptMediumHetero, StandInIsSymmetric) {
    const RampScene sc(vec3(0.1f, 0.2f, 0.4f), vec3(0.9f, 0.6f, 0.3f));
    for (bool vertices : {true, false}) {
        const Ends ab = piece(sc.view, kA, kB, vertices), ba = piece(sc.view, kB, kA, vertices);
        std::printf("vertices %d: fwd %.7g rev %.7g | reversed fwd %.7g rev %.7g\n", vertices,
                    ab.fwd, ab.rev, ba.fwd, ba.rev);
        EXPECT_GT(ab.fwd, 0.0f);
        EXPECT_NEAR(ab.fwd, ba.rev, 1e-5f * ab.fwd);
        EXPECT_NEAR(ab.rev, ba.fwd, 1e-5f * ab.rev);
        if (vertices) EXPECT_GT(std::fabs(ab.fwd - ab.rev), 0.05f * ab.fwd);  // x differs
    }
    // negative control: a left-point rule (nodes at k h, not (k + 1/2) h) is not symmetric
    auto left_tau = [&](Vec3 a, Vec3 b) {
        const float t = length(b - a), h = t / kHeteroQuadrature;
        const Vec3 d = (b - a) / t;
        float den = 0.0f;
        for (int k = 0; k < kHeteroQuadrature; ++k)
            den += medium_density(sc.view, sc.medium, 0, a + d * (h * float(k)), d);
        return den * h;
    };
    EXPECT_GT(std::fabs(left_tau(kA, kB) - left_tau(kB, kA)), 0.05f * left_tau(kA, kB));
}

TEST(BdptMediumHetero, StandInIsExactForALinearDensity) {
    const Vec3 sa{0.1f, 0.2f, 0.4f}, ss{0.9f, 0.6f, 0.3f};
    const RampScene sc(sa, ss);
    const Ends e = piece(sc.view, kA, kB, true);
    const Ends p = piece(sc.view, kA, kB, false);
    // the density x along the chord: integral (xB - xA) t / |B - A| ... = t (xA + xB) / 2
    const double t = length(kB - kA), integral = t * (kA.x + kB.x) / 2.0;
    const double st[3] = {sa.x + ss.x, sa.y + ss.y, sa.z + ss.z};
    for (double scale : {1.0, 1.03}) {
        double fwd = 0.0, rev = 0.0, pass = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double tr = std::exp(-st[c] * scale * integral);
            fwd += st[c] * scale * kB.x * tr / 3.0;
            rev += st[c] * scale * kA.x * tr / 3.0;
            pass += tr / 3.0;
        }
        std::printf("scale %.2f: fwd %.7g (want %.7g) rev %.7g (%.7g) pass %.7g (%.7g)\n", scale,
                    e.fwd, fwd, e.rev, rev, p.fwd, pass);
        if (scale == 1.0) {
            EXPECT_NEAR(e.fwd, fwd, 1e-5 * fwd);
            EXPECT_NEAR(e.rev, rev, 1e-5 * rev);
            EXPECT_NEAR(p.fwd, pass, 1e-5 * pass);
            EXPECT_NEAR(p.rev, pass, 1e-5 * pass);
        } else {  // negative control: the extinction 3 % off is told apart
            EXPECT_GT(std::fabs(e.fwd - fwd), 1e-3 * fwd);
            EXPECT_GT(std::fabs(p.fwd - pass), 1e-3 * pass);
        }
    }
}

TEST(BdptMediumHetero, HomogeneousPiecesKeepTheirExactPdfs) {
    // medium_segment_piece_at on a homogeneous medium is medium_segment_piece, bit for bit
    Medium m{};
    m.sigma_a = vec3(0.1f, 0.2f, 0.3f);
    m.sigma_s = vec3(1.0f, 0.5f, 0.25f);
    m.sigma_t = m.sigma_a + m.sigma_s;
    m.scatters = 1u;
    SceneView v{};
    v.media = &m;
    v.num_media = 1;
    for (bool start : {false, true})
        for (bool scatter : {false, true}) {
            MediumSegmentPdf a = medium_segment_begin(start), b = a;
            medium_segment_piece(a, &m, 1.7f, scatter);
            medium_segment_piece_at(b, v, 0, kA, vec3(1.0f, 0.0f, 0.0f), 1.7f, scatter);
            EXPECT_EQ(a.fwd, b.fwd);
            EXPECT_EQ(a.rev, b.rev);
            EXPECT_EQ(a.flags, b.flags);
        }
}
