// Ray queries on the CPU through Lantern's own BVH (accel/bvh.h): the same traversal code the
// CUDA backend runs, here as plain C++. Same contract as EmbreeAccel: closest hit per ray kind
// (camera rays see only camera-visible triangles, shadow rays only shadow casters), the
// stochastic alpha test of scene/alpha.h, the same triangles left out with the same warnings,
// the same move of rays that start beyond kMaxCoordinate (EmbreeAccel::prepare()).
#pragma once

#include <string>
#include <vector>

#include "accel/boundary_hits.h"
#include "accel/bvh_builder.h"
#include "accel/tlas_build.h"
#include "backend/cpu/embree_accel.h"

namespace lantern {

class BvhAccel {
public:
    // `s` must outlive the accel (the alpha test reads the scene's materials and textures).
    // `meshes`: two levels, one bottom-level BVH per mesh (accel/tlas_build.h), so that
    // move() can place a mesh again; null: one BVH over every triangle.
    BvhAccel(const SceneView& s, int threads, std::vector<std::string>& warnings,
             const std::vector<MeshRange>* meshes = nullptr);

    HitRecord intersect(const Ray& r, RayKind kind) const;
    bool occluded(const Ray& r) const;
    // A shadow ray through media in one query (accel/boundary_hits.h): whether a caster but a
    // volume boundary blocks r; if not, the boundaries on it in *out. out->n -1 (two levels,
    // or too many): no answer.
    bool occluded_collect(const Ray& r, BoundaryHits* out) const;
    const BvhStats& stats() const { return bvh_.stats; }
    // Two levels only: mesh k placed by to_world (relative to its exported positions), the top
    // level rebuilt; false, nothing changed, without two levels or for a singular transform.
    bool move(int k, const Transform& to_world);
    bool two_level() const { return two_level_; }
    int64_t bottom_builds() const { return two_level_ ? tl_.blas_builds : 1; }

private:
    bool guard(const Ray& r, Ray* out, float* shift) const;

    SceneView s_;
    Vec3 box_[2];  // far_ray_bounds(): rays from beyond kMaxCoordinate start where they enter it
    Bvh bvh_;
    BvhView view_;
    bool any_alpha_ = false;
    bool two_level_ = false;
    Tlas tl_;
    TlasView tl_view_;
};

}  // namespace lantern
