// Colour grids of Volume objects (docs/volumes.md, issue 29): grid_color's trilinear colour
// against a multilinear field it reproduces exactly, its absorption factor the trilinear value of
// max(1 - base c, 0) per voxel (the average of Cycles' stochastic lookup; the factor of the
// interpolated colour as the control, which differs where the voxels straddle 1 / base), 0 and 1
// outside the block; at scene load, a colour grid of a transform of its own: the medium's
// coefficients follow Cycles' Principled Volume rule at random points, and the majorant bricks
// bound the extinction there (tighter than the colour's global bound in some brick); a vec3 grid
// as the density and a float grid as the colour are refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/medium_grid.h"
#include "scene/medium_hetero.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;

namespace {

constexpr int kColorNx = 5, kColorNy = 4, kColorNz = 3;

// channel c's colour at index (i, j, k): multilinear, so trilinear interpolation is exact
double colour(int c, double i, double j, double k) {
    return 0.1 + 0.2 * c + 0.15 * i - 0.05 * j + 0.1 * k + 0.02 * i * j * k;
}

std::vector<float> colour_voxels() {
    std::vector<float> v;
    for (int k = 0; k < kColorNz; ++k)
        for (int j = 0; j < kColorNy; ++j)
            for (int i = 0; i < kColorNx; ++i)
                for (int c = 0; c < 3; ++c) v.push_back(float(colour(c, i, j, k)));
    return v;
}

DensityGrid identity_colour_grid() {
    DensityGrid g{};
    g.world_to_index = Transform{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    g.nx = kColorNx;
    g.ny = kColorNy;
    g.nz = kColorNz;
    g.channels = 3;
    return g;
}

}  // namespace

TEST(ColourGrid, TrilinearColourAndAbsorptionFactor) {
    const DensityGrid g = identity_colour_grid();
    const std::vector<float> v = colour_voxels();
    const Vec3 base{1.0f, 1.2f, 1.5f};
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int straddles = 0;
    for (int n = 0; n < 300; ++n) {
        const float x = u(rng) * (kColorNx - 1), y = u(rng) * (kColorNy - 1), z = u(rng) * (kColorNz - 1);
        const GridColor r = grid_color(g, v.data(), base, Vec3{x, y, z});
        const float cs[3] = {r.color.x, r.color.y, r.color.z};
        const float as[3] = {r.absorb.x, r.absorb.y, r.absorb.z};
        const float bs[3] = {base.x, base.y, base.z};
        for (int c = 0; c < 3; ++c) {
            ASSERT_NEAR(cs[c], colour(c, x, y, z), 1e-5) << x << " " << y << " " << z;
            // the factor: the voxels' max(1 - base c, 0), trilinearly weighted
            const int i = std::min(int(x), kColorNx - 2), j = std::min(int(y), kColorNy - 2),
                      k = std::min(int(z), kColorNz - 2);
            double want = 0.0;
            for (int q = 0; q < 8; ++q) {
                const int di = q & 1, dj = (q >> 1) & 1, dk = q >> 2;
                const double w = (di ? x - i : 1 - (x - i)) * (dj ? y - j : 1 - (y - j)) *
                                 (dk ? z - k : 1 - (z - k));
                want += w * std::max(1.0 - bs[c] * colour(c, i + di, j + dj, k + dk), 0.0);
            }
            ASSERT_NEAR(as[c], want, 1e-5);
            // the control: max(1 - base x the interpolated colour, 0) differs where the voxels
            // straddle 1 / base
            const double naive = std::max(1.0 - bs[c] * colour(c, x, y, z), 0.0);
            straddles += std::fabs(naive - want) > 1e-3;
        }
    }
    EXPECT_GT(straddles, 20);
    // at voxel centres the colour is the voxel's; outside the block: colour 0, factor 1
    const GridColor r = grid_color(g, v.data(), base, Vec3{2, 1, 1});
    EXPECT_FLOAT_EQ(r.color.y, float(colour(1, 2, 1, 1)));
    const GridColor out = grid_color(g, v.data(), base, Vec3{-1.5f, 0, 0});
    EXPECT_EQ(out.color.x, 0.0f);
    EXPECT_EQ(out.absorb.z, 1.0f);
}

namespace {

// A smoke of 20^3 density voxels (a ramp in z) with a colour grid of 7^3 voxels over the same
// region, a transform of its own (scaled, shifted by a third of a voxel), colour rising along x.
SceneInput colour_smoke(bool swap = false) {
    SceneInput in;
    GridInput d;
    d.name = "smoke:density";
    d.dims[0] = d.dims[1] = d.dims[2] = 20;
    const float md[16] = {0.05f, 0, 0, -0.5f, 0, 0.05f, 0, -0.5f, 0, 0, 0.05f, -0.5f, 0, 0, 0, 1};
    std::copy(md, md + 16, d.index_to_world);
    for (int k = 0; k < 20; ++k)
        for (int j = 0; j < 20; ++j)
            for (int i = 0; i < 20; ++i) d.voxels.push_back(0.5f + 0.1f * k);
    GridInput c;
    c.name = "smoke:color";
    c.channels = 3;
    c.dims[0] = c.dims[1] = c.dims[2] = 7;
    const float mc[16] = {0.16f, 0, 0, -0.45f, 0, 0.16f, 0, -0.5f, 0, 0, 0.16f, -0.5f, 0, 0, 0, 1};
    std::copy(mc, mc + 16, c.index_to_world);
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 7; ++i) {
                c.voxels.push_back(0.2f * i);
                c.voxels.push_back(0.5f);
                c.voxels.push_back(1.2f - 0.2f * i);
            }
    in.grids.push_back(swap ? c : d);
    in.grids.push_back(swap ? d : c);
    MediumInput med;
    med.name = "smoke";
    med.color_scatter = Vec3{2.0f, 1.5f, 1.0f};
    med.color_absorb = Vec3{0.8f, 0.8f, 0.8f};
    med.color_base = Vec3{0.9f, 0.9f, 0.9f};
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "smoke";
    mat.medium = 0;
    mat.volume_only = true;
    mat.density_grid = 0;
    mat.color_grid = 1;
    in.materials.push_back(mat);
    in.meshes.push_back(box_mesh({-0.55f, -0.55f, -0.55f}, {0.5f, 0.5f, 0.5f}, 0));
    return in;
}

}  // namespace

