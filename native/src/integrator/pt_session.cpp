// Integrator "pt"'s schedule (integrator/schedule_pt.h) on the CPU executor, in a translation
// unit of its own as lt's and bdpt's are: GCC budgets the inlining of a whole unit (--param
// inline-unit-growth), and inside session.cpp pt_shade's hot helpers (offset_ray_origin,
// russian_roulette, length) were left out of line once that unit grew
// (bench/results/2026-12-04-instrcost).
#include "backend/cpu/cpu_exec.h"
#include "integrator/schedule_pt.h"

namespace lantern {

template void wf::pt_chunk<CpuExec>(CpuExec&, Wavefront<CpuExec>&, const SceneView,
                                    WavefrontStep&, int64_t, int);

}  // namespace lantern
