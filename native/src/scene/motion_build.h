// Host side of motion blur (scene/motion.h): decomposing the exported matrices and bounding a
// moving instance over the shutter.
#pragma once

#include <string>
#include <vector>

#include "scene/motion.h"

namespace lantern {

// m (row-major 4x4, the last row ignored) as a MotionStep; false when it is not finite or its
// 3x3 part is singular.
bool decompose_motion_step(const float m[16], MotionStep* out);
// World bounds (lo, hi) over the shutter of object o whose exported bounds are box.
void motion_world_box(const MotionView& mv, const ObjectMotion& o, const Vec3 box[2],
                      Vec3 out[2]);

struct SceneInput;
struct MeshInput;
struct MeshRange;
struct BvhNode;
struct BvhTri;
// Deformation blur (scene/deform_build.cpp): mesh m's steps as DeformMesh *out, its corners
// appended to `corners` (indices: the scene's, r its range); false with *warning where its steps
// do not fit its positions or are not finite.
bool build_deform(const MeshInput& m, const MeshRange& r, const std::vector<uint32_t>& indices,
                  std::vector<Vec3>& corners, DeformMesh* out, std::string* warning);
// A deforming mesh's bottom level (nodes over tris) refitted to hold its triangles at every
// step; box (its lo, hi) grown to the union.
void deform_refit(std::vector<BvhNode>& nodes, const std::vector<BvhTri>& tris,
                  const MotionView& mv, const DeformMesh& dm, Vec3 box[2]);
// What moves, for the integrators that hand a motion scene to pt ("" when nothing does):
// "motion blur (mesh 'x' moves)" or "motion blur (the camera moves)".
std::string motion_reason(const SceneInput& in);
// The same for meshes and strands only (a moving camera aside): what needs every ray timed.
std::string motion_geometry_reason(const SceneInput& in);

}  // namespace lantern
