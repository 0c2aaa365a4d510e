// Host-side builder of the BVH in accel/bvh.h: binned SAH over the scene's usable triangles
// (the ones EmbreeAccel keeps: finite vertices, non-zero area), multithreaded, deterministic:
// the same scene gives the same nodes and triangle order whatever the thread count.
#pragma once

#include <string>
#include <vector>

#include "accel/bvh.h"

namespace lantern {

struct BvhBuildOptions {
    int bins = 32;           // SAH bins per axis (clamped to [4, 64])
    int max_leaf = 8;        // a leaf never holds more triangles than this
    float node_cost = 1.0f;  // SAH cost of visiting a node, in ray-triangle tests
    int threads = 0;         // 0: hardware concurrency
    int sah_depth = 32;      // deeper nodes split at the object median (clamped to [0, 32]), so
                             // depth <= sah_depth + log2(triangles) < kBvhStackSize
};

struct BvhStats {
    int32_t triangles = 0;           // in the BVH
    int32_t skipped_nonfinite = 0;   // left out: a vertex is NaN or infinite
    int32_t skipped_degenerate = 0;  // left out: zero area
    int32_t nodes = 0, leaves = 0;
    int32_t max_depth = 0;  // inner-node levels on the longest path
    int32_t max_leaf_size = 0;
    double sah_cost = 0.0;  // expected tests per ray, relative to the root box
    double build_ms = 0.0;
};

// Owns the host arrays; view() points at them. The CUDA backend copies nodes and tris to the
// device as they are and builds a BvhView over the device pointers.
struct Bvh {
    std::vector<BvhNode> nodes;
    std::vector<BvhTri> tris;
    BvhStats stats;
    BvhView view() const {
        return {nodes.data(), tris.data(), int32_t(nodes.size()), int32_t(tris.size())};
    }
};

// Builds over s.positions / s.indices / s.tri_flags (null flags: visible to all rays);
// `warnings` receives what was left out and why, worded as EmbreeAccel words it.
Bvh build_bvh(const SceneView& s, const BvhBuildOptions& options,
              std::vector<std::string>& warnings);

}  // namespace lantern
