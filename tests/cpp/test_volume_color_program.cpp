// Colour programs of heterogeneous media (kTargetVolumeColor, scene/medium_color_build.cpp,
// docs/volumes.md "Node graphs on volume inputs"): a colour c per point from a ColorRamp over a
// grid's value (a Volume object) or over the position (a mesh volume) scatters
// color_scatter x c and absorbs color_absorb x max(1 - c, 0) per unit of density. Every majorant
// brick (and a mesh medium's one majorant) bounds the extinction sampled along random rays; the
// control: the same scene's majorants without the colour's part (color_scatter 0, the ramp
// ignored) are exceeded by those samples, so the check can fail. The colour a point reads is
// the ramp's, clamped at 0 and finite for a ramp of negative, huge and NaN rows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "scene/medium_hetero.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;

namespace {

constexpr int kCpNx = 30, kCpNy = 24, kCpNz = 20;

void cp_instr(std::vector<uint32_t>& code, int op, int mode, int flags, int dim, int in, int out,
              int aux = 0, int aux2 = 0) {
    code.insert(code.end(), {uint32_t(op | (mode << 8) | (flags << 16) | (dim << 24)),
                             uint32_t(in | (out << 16)), uint32_t(aux), uint32_t(aux2)});
}

enum class CpRamp { kPlain, kBad };

// The ramp's table (RGBA rows) after 8 constants: plain, a dark blue to a bright orange (c up
// to 1.6: scattering above the socket's range); bad, rows with a negative, a huge and a NaN
// component.
std::vector<float> cp_consts(CpRamp ramp) {
    std::vector<float> c = {0, 0, 0, 0, 0, 0, 0, 0};
    if (ramp == CpRamp::kPlain)
        c.insert(c.end(), {0.05f, 0.1f, 0.6f, 1, 0.9f, 0.5f, 0.2f, 1, 1.6f, 0.7f, 0.05f, 1});
    else
        c.insert(c.end(), {-2.0f, 0.3f, 0.5f, 1, 5e12f, NAN, 0.2f, 1, 0.5f, 0.5f, 0.5f, 1});
    return c;
}

// A Volume object (grid == true: density grid 0, a "heat" grid 1 on its own transform; the
// ramp over the heat's value) or a mesh cube [0, 1]^3 (the ramp over x, density 3) whose
// medium's Color is the ramp; colored false: the same medium without its colour program
// (the control's majorants).
SceneInput cp_scene(bool grid, bool colored, CpRamp ramp = CpRamp::kPlain) {
    SceneInput in;
    const float m16[16] = {0.05f, 0, 0.01f, -0.7f, 0, 0.06f, 0, -0.6f, 0, 0, 0.05f, 0.1f,
                           0, 0, 0, 1};
    if (grid) {
        GridInput d;
        d.name = "density";
        d.dims[0] = kCpNx;
        d.dims[1] = kCpNy;
        d.dims[2] = kCpNz;
        std::copy(m16, m16 + 16, d.index_to_world);
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int k = 0; k < kCpNz; ++k)
            for (int j = 0; j < kCpNy; ++j)
                for (int i = 0; i < kCpNx; ++i)
                    d.voxels.push_back((i > 3 && i < 26 && j > 2 && k > 2 && k < 17)
                                           ? 4.0f * u(rng) : 0.0f);
        in.grids.push_back(d);
        GridInput h = d;
        h.name = "heat";
        h.dims[0] = 12;
        h.dims[1] = 10;
        h.dims[2] = 9;
        const float s[3] = {2.6f, 2.5f, 2.3f};
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) h.index_to_world[4 * r + c] = m16[4 * r + c] * s[c];
        h.voxels.clear();
        for (int k = 0; k < 9; ++k)
            for (int j = 0; j < 10; ++j)
                for (int i = 0; i < 12; ++i)
                    h.voxels.push_back(0.5f +
                                       0.5f * std::sin(0.7f * float(i) - 0.4f * float(j + k)));
        in.grids.push_back(h);
    }
    std::vector<float> c = cp_consts(ramp);
    std::vector<uint32_t> code;
    if (grid) {
        cp_instr(code, kOpGrid, 0, 0, 0, 0, 16, 1);    // heat: 16..19 (its value at 19)
        cp_instr(code, kOpRamp, 0, 1, 0, 19, 24, 8, 3);  // linear ramp of 3 rows: 24..27
    } else {
        cp_instr(code, kOpInput, 0, 0, 0, 0, 16);      // position: 16..18
        cp_instr(code, kOpRamp, 0, 1, 0, 16, 24, 8, 3);
    }
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()),
                   uint32_t(kTargetVolumeColor), 24u};
    MediumInput med;
    med.name = "tinted";
    med.sigma_a = vec3(0.1f, 0.1f, 0.2f);
    med.sigma_s = vec3(0.05f);
    if (!grid) {
        med.sigma_a = med.sigma_a * 3.0f;
        med.sigma_s = med.sigma_s * 3.0f;
    }
    if (colored) {
        med.color_scatter = vec3(grid ? 1.0f : 3.0f);
        med.color_absorb = Vec3{0.4f, 0.5f, 0.6f} * (grid ? 1.0f : 3.0f);
    }
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "tinted";
    mat.medium = 0;
    mat.volume_only = true;
    mat.density_grid = grid ? 0 : -1;
    mat.program_first = 0;
    mat.program_count = colored ? 1 : 0;
    in.materials.push_back(mat);
    if (grid) {
        const Transform tf{{{m16[0], m16[1], m16[2], m16[3]},
                            {m16[4], m16[5], m16[6], m16[7]},
                            {m16[8], m16[9], m16[10], m16[11]}}};
        Vec3 lo = vec3(kInf), hi = vec3(-kInf);
        for (int k = 0; k < 8; ++k) {
            const Vec3 p = tf.point(Vec3{k & 1 ? float(kCpNx) : -1.0f,
                                         k & 2 ? float(kCpNy) : -1.0f,
                                         k & 4 ? float(kCpNz) : -1.0f});
            lo = Vec3{std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
            hi = Vec3{std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
        in.meshes.push_back(box_mesh(lo, hi, 0));
    } else {
        in.meshes.push_back(box_mesh(vec3(0.0f), vec3(1.0f), 0));
    }
    return in;
}

// The largest ratio of the extinction sampled along random rays to the majorant of `bound`'s
// scene where the samples fall (the medium of `sample`'s scene): <= 1 where the majorants hold.
float cp_worst_ratio(const SceneView& sample, const SceneView& bound, Vec3 lo, Vec3 hi,
                     int* checked) {
    const int32_t med = sample.material_medium[0];
    const Medium& m = sample.media[med];
    const Medium& mb = bound.media[bound.material_medium[0]];
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    float worst = 0.0f;
    *checked = 0;
    for (int r = 0; r < 300; ++r) {
        const Vec3 o = lo + (hi - lo) * Vec3{u(rng), u(rng), u(rng)};
        const float ct = 1.0f - 2.0f * u(rng), ph = 2.0f * kPi * u(rng);
        const float st = std::sqrt(std::max(0.0f, 1.0f - ct * ct));
        const Vec3 d{st * std::cos(ph), st * std::sin(ph), ct};
        const float t_end = 0.3f + 1.5f * u(rng);
        MajorantWalk walk = medium_majorant_walk(bound, mb, o, d, t_end);
        MajorantSeg seg;
        while (majorant_next(walk, &seg)) {
            for (int k = 0; k <= 12; ++k) {
                const float x = seg.t0 + (seg.t1 - seg.t0) * (float(k) + 0.5f) / 13.0f;
                const Vec3 p = o + d * x;
                if (!(p.x > lo.x && p.y > lo.y && p.z > lo.z && p.x < hi.x && p.y < hi.y &&
                      p.z < hi.z))
                    continue;
                const MediumCoeffs c = medium_coeffs_at(sample, m, med, p, d);
                const float ext = max_component(c.sigma_a + c.sigma_s);
                // (a homogeneous medium, the mesh's control: its extinction is its majorant)
                const float mu = mb.hetero ? seg.mu : max_component(mb.sigma_t);
                if (ext > 0.0f) worst = std::max(worst, ext / std::max(mu, 1e-30f));
                ++*checked;
            }
        }
    }
    return worst;
}

void cp_box(const SceneInput& in, Vec3* lo, Vec3* hi) {
    *lo = vec3(kInf);
    *hi = vec3(-kInf);
    const std::vector<float>& p = in.meshes[0].positions;
    for (size_t k = 0; k + 2 < p.size(); k += 3) {
        *lo = Vec3{std::min(lo->x, p[k]), std::min(lo->y, p[k + 1]), std::min(lo->z, p[k + 2])};
        *hi = Vec3{std::max(hi->x, p[k]), std::max(hi->y, p[k + 1]), std::max(hi->z, p[k + 2])};
    }
}

}  // namespace

TEST(VolumeColorProgram, MajorantsBoundTheColouredExtinction) {
    for (bool grid : {true, false}) {
        const SceneInput in = cp_scene(grid, true), plain = cp_scene(grid, false);
        HostScene scene(in), without(plain);
        const SceneView& s = scene.view();
        const Medium& m = s.media[s.material_medium[0]];
        ASSERT_GE(m.color_prog, 0);
        ASSERT_EQ(m.hetero, 1u);
        EXPECT_EQ(m.majorant_grid >= 0, grid);
        Vec3 lo, hi;
        cp_box(in, &lo, &hi);
        int checked = 0, checked_control = 0;
        const float worst = cp_worst_ratio(s, s, lo, hi, &checked);
        // the control: the majorants of the medium without its colour's part
        const float control = cp_worst_ratio(s, without.view(), lo, hi, &checked_control);
        std::printf("%s: %d samples, sigma_t / majorant at most %.4f; against the majorants "
                    "without the colour %.3f\n", grid ? "grid" : "mesh", checked, worst, control);
        EXPECT_GT(checked, grid ? 5000 : 1000);  // (a mesh medium: one majorant a ray)
        EXPECT_LE(worst, 1.0f + 1e-5f);
        EXPECT_GT(worst, grid ? 0.3f : 0.6f) << "the bound should not be loose everywhere";
        EXPECT_GT(control, 1.2f) << "the control: without the colour's part samples exceed it";
    }
}

TEST(VolumeColorProgram, BadRampRowsGiveFiniteClampedColour) {
    const SceneInput in = cp_scene(false, true, CpRamp::kBad);
    HostScene scene(in);
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    const Medium& m = s.media[med];
    ASSERT_GE(m.color_prog, 0);
    EXPECT_TRUE(std::isfinite(m.majorant));
    float smax = 0.0f;
    for (int k = 0; k <= 40; ++k) {
        const Vec3 p{float(k) / 40.0f, 0.5f, 0.5f};
        const Vec3 c = medium_color_at(s, m.color_prog, medium_shade_point(med, p, Vec3{1, 0, 0}));
        for (float v : {c.x, c.y, c.z}) {
            EXPECT_TRUE(std::isfinite(v));
            EXPECT_GE(v, 0.0f);
            EXPECT_LE(v, 1e9f);
        }
        const MediumCoeffs co = medium_coeffs_at(s, m, med, p, Vec3{1, 0, 0});
        EXPECT_TRUE(std::isfinite(max_component(co.sigma_a + co.sigma_s)));
        EXPECT_LE(max_component(co.sigma_a + co.sigma_s), m.majorant * (1.0f + 1e-5f));
        smax = std::max(smax, co.sigma_s.x);
    }
    // x = 0: the red row's -2 is 0 (no negative scattering), its absorption max(1 - 0, 0)
    const MediumCoeffs at0 = medium_coeffs_at(s, m, med, Vec3{0.0f, 0.5f, 0.5f}, Vec3{1, 0, 0});
    EXPECT_NEAR(at0.sigma_s.x, 0.15f, 1e-5f);
    EXPECT_NEAR(at0.sigma_a.x, 0.3f + 1.2f, 1e-4f);
    EXPECT_GT(smax, 1e6f);  // the huge row scatters (clamped at 1e9 per unit of colour)
}
