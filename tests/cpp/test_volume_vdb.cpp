// Volume objects' density grids (docs/volumes.md): the trilinear lookup against functions it
// reproduces exactly (affine and multilinear in the index), with a nearest-voxel lookup as a
// negative control; OpenVDB files written here and read back (voxels, the sparse block's origin,
// the transform), their bad input (missing file, not a VDB, no such grid, too large, empty);
// the grid's world-to-index map at scene load; pt through an absorbing grid whose density is a
// ramp against Beer-Lambert (8 seeds' standard error, a 2 % control), with NaN, negative and
// enormous voxels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/cpu/embree_loader.h"
#include "integrator/session.h"
#include "scene/medium_grid.h"
#include "scene/scene.h"
#include "scene/vdb_io.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;

namespace {

constexpr int kNx = 5, kNy = 4, kNz = 6;

// f(i, j, k): affine plus a multilinear term; trilinear interpolation reproduces it exactly
double field(double i, double j, double k) {
    return 0.5 + 0.25 * i - 0.125 * j + 0.3 * k + 0.05 * i * j * k;
}

std::vector<float> field_voxels() {
    std::vector<float> v;
    for (int k = 0; k < kNz; ++k)
        for (int j = 0; j < kNy; ++j)
            for (int i = 0; i < kNx; ++i) v.push_back(float(field(i, j, k)));
    return v;
}

DensityGrid identity_grid() {
    DensityGrid g{};
    g.world_to_index = Transform{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    g.nx = kNx;
    g.ny = kNy;
    g.nz = kNz;
    return g;
}

std::string tmp_path(const char* name) {
    const char* d = std::getenv("TMPDIR");
    return std::string(d ? d : "/tmp") + "/lantern_vdb_" + std::to_string(::getpid()) + "_" + name;
}

}  // namespace

TEST(DensityGrid, TrilinearLookupIsExactForMultilinearFields) {
    const std::vector<float> v = field_voxels();
    const DensityGrid g = identity_grid();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    double worst = 0.0, worst_nearest = 0.0;
    for (int n = 0; n < 2000; ++n) {
        const Vec3 q{u(rng) * (kNx - 1), u(rng) * (kNy - 1), u(rng) * (kNz - 1)};
        const double want = field(q.x, q.y, q.z);
        worst = std::max(worst, std::fabs(grid_lookup_index(g, v.data(), q) - want));
        // negative control: the nearest voxel's value
        const Vec3 r{std::round(q.x), std::round(q.y), std::round(q.z)};
        worst_nearest = std::max(worst_nearest,
                                 std::fabs(grid_lookup_index(g, v.data(), r) - want));
    }
    EXPECT_LT(worst, 2e-5);
    EXPECT_GT(worst_nearest, 0.05);
    // voxel centres are the integers: the voxel itself there
    EXPECT_NEAR(grid_lookup_index(g, v.data(), Vec3{2, 1, 3}), field(2, 1, 3), 1e-6);
    // half a voxel outside the block: halfway to the background 0; a voxel out: 0
    EXPECT_NEAR(grid_lookup_index(g, v.data(), Vec3{-0.5f, 1, 3}), 0.5 * field(0, 1, 3), 1e-6);
    EXPECT_EQ(grid_lookup_index(g, v.data(), Vec3{1, 1, kNz}), 0.0f);
    EXPECT_EQ(grid_lookup_index(g, v.data(), Vec3{NAN, 1, 1}), 0.0f);
    EXPECT_EQ(grid_lookup_index(g, v.data(), Vec3{-1e30f, 1, 1}), 0.0f);
}

TEST(DensityGrid, OneVoxelIsATentOfOneVoxelRadius) {
    const float one = 2.0f;
    DensityGrid g = identity_grid();
    g.nx = g.ny = g.nz = 1;
    EXPECT_FLOAT_EQ(grid_lookup_index(g, &one, Vec3{0, 0, 0}), 2.0f);
    EXPECT_FLOAT_EQ(grid_lookup_index(g, &one, Vec3{0.25f, -0.5f, 0}), 2.0f * 0.75f * 0.5f);
    EXPECT_EQ(grid_lookup_index(g, &one, Vec3{1.0f, 0, 0}), 0.0f);
}

TEST(DensityGrid, SceneMapsTheWorldToTheIndexAndCleansVoxels) {
    // index -> world: voxel size 0.1, rotated 90 degrees about z, translated (1, 2, 3)
    SceneInput in;
    GridInput gi;
    gi.name = "density";
    gi.dims[0] = kNx;
    gi.dims[1] = kNy;
    gi.dims[2] = kNz;
    const float m[16] = {0, -0.1f, 0, 1, 0.1f, 0, 0, 2, 0, 0, 0.1f, 3, 0, 0, 0, 1};
    std::copy(m, m + 16, gi.index_to_world);
    gi.voxels = field_voxels();
    gi.voxels[0] = NAN;
    gi.voxels[1] = -3.0f;
    gi.voxels[2] = 1e20f;
    in.grids.push_back(gi);
    MediumInput med;
    med.name = "smoke";
    med.sigma_a = vec3(1.0f);
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "smoke";
    mat.medium = 0;
    mat.volume_only = true;
    mat.density_grid = 0;
    in.materials.push_back(mat);
    in.meshes.push_back(box_mesh({0.5f, 2, 3}, {1, 2.5f, 3.5f}, 0));
    HostScene scene(in);
    const SceneView& s = scene.view();
    ASSERT_EQ(s.num_grids, 1);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int n = 0; n < 200; ++n) {
        const float i = 1 + u(rng) * (kNx - 2), j = 1 + u(rng) * (kNy - 2),
                    k = 1 + u(rng) * (kNz - 2);
        const Vec3 w{1 - 0.1f * j, 2 + 0.1f * i, 3 + 0.1f * k};
        ASSERT_NEAR(grid_lookup(s.grids[0], s.grid_voxels, w), field(i, j, k), 2e-4)
            << i << " " << j << " " << k;
    }
    // the cleaned voxels: NaN and negative 0, enormous 1e9; the majorant from the largest
    EXPECT_EQ(s.grid_voxels[0], 0.0f);
    EXPECT_EQ(s.grid_voxels[1], 0.0f);
    EXPECT_EQ(s.grid_voxels[2], 1e9f);
    EXPECT_EQ(s.grids[0].max_value, 1e9f);
    int said = 0;
    for (const std::string& w : scene.warnings())
        said += (w.find("NaN") != std::string::npos) + (w.find("1e9") != std::string::npos);
    EXPECT_EQ(said, 2);
    const Medium& md = s.media[s.material_medium[0]];
    EXPECT_EQ(md.density_grid, 0);
    EXPECT_EQ(md.density_prog, -1);
    EXPECT_FLOAT_EQ(md.majorant, 1e9f);
}

