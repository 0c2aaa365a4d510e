// Bounds of a node program over a box of points (host only; docs/volumes.md "Node graphs on
// volume inputs"): interval arithmetic through the program's instructions, from the ranges of
// what it reads over the box (the position, the medium's affine attribute maps, the Volume
// object grids' voxels that a trilinear lookup inside the box can read) to its result. Each op
// with a rule gives an interval that holds every value the op can give for inputs in its
// input intervals, so the result's interval holds every value the program gives at a point of
// the box: a true bound, which the majorant bricks of a density program need (the trackings
// are exact only where the majorant bounds the extinction). An op without a rule (docs/volumes.md
// lists the ops that have one) makes the result unbounded; the
// caller then falls back (and says so).
#pragma once

#include <string>
#include <vector>

#include "scene/material_program.h"

namespace lantern {

struct Interval {
    float lo, hi;
};

// One image texture's texel ranges per block of block x block texels (each channel, in the
// values its lookup blends: an 8-bit texture's bytes / 255), for the Image Texture's rule
// (scene/program_bound_image.cpp); block 0: not scanned yet.
struct TexelBlocks {
    int block = 0, bw = 0, bh = 0;  // the block's size in texels; blocks per row, per column
    std::vector<float> lo, hi;      // 4 per block, rows of blocks bottom to top
    float all_lo[4] = {}, all_hi[4] = {};  // the whole image's
    bool finite = true;
};

// What a series of bounds over one scene can share: the image textures' block ranges (by
// SceneView::textures index), scanned the first time a bound reads the texture. A caller
// bounding one program over many boxes passes one cache to every call.
struct ProgramBoundCache {
    std::vector<TexelBlocks> textures;
};

// While one lives, program_bound calls on its thread without a cache of their own share its
// cache: a medium's build (HostScene::build_hetero, build_grid_medium) opens one, so the
// bounds over its sub-boxes and bricks, through whichever helper, scan each texture once.
// Scopes nest (the inner one is used); a scope outlives none of the scene's textures.
class ProgramBoundScope {
public:
    ProgramBoundScope();
    ~ProgramBoundScope();
    ProgramBoundScope(const ProgramBoundScope&) = delete;
    ProgramBoundScope& operator=(const ProgramBoundScope&) = delete;
    ProgramBoundCache cache;

private:
    ProgramBoundCache* outer_;
};

// The interval of each channel of program p's result over the points of the world box
// [lo, hi] inside heterogeneous medium med (its attribute maps, SceneView::medium_maps; -1:
// none). False when some op on the way has no rule, or a bound is not finite; out is then
// (-inf, inf). The result is what program_run returns (NaN and infinities are 0 there: a
// finite bound holds them), widened by a relative 1e-5 against float rounding in the lookups.
// channels: how many of the result's channels the caller reads (a density reads x alone, and
// a scalar program leaves y, z unwritten); the others are (-inf, inf) and do not fail it.
// cache: shared by calls over one scene (null: the innermost ProgramBoundScope's on this
// thread, else a cache of this call alone).
bool program_bound(const SceneView& s, const MaterialProgram& p, int32_t med, Vec3 lo, Vec3 hi,
                   Interval out[3], int channels = 3, ProgramBoundCache* cache = nullptr);

// The warning of a medium whose density program has no interval bound (its majorant falls
// back to the largest density on a lattice x 1.5): one text for mesh volumes and Volume objects.
std::string unbounded_density_warning(const std::string& medium);

// The range of grid g's trilinear lookups over the world box [lo, hi] (each channel; a float
// grid's in all three): the smallest and largest voxel a lookup inside the box can read, one
// voxel of margin each way, 0 where a lookup can reach outside the block.
void grid_range(const SceneView& s, const DensityGrid& g, Vec3 lo, Vec3 hi, Interval out[3]);

}  // namespace lantern
