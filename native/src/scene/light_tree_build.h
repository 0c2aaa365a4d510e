// Host side of the light tree (scene/light_tree.h): built once per scene from its lights.
#pragma once

#include <vector>

#include "scene/scene_view.h"

namespace lantern {

struct LightTreeStorage {
    std::vector<LightTreeNode> nodes;  // depth-first; empty without local lights
    std::vector<int32_t> distant;      // the sun and world lights, by index
};

// Builds the tree over the local lights (point, spot, area, emissive triangles; positions and
// indices are the scene's triangles) and lists the distant ones; sets every light's tree_leaf
// and tree_energy. Splits by the surface area orientation heuristic over 12 buckets per axis.
// shutter (motion blur; light_shutter_boxes): per light a box (lo, hi) over the shutter that
// its bounds take in, or an empty one (lo.x > hi.x) for a light that does not move.
void build_light_tree(std::vector<Light>& lights, const std::vector<Vec3>& positions,
                      const std::vector<uint32_t>& indices, LightTreeStorage& out,
                      const std::vector<Vec3>* shutter = nullptr);

// Motion blur (docs/motion_blur.md "A moving emitter"): the box each emissive triangle of a
// moving mesh sweeps over the shutter, its corners where they are (light_triangle_at's
// placement: deformation lerped, then the object's matrix) at 16 times per step interval, in
// boxes[2k], boxes[2k + 1]; an empty box for every other light. False where no light moves.
bool light_shutter_boxes(const SceneView& v, const std::vector<Light>& lights,
                         std::vector<Vec3>& boxes);

}  // namespace lantern
