// Ray queries on the CPU through Embree 3 (loaded privately, see embree_loader.h). Triangles
// with non-finite vertices or zero area are left out of the build and counted in warnings.
// When some objects are hidden from camera rays or cast no shadow, separate acceleration
// structures serve those ray kinds; scenes that do not use the flags build only one.
#pragma once

#include <cstdint>
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

class EmbreeAccel {
public:
    // Builds from the scene's triangles; `warnings` receives what was skipped and why.
    EmbreeAccel(const SceneView& s, std::vector<std::string>& warnings);
    ~EmbreeAccel();
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    HitRecord intersect(const Ray& r, RayKind kind) const;
    bool occluded(const Ray& r) const;

private:
    struct Built {
        void* scene = nullptr;               // RTCScene
        std::vector<int32_t> prim_to_tri;    // Embree primID -> scene triangle
    };
    Built build(const SceneView& s, uint8_t need_flag);
    const Built& for_kind(RayKind kind) const;

    void* device_ = nullptr;                 // RTCDevice
    Built all_, camera_, shadow_;
    bool has_camera_ = false, has_shadow_ = false;
};

}  // namespace lantern
