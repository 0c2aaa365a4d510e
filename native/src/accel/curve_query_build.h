// Host side of the strand query (accel/curve_query.h): the scene's segments split per kind of
// ray (the strands each kind sees, scene/scene_curves.cpp's flags) with the moving sets apart,
// their curve BVHs and the moving sets' bounds over the shutter; and the same view over
// copies of those arrays (the CUDA backend's upload, plain host code tested on the CPU).
// backend/cpu/curve_accel.cpp builds one (its Embree path uses the split alone).
#pragma once

#include <functional>
#include <vector>

#include "accel/curve_bvh_build.h"
#include "accel/curve_query.h"
#include "scene/scene_view.h"

namespace lantern {

struct CurveQuery {
    // a set moving with its object: its segments per kind and their BVHs (exported frame)
    struct Moving {
        const CurveSetMotion* set = nullptr;
        Vec3 box[2];  // world bounds over the shutter
        std::vector<CurveSeg> segs[kCurveKinds];
        CurveBvh bvh[kCurveKinds];
    };
    int32_t first_prim = 0;  // SceneView::num_triangles
    int32_t distinct = 1;    // 1: every kind sees every strand (still[0] alone), else 3
    int32_t num_segs = 0;
    std::vector<CurveSeg> still[kCurveKinds];  // the strands that do not move with an object
    CurveBvh bvh[kCurveKinds];
    std::vector<Moving> moving;  // one per CurveView::sets entry
    std::vector<CurveMovingSet> moving_views;  // (built by curve_query_build)
    MotionView motion;
    CurveQueryView view() const;
};

// The scene's segments per kind of ray, each moving set's apart (no BVH yet).
void curve_query_split(CurveQuery& q, const SceneView& s);
// The split (curve_query_split) and the BVHs and boxes over it.
void curve_query_build(CurveQuery& q, const SceneView& s);

// copy(host, bytes): a copy of those bytes elsewhere (the device), its address
using CurveQueryCopy = std::function<const void*(const void*, size_t)>;
// The view over copies of q's arrays; `copied` is the scene's own copied view
// (HostScene::copied_view), whose keys and motion steps the copy reads.
CurveQueryView curve_query_copied(const CurveQuery& q, const CurveQueryCopy& copy,
                                  const SceneView& copied);

}  // namespace lantern
