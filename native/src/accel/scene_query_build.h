// Host side of accel/scene_query.h: the structures the built-in ray queries need beyond the
// one-level BVH (the two-level BVH where meshes move, the strands' query) and the same view
// over copies of their arrays (the CUDA backend's upload: plain host code, tested on the CPU
// with host copies in tests/cpp/test_scene_query.cpp).
#pragma once

#include <string>
#include <vector>

#include "accel/curve_query_build.h"
#include "accel/scene_query.h"
#include "accel/tlas_build.h"

namespace lantern {

struct SceneQuery {
    bool two_level = false;
    Tlas tlas;          // two_level: one bottom level per mesh
    CurveQuery curves;  // strands (curves.num_segs 0: none)
    SceneQueryView view() const;
};

// Whether a scene needs SceneQuery at all: moving meshes (two levels) or strands.
bool scene_query_needed(const SceneView& s);
// meshes: two levels (accel/tlas_build.h), null: the caller's one-level BVH.
void scene_query_build(SceneQuery& q, const SceneView& s, const std::vector<MeshRange>* meshes,
                       int threads, std::vector<std::string>& warnings);
// The view over copies of q's arrays (copy as curve_query_copied's); `copied`: the scene's own
// copied view (HostScene::copied_view), whose motion steps, deformations and strand keys the
// copied structures read. The bottom levels go as two arrays (every mesh's nodes, tris).
SceneQueryView scene_query_copied(const SceneQuery& q, const CurveQueryCopy& copy,
                                  const SceneView& copied);

}  // namespace lantern
