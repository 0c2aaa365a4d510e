// The pt and lt chunks of the schedule (integrator/schedule_pt.h, schedule_lt.h) instantiated on
// CudaExec. One translation unit per part of the schedule, so that a build compiles them side by
// side: nvcc spends most of the backend's build on these kernels (docs/cuda_backend.md).
#include "backend/cuda/cuda_exec.cuh"
#include "integrator/schedule_lt.h"
#include "integrator/schedule_pt.h"

namespace lantern {
namespace wf {

template void pt_chunk<CudaExec>(CudaExec&, Wavefront<CudaExec>&, const SceneView, WavefrontStep&,
                                 int64_t, int);
template void lt_chunk<CudaExec>(CudaExec&, Wavefront<CudaExec>&, const SceneView, WavefrontStep&,
                                 int64_t, int);

}  // namespace wf
}  // namespace lantern
