// Host side of the two-level BVH (accel/tlas.h): one bottom level per mesh, built once over the
// mesh's triangles as the scene holds them (the exported world positions), and a top level
// over the instances, rebuilt (a median split over a few boxes: microseconds) when one moves.
// An instance's transform maps its exported positions to where they are now (identity at build).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "accel/bvh_builder.h"
#include "accel/tlas.h"

namespace lantern {

// Where one mesh (one SceneInput::meshes entry) lies in the scene's arrays.
struct MeshRange {
    int32_t tri_begin = 0, tri_count = 0;
    int32_t vert_begin = 0, vert_count = 0;
};

struct Tlas {
    std::vector<Bvh> blas;               // one per mesh, scene triangle ids in BvhTri::prim
    std::vector<BvhView> blas_views;
    std::vector<Vec3> blas_box;          // object-space bounds, lo and hi per mesh
    std::vector<Transform> to_world;     // per instance
    std::vector<BvhInstance> instances;  // per instance (instance k places blas k)
    std::vector<BvhNode> nodes;          // the top level
    std::vector<int32_t> leaf_inst;
    int64_t blas_builds = 0, tlas_builds = 0;  // counted: a move must not build a bottom level
    MotionView motion;                   // the scene's (motion blur): moving instances
    TlasView view() const {
        return {nodes.data(), int32_t(nodes.size()), leaf_inst.data(), instances.data(),
                blas_views.data(), motion};
    }
};

// One bottom level whose traversal needs at most max_stack entries (depth - 1; tlas.h's
// kBlasStackSize, above the top level's on one stack): SAH, or where that is deeper (seldom)
// built again with object medians from depth max_stack - 32; a std::length_error naming the
// depth when still deeper.
Bvh build_blas(const SceneView& s, int threads, int max_stack, std::vector<std::string>& warnings);
// Bottom levels of every mesh (identity instances) and the top level; `warnings` receives
// what was left out, worded as build_bvh words it.
void build_tlas_scene(Tlas& tl, const SceneView& s, const std::vector<MeshRange>& meshes,
                      int threads, std::vector<std::string>& warnings);
// The top level over the instances as they are now.
void build_tlas(Tlas& tl);
// Instance k placed by to_world (relative to its exported positions); false, nothing changed,
// for a non-finite or singular transform or k out of range. Call build_tlas() after.
bool set_instance_transform(Tlas& tl, int k, const Transform& to_world);
// The inverse of an affine transform in double; false when it is singular or not finite.
bool invert_affine(const Transform& m, Transform* inv);
// World bounds of instance k (lo, hi) over the shutter where it moves; empty (lo > hi) for an
// empty mesh.
void instance_world_box(const Tlas& tl, int k, Vec3 box[2]);
// The box (lo, hi) under m, padded by a few ulps unless m is the identity; empty stays empty.
void transformed_box(const Vec3 box[2], const Transform& m, Vec3 out[2]);
// Bounds (lo, hi) of each mesh's vertices as the scene holds them.
void mesh_boxes(const SceneView& s, const std::vector<MeshRange>& meshes, std::vector<Vec3>& out);

}  // namespace lantern
