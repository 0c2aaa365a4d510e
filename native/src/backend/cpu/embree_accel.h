// Ray queries on the CPU through Embree 3 (loaded privately, see embree_loader.h). Triangles
// with non-finite vertices or zero area are left out of the build and counted in warnings; rays
// Embree would assert on are moved into its range or refused first (prepare()).
// When some objects are hidden from camera rays or cast no shadow, separate acceleration
// structures serve those ray kinds; scenes that do not use the flags build only one.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "scene/scene_view.h"

namespace lantern {

enum class RayKind { kCamera, kIndirect, kShadow };

struct HitRecord {
    float t;
    int32_t prim;   // triangle index in the scene, -1 for a miss
    Vec2 uv;
};

// Bounds of the triangles the accelerators hold (finite, not degenerate), padded: where
// EmbreeAccel::prepare() moves rays that start beyond kMaxCoordinate. Empty (lo > hi) if none.
void far_ray_bounds(const SceneView& s, Vec3 box[2]);

class EmbreeAccel {
public:
    // Builds from the scene's triangles; `warnings` receives what was skipped and why.
    EmbreeAccel(const SceneView& s, std::vector<std::string>& warnings);
    ~EmbreeAccel();
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    HitRecord intersect(const Ray& r, RayKind kind) const;
    bool occluded(const Ray& r) const;
    // The ray as Embree can take it (origin o, range [tnear, tfar], hit distances then + shift),
    // or false when there is nothing to trace (embree_accel.cpp, "Rays Embree can take").
    static bool prepare(const Ray& r, const Vec3 box[2], float o[3], float* tnear, float* tfar,
                        float* shift);
    // What the alpha filter of a Built's alpha-tested geometry reads (scene/alpha.h).
    struct AlphaFilter {
        SceneView s;
        const int32_t* prim_to_tri = nullptr;  // that geometry's primID -> scene triangle
    };


private:
    struct Built {
        void* scene = nullptr;               // RTCScene
        // Embree primID -> scene triangle: the opaque geometry's first, then the alpha-tested
        // one's (a separate geometry, so that only its hits run the alpha filter)
        std::vector<int32_t> prim_to_tri;
        uint32_t alpha_geom = ~0u;           // geomID of the alpha-tested geometry
        size_t alpha_base = 0;               // its first entry in prim_to_tri
        std::unique_ptr<AlphaFilter> filter;
        int32_t tri(uint32_t geom, uint32_t prim) const {
            return prim_to_tri[(geom == alpha_geom ? alpha_base : 0) + prim];
        }
    };
    Built build(const SceneView& s, uint8_t need_flag);
    const Built& for_kind(RayKind kind) const;

    Vec3 box_[2];  // far_ray_bounds()
    void* device_ = nullptr;                 // RTCDevice
    Built all_, camera_, shadow_;
    bool has_camera_ = false, has_shadow_ = false;
};

}  // namespace lantern
