// Ray queries on the CPU through Lantern's own BVH (accel/bvh.h): the same traversal code the
// CUDA backend runs, here as plain C++. Same contract as EmbreeAccel: closest hit per ray kind
// (camera rays see only camera-visible triangles, shadow rays only shadow casters), the
// stochastic alpha test of scene/alpha.h, the same triangles left out with the same warnings,
// the same move of rays that start beyond kMaxCoordinate (EmbreeAccel::prepare()).
#pragma once

#include <string>
#include <vector>

#include "accel/bvh_builder.h"
#include "backend/cpu/embree_accel.h"

namespace lantern {

class BvhAccel {
public:
    // `s` must outlive the accel (the alpha test reads the scene's materials and textures).
    BvhAccel(const SceneView& s, int threads, std::vector<std::string>& warnings);

    HitRecord intersect(const Ray& r, RayKind kind) const;
    bool occluded(const Ray& r) const;
    const BvhStats& stats() const { return bvh_.stats; }

private:
    bool guard(const Ray& r, Ray* out, float* shift) const;

    SceneView s_;
    Vec3 box_[2];  // far_ray_bounds(): rays from beyond kMaxCoordinate start where they enter it
    Bvh bvh_;
    BvhView view_;
    bool any_alpha_ = false;
};

}  // namespace lantern
