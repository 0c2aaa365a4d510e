// OpenVDB files (docs/volumes.md): a file's grids from its metadata alone, one float grid read
// into a dense block (what scene/medium_grid.h samples), and a small writer (tests, tools).
// Built with OpenVDB when CMake finds it (LANTERN_HAVE_OPENVDB); without it every function but
// vdb_available() throws std::runtime_error("... built without OpenVDB ...").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lantern {

bool vdb_available();

// A grid of a file as its metadata describes it, before any voxel is read.
struct VdbGridMeta {
    std::string name, type;   // type: OpenVDB's ("float", "vec3s", ...)
    bool has_bbox = false;    // the file recorded the active voxels' bounds
    int32_t bbox_min[3] = {0, 0, 0}, bbox_max[3] = {-1, -1, -1};  // inclusive, index space
    uint64_t active_voxels = 0;
    uint64_t dense_voxels() const;  // voxels of the bounds' dense block (0 when empty)
};
std::vector<VdbGridMeta> vdb_grids(const std::string& path);

// A float or vec3 grid's voxels over its active bounds, x fastest: voxel (i, j, k) of the block
// is the grid's (origin + (i, j, k)); a vec3 grid (channels 3: Vec3S, Vec3D read as floats)
// holds 3 floats per voxel. index_to_object (4x4, rows, column vectors) maps the grid's index
// space (voxel centres at integers) to object space.
struct VdbDense {
    std::string name;
    int32_t dims[3] = {0, 0, 0};
    int32_t origin[3] = {0, 0, 0};
    int32_t channels = 1;
    double index_to_object[4][4] = {};
    float background = 0.0f;  // a vec3 grid's: the largest magnitude of its background's parts
    std::vector<float> voxels;
};
// Throws std::runtime_error naming the file and grid: no such file, not a VDB file, no grid of
// that name (the float and vec3 grids it has are listed), neither a float nor a vec3 grid, a
// transform that is not affine, or more than max_voxels floats in the dense block (3 per voxel
// of a vec3 grid; checked from the metadata before the voxels are read). An empty grid gives
// dims 0.
VdbDense vdb_read_dense(const std::string& path, const std::string& grid, uint64_t max_voxels);

// Writes a float grid named `name` of dims voxels (x fastest) at index origin (0,0,0), the
// voxels that differ from 0 active, with the affine index_to_object (rows, column vectors).
void vdb_write_dense(const std::string& path, const std::string& name, const float* voxels,
                     const int32_t dims[3], const double index_to_object[4][4]);
// Writes several float grids of the same dims and transform into one file (a fire: density,
// temperature, flame), each as vdb_write_dense does.
void vdb_write_dense_grids(const std::string& path, const std::vector<std::string>& names,
                           const std::vector<const float*>& voxels, const int32_t dims[3],
                           const double index_to_object[4][4]);
// One grid for vdb_write_list: dims voxels (x fastest) of `channels` floats each (1: a float
// grid, 3: a vec3 grid, Vec3D when as_double), the voxels that differ from 0 active.
struct VdbWriteGrid {
    std::string name;
    const float* voxels = nullptr;
    int32_t dims[3] = {0, 0, 0};
    int32_t channels = 1;
    bool as_double = false;
    double index_to_object[4][4] = {};
};
// Writes the grids into one file (tests: a smoke's density and colour, transforms of their own).
void vdb_write_list(const std::string& path, const std::vector<VdbWriteGrid>& grids);
// Writes a sparse float grid: voxel coords[3 k .. 3 k + 2] (index space) active with value
// values[k], k < n (tests: a grid of two voxels far apart spans billions as a dense block).
void vdb_write_sparse(const std::string& path, const std::string& name, const int32_t* coords,
                      const float* values, size_t n, const double index_to_object[4][4]);

}  // namespace lantern
