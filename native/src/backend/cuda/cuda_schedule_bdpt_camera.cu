// The camera chunk of bdpt, lvc and cis (integrator/schedule_bdpt.h) instantiated on CudaExec:
// its shading kernel is the backend's largest, so it has a translation unit of its own.
#include "backend/cuda/cuda_exec.cuh"
#include "integrator/schedule_bdpt.h"

namespace lantern {
namespace wf {

template void camera_chunk<CudaExec>(CudaExec&, Wavefront<CudaExec>&, const SceneView,
                                     WavefrontStep&, int64_t, int);

}  // namespace wf
}  // namespace lantern
