#include "backend/cuda/cuda_exec.cuh"
#include "integrator/schedule_pt.h"
namespace lantern {
namespace wf {
template void pt_chunk<CudaExec>(CudaExec&, Wavefront<CudaExec>&, const SceneView, WavefrontStep&,
                                 int64_t, int);
}  // namespace wf
}  // namespace lantern
