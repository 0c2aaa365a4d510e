// Bidirectional stages shared by the integrators "bdpt", "lvc" and "cis": light sub-paths whose
// non-delta vertices go into the light vertex cache (LVC) and are splatted to the camera (t = 1),
// and camera sub-paths that add emission (s = 0), next-event estimation (s = 1) and connections
// to cache vertices (s >= 2). MIS: the balance of Georgiev's "Implementing Vertex Connection and
// Merging" (2012) report with the power heuristic, i.e. SmallVCM's recursive dVCM / dVC, with the
// sample counts of the cache folded in (docs/lvc_notes.md, "MIS with a vertex cache"):
//
//   technique              count per camera sample
//   s = 0 (hit a light)    1
//   s = 1 (next event)     1
//   s >= 2 (connection)    r = N L / |C|   (bdpt: 1, every vertex of the paired light path)
//   t = 1 (light tracing)  n_lt = L / spp_per_iteration
//
// Every stage touches one path slot; the session (bdpt_session.cpp) runs them over queues.
//
// The stages live in three headers: bdpt_common.h (MIS helpers, the cache vertex, settings,
// per-slot state), bdpt_light.h (the light pass) and bdpt_camera.h (the camera pass).
#pragma once

#include "integrator/bdpt_camera.h"
#include "integrator/bdpt_camera_events.h"  // the stages around the camera shade
#include "integrator/bdpt_common.h"
#include "integrator/bdpt_light.h"
#include "integrator/bdpt_medium_stages.h"  // scenes with media: the hooks' definitions
#include "integrator/bdpt_sss.h"            // subsurface: the camera paths' walks