TEST(ColourGrid, SceneCoefficientsAndMajorantBricks) {
    HostScene scene(colour_smoke());
    const SceneView& s = scene.view();
    ASSERT_EQ(s.num_grids, 2);
    EXPECT_EQ(s.grids[1].channels, 3);
    const int32_t med = s.material_medium[0];
    const Medium& m = s.media[med];
    ASSERT_EQ(m.color_grid, 1);
    ASSERT_GE(m.majorant_grid, 0);
    EXPECT_EQ(m.scatters, 1u);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-0.49f, 0.44f);  // inside the density block
    const Vec3 d{0.0f, 0.0f, 1.0f};
    float global = 0.0f, lowest = 1e30f;
    for (int n = 0; n < 2000; ++n) {
        const Vec3 p{u(rng), u(rng), u(rng)};
        const MediumCoeffs c = medium_coeffs_at(s, m, med, p, d);
        // Cycles' rule with the colour grid's own transform (colour linear in x between its
        // voxel centres at -0.45 + 0.16 i; clamped voxels beyond the block read 0)
        const float den = 0.5f + 0.1f * ((p.z + 0.5f) / 0.05f);
        const GridColor gc = grid_color(s.grids[1], s.grid_voxels, m.color_base, p);
        const float qi = (p.x + 0.45f) / 0.16f, qj = (p.y + 0.5f) / 0.16f,
                    qk = (p.z + 0.5f) / 0.16f;
        if (qi > 0.0f && qi < 6.0f && qj > 0.0f && qj < 6.0f && qk > 0.0f && qk < 6.0f)
            ASSERT_NEAR(gc.color.x, 0.2f * qi, 1e-4) << p.x;
        ASSERT_NEAR(c.sigma_s.x, 2.0f * gc.color.x * den, 1e-3);
        ASSERT_NEAR(c.sigma_a.z, 0.8f * gc.absorb.z * den, 1e-3);
        const Vec3 st = c.sigma_a + c.sigma_s;
        MajorantWalk w = medium_majorant_walk(s, m, p, d, 1e-4f);
        MajorantSeg seg;
        ASSERT_TRUE(majorant_next(w, &seg));
        ASSERT_LE(max_component(st), seg.mu * (1.0f + 1e-5f)) << p.x << " " << p.y << " " << p.z;
        global = std::max(global, seg.mu);
        lowest = std::min(lowest, seg.mu / std::max(max_component(st), 1e-6f));
    }
    // the per-brick colour bound is tighter than the whole grid's somewhere
    EXPECT_LT(lowest, 2.0f);
    EXPECT_GT(global, 0.0f);
}

TEST(ColourGrid, WrongKindsOfGridAreRefusedByName) {
    SceneInput in = colour_smoke(true);  // the density names the colour grid and vice versa
    try {
        HostScene scene(in);
        FAIL() << "a vec3 density was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("'smoke:color' is a colour"), std::string::npos)
            << e.what();
    }
    in = colour_smoke();
    in.materials[0].color_grid = 0;  // a float grid as the colour
    try {
        HostScene scene(in);
        FAIL() << "a float colour was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("'smoke:density' is a float grid"),
                  std::string::npos)
            << e.what();
    }
}