TEST(VdbFile, WrittenGridReadsBackWithItsBlockAndTransform) {
    if (!vdb_available()) GTEST_SKIP() << "built without OpenVDB";
    const std::string path = tmp_path("roundtrip.vdb");
    // a block with zero borders: the active voxels start at index (1, 1, 1)
    const int32_t dims[3] = {kNx + 2, kNy + 2, kNz + 2};
    std::vector<float> v(size_t(dims[0]) * dims[1] * dims[2], 0.0f);
    for (int k = 0; k < kNz; ++k)
        for (int j = 0; j < kNy; ++j)
            for (int i = 0; i < kNx; ++i)
                v[(size_t(k + 1) * dims[1] + (j + 1)) * dims[0] + (i + 1)] = float(field(i, j, k));
    const double m[4][4] = {{0.2, 0, 0, -1}, {0, 0.2, 0, 0.5}, {0, 0, 0.2, 2}, {0, 0, 0, 1}};
    vdb_write_dense(path, "density", v.data(), dims, m);
    const std::vector<VdbGridMeta> meta = vdb_grids(path);
    ASSERT_EQ(meta.size(), 1u);
    EXPECT_EQ(meta[0].name, "density");
    EXPECT_EQ(meta[0].type, "float");
    ASSERT_TRUE(meta[0].has_bbox);
    EXPECT_EQ(meta[0].bbox_min[0], 1);
    EXPECT_EQ(meta[0].bbox_max[2], kNz);
    EXPECT_EQ(meta[0].dense_voxels(), uint64_t(kNx) * kNy * kNz);
    const VdbDense d = vdb_read_dense(path, "density", 1u << 20);
    ASSERT_EQ(d.dims[0], kNx);
    ASSERT_EQ(d.dims[1], kNy);
    ASSERT_EQ(d.dims[2], kNz);
    EXPECT_EQ(d.origin[0], 1);
    EXPECT_EQ(d.origin[2], 1);
    const std::vector<float> want = field_voxels();
    // field(0, 0, 0) is 0.5: every voxel of the block is active and read back
    for (size_t n = 0; n < want.size(); ++n) ASSERT_FLOAT_EQ(d.voxels[n], want[n]) << n;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(d.index_to_object[r][c], m[r][c], 1e-12);
    std::remove(path.c_str());
}

