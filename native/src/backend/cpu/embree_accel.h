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

#include "accel/boundary_hits.h"
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
// box grown to hold b (a moved instance's world bounds), padded as far_ray_bounds pads.
void grow_far_ray_bounds(Vec3 box[2], const Vec3 b[2]);

struct MeshRange;  // accel/tlas_build.h

class EmbreeAccel {
public:
    // Builds from the scene's triangles; `warnings` receives what was skipped and why.
    // `meshes`: two levels (embree_instances.cpp), a child scene per mesh under instances,
    // so that move() places a mesh again without building it; null: one flat scene per kind.
    EmbreeAccel(const SceneView& s, std::vector<std::string>& warnings,
                const std::vector<MeshRange>* meshes = nullptr);
    ~EmbreeAccel();
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    HitRecord intersect(const Ray& r, RayKind kind) const;
    bool occluded(const Ray& r) const;
    // A shadow ray through media in one query (accel/boundary_hits.h): whether a caster but a
    // volume boundary blocks r; if not, the boundaries on it in *out (out->n -1: no answer,
    // with two levels or too many crossings). A structure of its own (the casters, the
    // boundaries in geometries whose filter records them), built where a boundary casts shadows.
    bool occluded_collect(const Ray& r, BoundaryHits* out) const;
    // The ray as Embree can take it (origin o, range [tnear, tfar], hit distances then + shift),
    // or false when there is nothing to trace (embree_accel.cpp, "Rays Embree can take").
    static bool prepare(const Ray& r, const Vec3 box[2], float o[3], float* tnear, float* tfar,
                        float* shift);
    // What the alpha filter of a Built's alpha-tested geometry reads (scene/alpha.h).
    struct AlphaFilter {
        SceneView s;
        const int32_t* prim_to_tri = nullptr;  // that geometry's primID -> scene triangle
        bool instanced = false;  // under an instance: the world ray is in the WorldContext
    };
    // Two levels only: mesh k placed by to_world (row-major 3x4, relative to its exported
    // positions), the top scenes committed again; false without two levels.
    bool move(int k, const float to_world[12], const Vec3 world_box[2]);
    bool two_level() const { return two_level_; }
    int64_t bottom_builds() const { return bottom_builds_; }


private:
    struct Built {
        void* scene = nullptr;               // RTCScene
        // Embree primID -> scene triangle: the opaque geometry's first, then the alpha-tested
        // one's (a separate geometry, so that only its hits run the alpha filter)
        std::vector<int32_t> prim_to_tri;
        uint32_t alpha_geom = ~0u;           // geomID of the alpha-tested geometry
        size_t alpha_base = 0;               // its first entry in prim_to_tri
        std::unique_ptr<AlphaFilter> filter;
        // split_bounds builds only: the volume boundaries' geometries (opaque, alpha-tested),
        // their triangles and filters (never read through tri(): occluded_collect only)
        std::vector<int32_t> bound_tris;
        std::unique_ptr<AlphaFilter> bound_filter[2];
        int32_t tri(uint32_t geom, uint32_t prim) const {
            return prim_to_tri[(geom == alpha_geom ? alpha_base : 0) + prim];
        }
    };
    // split_bounds: the volume boundaries in geometries of their own (occluded_collect's)
    Built build(const SceneView& s, uint8_t need_flag, int begin = 0, int end = -1,
                bool instanced = false, bool split_bounds = false);
    const Built& for_kind(RayKind kind) const;
    // ---- two levels (embree_instances.cpp) ----
    struct Top {
        void* scene = nullptr;            // RTCScene of instances
        std::vector<void*> geom;          // per mesh: its instance (RTCGeometry), or null
        std::vector<int32_t> geom_mesh;   // instance geomID -> mesh
        std::vector<const Built*> child;  // per mesh: the child scene it instances
    };
    void build_instanced(const SceneView& s, const std::vector<MeshRange>& meshes);
    void release_instanced();
    const Top& top_for_kind(RayKind kind) const;
    HitRecord intersect_instanced(const Ray& r, RayKind kind) const;
    bool occluded_instanced(const Ray& r) const;
    bool two_level_ = false;
    int64_t bottom_builds_ = 0;
    std::vector<std::unique_ptr<Built>> children_;  // per mesh, and filtered per-kind copies
    Top top_all_, top_camera_, top_shadow_;
    // motion blur: the scene's positions with each moving mesh's in its object space (its
    // child is built there and placed by its steps at the ray's time, embree_instances.cpp)
    std::vector<Vec3> motion_positions_;

    Vec3 box_[2];  // far_ray_bounds()
    void* device_ = nullptr;                 // RTCDevice
    Built all_, camera_, shadow_;
    Built collect_;  // occluded_collect's: the shadow casters, boundaries apart (flat only)
    bool has_camera_ = false, has_shadow_ = false, has_collect_ = false;
};

}  // namespace lantern
