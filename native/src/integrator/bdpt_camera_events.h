// The camera pass's stages around its shade (bdpt_camera_shade), each a kernel of its own on a
// GPU (issue 30: no kernel holds every call chain of the camera pass under one stack frame):
//
// - the emission stage, before the shade, in scenes without media: the lights the traced
//   segment crosses and the background on a miss (bdpt_camera_emission; a soft-falloff light's
//   weight tests V(c, x) with a ray of its own, soft_light_path.h);
// - the events stage, after the shade: next-event estimation (s = 1) and the connections
//   (s >= 2) of the camera vertex the shade queued (bdpt_queue_camera_events), a surface's or a
//   medium's, from the slot's stream as the shade left it there, the surface's material resolved
//   again from the same inputs (the same material).
//
// Neither reads what the shade writes after queueing (the slot's next ray, throughput, depth,
// stream), and the slot's additions keep the fused order (the crossed lights' emission first,
// the events stage adds nothing itself: its shadow rays are the shadow stage's), so every
// executor's images keep the bits of the shade that made all three itself. schedule_bdpt.h runs
// them; the CPU runs the same stages.
#pragma once

#include "integrator/bdpt_camera.h"
#include "integrator/bdpt_medium_stages.h"

namespace lantern {

// A stage's ray queries (StageRays) at the path's time, by reference: StageRays::at makes a copy,
// and a StageRays holds the executor's Rays (on a GPU a BVH view and a whole SceneView, ~700 B)
// that a GPU thread keeps on its stack under every call it is passed to.
template <class SR>
struct StageRaysRef {
    const SR* sr;
    float time;
    bool no_centre_test;
    LANTERN_HD bool blocked(const Ray& r, bool shadow_ray) const {
        Ray q = r;
        q.time = time;
        return sr->rays.occluded(q, shadow_ray ? sr->shadow : sr->indirect);
    }
    LANTERN_HD auto closest_indirect(const Ray& r) const {  // (soft_light_medium.h)
        Ray q = r;
        q.time = time;
        return sr->rays.closest(q, sr->indirect);
    }
};
template <class SR>
LANTERN_HD inline StageRaysRef<SR> stage_rays_at(const SR& sr, float time) {
    return StageRaysRef<SR>{&sr, time, sr.no_centre_test};
}

// The emission stage: s = 0 along the traced segment (scenes without media; in media the shade's
// segment stage finds the lights it crosses, bdpt_camera_medium_segment). L: linking's tests
// compiled in (bidir_links_on).
template <bool L = true, class SR>
LANTERN_HD inline void bdpt_camera_emission_stage(const SceneView& s, const PathState& ps,
                                                  const BdptState& bs,
                                                  const BdptSettings& st_all, int i,
                                                  int64_t path, const SR& sr) {
    const BdptSettings st = camera_settings(st_all, pixel_conn_of_slot(st_all, bs, i));
    const int tri = ps.hit_prim[i];
    bdpt_camera_emission<L>(s, ps, bs, st, i, tri >= 0 ? ps.hit_t[i] : ps.ray_tmax[i], tri < 0,
                            sr);
}

// The events stage: the queued camera vertex's next event and connections (none where the shade
// queued nothing: a delta surface, a path that ended or went under the surface). sr: the
// stage's own ray queries (V(c, x) of soft-falloff lights). L: linking's tests compiled in.
template <bool L = true, class SR>
LANTERN_HD inline void bdpt_camera_events(const SceneView& s, const PathState& ps,
                                          const BdptState& bs, const BdptSettings& st_all,
                                          const LightCache& cache, int i, int64_t path,
                                          const SR& sr) {
    if (!bs.cam_on[i]) return;
    const BdptSettings st = camera_settings(st_all, pixel_conn_of_slot(st_all, bs, i));
    CameraVertex& z = bs.cam_z[i];  // read in the slot's memory: no copy on a GPU thread's stack
    MaterialScratch scratch;        // z.m's, and the cache vertices' (kOneScratch)
    z.scratch = &scratch;
    Rng rng = bs.cam_rng[i];
    if (z.medium_vertex >= 0) {
        bdpt_camera_medium_nee(s, ps, bs, st, z, i, rng, sr, path);
    } else {
        z.m = &camera_vertex_material(s, z);
        bdpt_camera_nee<L>(s, ps, bs, st, z, i, rng, sr, path);
    }
    // (a restricted path: pt's techniques alone, bidir_ray_visibility.h)
    if (!(L && bidir_restricted(s, ps, i))) bdpt_camera_connect(s, bs, st, cache, z, i, path);
}

}  // namespace lantern
