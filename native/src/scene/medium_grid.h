// Density grids of Volume objects (docs/volumes.md): an OpenVDB float grid copied at load into
// a dense block of voxels (scene/vdb_io.cpp), read here by trilinear interpolation between voxel
// centres (Cycles' default Linear interpolation; a voxel's centre is its integer index, as in
// OpenVDB). Outside the block the grid reads 0 (its background, cleaned to 0). A colour grid
// (a vec3 grid: Principled Volume's Color Attribute) holds 3 floats per voxel, read the same
// way (grid_color). Host+device.
#pragma once

#include <cstdint>

#include "core/math.h"

namespace lantern {

// The most voxels a scene's grids may hold together (1 GiB of floats); a larger grid is refused
// before it is read (scene/vdb_io.cpp: from the file's metadata).
constexpr uint64_t kMaxGridVoxels = uint64_t(1) << 28;

// A grid as stages see it (SceneView::grids): voxel (i, j, k) of the block is
// grid_voxels[offset + (k * ny + j) * nx + i] (a colour grid's: channels floats from
// offset + 3 ((k * ny + j) * nx + i)); world_to_index maps a world position to the block's index
// space (voxel centres at integers).
struct DensityGrid {
    Transform world_to_index;
    int32_t nx, ny, nz;
    int32_t channels;  // 1 (float grids) or 3 (colour grids)
    uint64_t offset;
    float max_value;  // the largest voxel (of any channel): a bound on every trilinear value
    float pad2;
};

LANTERN_HD inline float grid_voxel(const DensityGrid& g, const float* v, int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= g.nx || j >= g.ny || k >= g.nz) return 0.0f;
    return v[g.offset + (uint64_t(k) * uint64_t(g.ny) + uint64_t(j)) * uint64_t(g.nx) +
             uint64_t(i)];
}

// The grid's value at index-space point q (trilinear between the 8 voxel centres around it).
LANTERN_HD inline float grid_lookup_index(const DensityGrid& g, const float* v, Vec3 q) {
    // far outside (and NaN): 0, before the float -> int conversion could overflow
    if (!(q.x > -1.0f && q.y > -1.0f && q.z > -1.0f && q.x < float(g.nx) &&
          q.y < float(g.ny) && q.z < float(g.nz)))
        return 0.0f;
    const float fx = floorf(q.x), fy = floorf(q.y), fz = floorf(q.z);
    const int i = int(fx), j = int(fy), k = int(fz);
    const float tx = q.x - fx, ty = q.y - fy, tz = q.z - fz;
    float r = 0.0f;
    for (int c = 0; c < 8; ++c) {
        const int di = c & 1, dj = (c >> 1) & 1, dk = c >> 2;
        const float w = (di ? tx : 1.0f - tx) * (dj ? ty : 1.0f - ty) * (dk ? tz : 1.0f - tz);
        if (w > 0.0f) r += w * grid_voxel(g, v, i + di, j + dj, k + dk);
    }
    return r;
}

LANTERN_HD inline float grid_lookup(const DensityGrid& g, const float* v, Vec3 p_world) {
    return grid_lookup_index(g, v, g.world_to_index.point(p_world));
}

// A colour grid (channels 3) at world point p, as Principled Volume's Color Attribute scales the
// medium (scene/medium_hetero.h): `color` the trilinear colour c, `absorb` the trilinear value
// of max(1 - base c, 0) per channel (the absorption's factor, base the Color socket's value).
// Both are what Cycles' stochastic lookup (one voxel drawn with the trilinear weights, for each
// attribute on its own) gives on average; the voxels are >= 0 (cleaned at load). Outside the
// block the colour reads 0, so absorb reads 1.
struct GridColor {
    Vec3 color, absorb;
};
LANTERN_HD inline GridColor grid_color(const DensityGrid& g, const float* v, Vec3 base,
                                       Vec3 p_world) {
    GridColor r{vec3(0.0f), vec3(1.0f)};
    const Vec3 q = g.world_to_index.point(p_world);
    if (!(q.x > -1.0f && q.y > -1.0f && q.z > -1.0f && q.x < float(g.nx) &&
          q.y < float(g.ny) && q.z < float(g.nz)))
        return r;
    const float fx = floorf(q.x), fy = floorf(q.y), fz = floorf(q.z);
    const int i = int(fx), j = int(fy), k = int(fz);
    const float tx = q.x - fx, ty = q.y - fy, tz = q.z - fz;
    r.absorb = vec3(0.0f);
    for (int c = 0; c < 8; ++c) {
        const int di = c & 1, dj = (c >> 1) & 1, dk = c >> 2;
        const float w = (di ? tx : 1.0f - tx) * (dj ? ty : 1.0f - ty) * (dk ? tz : 1.0f - tz);
        const int a = i + di, b = j + dj, e = k + dk;
        Vec3 col = vec3(0.0f);
        if (a >= 0 && b >= 0 && e >= 0 && a < g.nx && b < g.ny && e < g.nz) {
            const float* x = v + g.offset +
                             3u * ((uint64_t(e) * uint64_t(g.ny) + uint64_t(b)) * uint64_t(g.nx) +
                                   uint64_t(a));
            col = Vec3{x[0], x[1], x[2]};
        }
        r.color = r.color + col * w;
        const Vec3 ab = vec3(1.0f) - base * col;
        r.absorb = r.absorb + Vec3{fmaxf(ab.x, 0.0f), fmaxf(ab.y, 0.0f), fmaxf(ab.z, 0.0f)} * w;
    }
    return r;
}

}  // namespace lantern