TEST(VdbFile, BadInputSaysWhat) {
    if (!vdb_available()) GTEST_SKIP() << "built without OpenVDB";
    auto message = [](auto f) {
        try {
            f();
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    EXPECT_NE(message([] { vdb_read_dense("/nonexistent/smoke.vdb", "density", 1000); })
                  .find("cannot be read"), std::string::npos);
    const std::string junk = tmp_path("junk.vdb");
    std::ofstream(junk) << "not a vdb file";
    EXPECT_NE(message([&] { vdb_grids(junk); }).find("cannot be read"), std::string::npos);
    std::remove(junk.c_str());
    const std::string path = tmp_path("bad.vdb");
    const int32_t dims[3] = {4, 4, 4};
    std::vector<float> v(64, 1.0f);
    const double m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    vdb_write_dense(path, "density", v.data(), dims, m);
    const std::string none = message([&] { vdb_read_dense(path, "flame", 1000); });
    EXPECT_NE(none.find("no grid named 'flame'"), std::string::npos) << none;
    EXPECT_NE(none.find("'density'"), std::string::npos) << none;
    // too large for the limit: refused from the metadata
    const std::string big = message([&] { vdb_read_dense(path, "density", 63); });
    EXPECT_NE(big.find("above the limit of 63"), std::string::npos) << big;
    EXPECT_EQ(vdb_read_dense(path, "density", 64).voxels.size(), 64u);  // control: at the limit
    // two voxels 2^20 apart: 2^60 voxels as a dense block, refused from the metadata alone
    const int32_t far[6] = {0, 0, 0, 1 << 20, 1 << 20, 1 << 20};
    const float two[2] = {1.0f, 2.0f};
    vdb_write_sparse(path, "density", far, two, 2, m);
    const std::vector<VdbGridMeta> meta = vdb_grids(path);
    ASSERT_EQ(meta.size(), 1u);
    EXPECT_EQ(meta[0].active_voxels, 2u);
    EXPECT_EQ(meta[0].dense_voxels(), uint64_t(1 << 20 | 1) * uint64_t(1 << 20 | 1) *
                                          uint64_t(1 << 20 | 1));
    const std::string huge = message([&] { vdb_read_dense(path, "density", kMaxGridVoxels); });
    EXPECT_NE(huge.find("above the limit"), std::string::npos) << huge;
    // an empty grid (every voxel the background): no block
    std::vector<float> zeros(64, 0.0f);
    vdb_write_dense(path, "density", zeros.data(), dims, m);
    const VdbDense e = vdb_read_dense(path, "density", 1000);
    EXPECT_EQ(e.dims[0], 0);
    EXPECT_TRUE(e.voxels.empty());
    std::remove(path.c_str());
}

TEST(MediumGridPt, AbsorbingGridOfARampIsBeerLambert) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    // a grid over the box x, y in -1..1, z -3..-2 (voxel size 0.1, centres on the faces) whose
    // density is 2 + (-2 - z) along z: from 2 at z = -2 to 3 at z = -3; a camera at the origin
    // looking down -Z through it at a white world
    SceneInput in;
    in.width = in.height = 8;
    in.orthographic = true;
    in.screen[0] = -0.1f; in.screen[1] = 0.1f; in.screen[2] = -0.1f; in.screen[3] = 0.1f;
    in.clip_start = 0.0f;
    in.world_color = vec3(1.0f);
    GridInput gi;
    gi.name = "density";
    gi.dims[0] = gi.dims[1] = 21;
    gi.dims[2] = 11;
    const float m[16] = {0.1f, 0, 0, -1, 0, 0.1f, 0, -1, 0, 0, 0.1f, -3, 0, 0, 0, 1};
    std::copy(m, m + 16, gi.index_to_world);
    for (int k = 0; k < 11; ++k)
        for (int j = 0; j < 21; ++j)
            for (int i = 0; i < 21; ++i) gi.voxels.push_back(3.0f - 0.1f * float(k));
    in.grids.push_back(gi);
    MediumInput med;
    med.name = "ramp";
    med.sigma_a = vec3(0.2f, 0.5f, 1.0f);
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "ramp";
    mat.medium = 0;
    mat.volume_only = true;
    mat.density_grid = 0;
    in.materials.push_back(mat);
    in.meshes.push_back(box_mesh({-0.95f, -0.95f, -2.999f}, {0.95f, 0.95f, -2.001f}, 0));
    const int k_seeds = 8;
    double sum[3] = {}, sum2[3] = {};
    for (int k = 0; k < k_seeds; ++k) {
        SessionSettings st;
        st.integrator = "pt";
        st.spp_per_iteration = 1024;
        st.max_depth = 1;
        st.seed = uint64_t(5 + k);
        st.threads = 1;
        Session s(in, st);
        ASSERT_TRUE(s.step());
        const std::vector<float> img = s.image();
        double c[3] = {};
        for (size_t n = 0; n < img.size(); ++n) c[n % 3] += img[n];
        for (int ch = 0; ch < 3; ++ch) {
            const double g = c[ch] / double(img.size() / 3);
            sum[ch] += g;
            sum2[ch] += g * g;
        }
    }
    // the density is -z: its integral over the chord z -2.999..-2.001
    const double a = -2.999, b = -2.001;
    const double integral = (b - a) * (-(a + b) * 0.5);
    const double s[3] = {0.2, 0.5, 1.0};
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / k_seeds;
        const double se = std::sqrt(std::max(sum2[c] / k_seeds - mean * mean, 0.0) /
                                    (k_seeds - 1)) + 1e-6 * mean;
        const double want = std::exp(-s[c] * integral);
        std::printf("grid ramp channel %d: %.6f want %.6f se %.2g\n", c, mean, want, se);
        EXPECT_LT(std::fabs(mean - want), 5.0 * se) << "channel " << c;
        EXPECT_GT(std::fabs(mean - std::exp(-s[c] * integral * 1.02)), 5.0 * se) << "channel " << c;
    }
}

