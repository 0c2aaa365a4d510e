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
void build_light_tree(std::vector<Light>& lights, const std::vector<Vec3>& positions,
                      const std::vector<uint32_t>& indices, LightTreeStorage& out);

}  // namespace lantern
