// The features pt's stages test on their hot path that most scenes do not use (issue 32: ray
// visibility and linking, strands, motion, subsurface). The stages take them as a compile-time
// mask F: a scene without any runs stages compiled without those tests (the cost it had before
// the features), a scene with any the general variant, kPtAll; where F has a feature's bit the
// stage still tests the scene's own data, as before. The schedule picks the variant per chunk
// (schedule_pt.h; the GPU builds kPtAll only).
#pragma once

#include <cstdint>

#include "scene/scene_view.h"

namespace lantern {

enum PtFeature : uint32_t {
    kPtLinks = 1u << 0,       // object and lamp ray visibility, light and shadow linking
    kPtStrands = 1u << 1,     // curve segments among the primitives (pt_curve.h)
    kPtMotion = 1u << 2,      // moving or deforming meshes, a moving camera (scene/motion.h)
    kPtSubsurface = 1u << 3,  // random-walk subsurface scattering (pt_sss.h)
    kPtAll = 0xFu,
};

// The features scene s uses (0: none; the stages need none of their tests).
inline uint32_t pt_features(const SceneView& s) {
    uint32_t f = 0;
    if (s.tri_rays || s.light_rays || s.light_receivers || s.light_blockers) f |= kPtLinks;
    if (s.curves.num_segs > 0) f |= kPtStrands;
    if (s.motion.any()) f |= kPtMotion;
    if (s.has_subsurface) f |= kPtSubsurface;
    return f;
}

}  // namespace lantern