TEST(MediumGridScene, MovingAVolumeObjectsBoxAsksForANewScene) {
    // move_mesh would move the box but not the grid's world-to-index map: it must refuse (the
    // add-on then exports again); a plain mesh beside it still moves (control)
    SceneInput in;
    GridInput gi;
    gi.name = "density";
    gi.dims[0] = gi.dims[1] = gi.dims[2] = 2;
    gi.voxels.assign(8, 1.0f);
    in.grids.push_back(gi);
    MediumInput med;
    med.name = "smoke";
    med.sigma_s = vec3(1.0f);
    in.media.push_back(med);
    MaterialInput smoke;
    smoke.name = "smoke";
    smoke.medium = 0;
    smoke.volume_only = true;
    smoke.density_grid = 0;
    MaterialInput wall;
    wall.name = "wall";
    in.materials = {smoke, wall};
    in.meshes.push_back(box_mesh({-1, -1, -1}, {2, 2, 2}, 0));
    in.meshes.push_back(box_mesh({3, 3, 3}, {4, 4, 4}, 1));
    HostScene scene(in);
    const Transform shift{{{1, 0, 0, -0.1f}, {0, 1, 0, 0}, {0, 0, 1, 0}}};  // inwards
    EXPECT_FALSE(scene.move_mesh(0, shift));
    EXPECT_TRUE(scene.move_mesh(1, shift));
}

TEST(MediumGridScene, LightTracingKeepsAGridMedium) {
    // lt tracks heterogeneous media (lt_medium.h, hetmedia): a grid density renders with lt,
    // without the hand-over; the same grid medium glowing goes to pt and says so (control: lt
    // has no camera gather for emissive media)
    SceneInput in;
    GridInput gi;
    gi.name = "density";
    gi.dims[0] = gi.dims[1] = gi.dims[2] = 2;
    gi.voxels.assign(8, 1.0f);
    in.grids.push_back(gi);
    MediumInput med;
    med.name = "smoke";
    med.sigma_s = vec3(1.0f);
    in.media.push_back(med);
    MaterialInput smoke;
    smoke.name = "smoke";
    smoke.medium = 0;
    smoke.volume_only = true;
    smoke.density_grid = 0;
    in.materials = {smoke};
    in.meshes.push_back(box_mesh({-1, -1, -3}, {2, 2, -2}, 0));
    SessionSettings st;
    st.integrator = "lt";
    st.spp_per_iteration = 1;
    st.max_depth = 2;
    st.threads = 1;
    auto handed = [&](const SceneInput& scene) {
        Session s(scene, st);
        for (const std::string& w : s.warnings())
            if (w.find("rendering with pt") != std::string::npos) return true;
        return false;
    };
    EXPECT_FALSE(handed(in));
    in.media[0].emission = vec3(0.5f);
    EXPECT_TRUE(handed(in));
}
