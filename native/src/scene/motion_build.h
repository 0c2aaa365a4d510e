// Host side of motion blur (scene/motion.h): decomposing the exported matrices and bounding a
// moving instance over the shutter.
#pragma once

#include <string>

#include "scene/motion.h"

namespace lantern {

// m (row-major 4x4, the last row ignored) as a MotionStep; false when it is not finite or its
// 3x3 part is singular.
bool decompose_motion_step(const float m[16], MotionStep* out);
// World bounds (lo, hi) over the shutter of object o whose exported bounds are box.
void motion_world_box(const MotionView& mv, const ObjectMotion& o, const Vec3 box[2],
                      Vec3 out[2]);

struct SceneInput;
// What moves, for the integrators that hand a motion scene to pt ("" when nothing does):
// "motion blur (mesh 'x' moves)" or "motion blur (the camera moves)".
std::string motion_reason(const SceneInput& in);

}  // namespace lantern
