// A camera vertex of the bidirectional integrators (bdpt_camera.h): what next-event estimation
// and connections read, and how much of its material a GPU thread keeps.
#pragma once

#include "bsdf/material_resolve.h"
#include "core/math.h"
#include "integrator/pt_surface.h"

namespace lantern {

// On a GPU thread a connection resolves the cache vertex's material into the camera vertex's
// scratch (one MaterialScratch on the shade kernel's stack, not two: 600 B of its frame) and
// then the camera vertex's again (the same inputs, so the same material). The CPU keeps both.
#ifdef __CUDA_ARCH__
constexpr bool kOneScratch = true;
#else
constexpr bool kOneScratch = false;
#endif

// A camera vertex: what next-event estimation and connections read.
struct CameraVertex {
    SurfaceHit h;
    Frame frame;
    Vec3 wo;      // local
    Vec3 beta;
    float dvcm, dvc;
    const Material* m;
    int depth;    // segments from the camera
    Vec3 n_pick;  // the normal the light tree sees here (light_pick_normal)
    Vec3 ng_l;    // the geometric normal in frame (what a bumped Lambert reads)
    // kOneScratch: where m may live, and what resolves it again (the hit's triangle, its
    // barycentrics and the direction towards the previous vertex)
    MaterialScratch* scratch;
    int tri;
    Vec2 uv;
    Vec3 wo_w;
    // scenes with media (bdpt_medium_stages.h): the medium of a medium vertex (-1: a surface),
    // and the medium the slot's ray arrived in
    int32_t medium_vertex = -1;
    int32_t slot_medium = -1;
    bool strand = false;  // on a strand: the fiber measure's cosines (bdpt_curve.h)
    bool tube = false;    // on a strand, not the hair lobe: pt's surface point (bdpt_curve.h)
};

}  // namespace lantern
