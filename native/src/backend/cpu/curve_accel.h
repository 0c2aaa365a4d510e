// Ray queries against the scene's strands (scene/curves.h) beside the triangles' structure:
// Embree's ROUND_LINEAR_CURVE geometry (backend/cpu/embree_curves.h) where the triangles use
// Embree, else the built-in curve BVH (accel/curve_bvh.h). CpuBackend asks it after the
// triangles with the ray cut at their hit, so the nearer wins; hits are entries only (a ray
// leaving a strand does not see it: Embree's back-facing hits are filtered out). Camera rays
// skip strands hidden from the camera, shadow rays those that cast no shadow.
// A strand set moving with its object (motion blur, scene/curves.h's CurveSetMotion) has its own
// structure in its exported frame, entered through its matrix at the ray's time: the built-in
// BVH's own curve BVH behind a box over the shutter (16 times per step interval, as the mesh
// top level pads its instances; the host+device query of accel/curve_query.h, the one the CUDA
// backend runs), or an Embree instance with the object's quaternion steps over
// a child scene holding the set in object space (as backend/cpu/embree_instances.cpp's meshes).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "accel/curve_query_build.h"
#include "backend/cpu/embree_accel.h"

namespace lantern {

class CurveAccel {
public:
    // use_embree: Embree's geometry (throws std::runtime_error when Embree fails), else the BVH
    CurveAccel(const SceneView& s, bool use_embree, std::vector<std::string>& warnings);
    ~CurveAccel();
    CurveAccel(const CurveAccel&) = delete;
    CurveAccel& operator=(const CurveAccel&) = delete;

    // *h replaced by the nearest strand hit closer than h->t (a miss: h->prim < 0, t = tmax)
    void closer(const Ray& r, RayKind kind, HitRecord* h) const;
    bool occluded(const Ray& r) const;
    const char* name() const { return embree_ ? "embree" : "bvh"; }

private:
    struct Embree;
    int kind_index(RayKind kind) const;
    int steps_ = 0;  // moving strands' steps (motion blur), else 0
    CurveQuery q_;   // the segments per kind (both paths); the BVHs (built-in path only)
    CurveQueryView view_;
    std::unique_ptr<Embree> embree_;
};

}  // namespace lantern
