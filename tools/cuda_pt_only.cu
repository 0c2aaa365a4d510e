// pt_chunk alone on CudaExec: a translation unit whose PTX (nvcc -ptx -I native/src, the
// backend's flags) cicc writes faster than cuda_schedule_pt.cu's, for stack-frame work on pt
// (bench/results/2026-12-02-stack2/pt.md).
#include "backend/cuda/cuda_exec.cuh"
#include "integrator/schedule_pt.h"
namespace lantern {
namespace wf {
template void pt_chunk<CudaExec>(CudaExec&, Wavefront<CudaExec>&, const SceneView, WavefrontStep&,
                                 int64_t, int);
}  // namespace wf
}  // namespace lantern
