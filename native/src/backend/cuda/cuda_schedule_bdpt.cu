// The bidirectional iteration (integrator/schedule_bdpt.h: light passes, the cache, its index)
// instantiated on CudaExec; its camera chunk, the largest kernel, is compiled beside it in
// cuda_schedule_bdpt_camera.cu.
#include "backend/cuda/cuda_exec.cuh"
#include "integrator/schedule_bdpt.h"

namespace lantern {
namespace wf {

extern template void camera_chunk<CudaExec>(CudaExec&, Wavefront<CudaExec>&, const SceneView,
                                            WavefrontStep&, int64_t, int);
template bool bidirectional_iteration<CudaExec>(CudaExec&, Wavefront<CudaExec>&,
                                                const SceneView&, WavefrontStep&);

}  // namespace wf
}  // namespace lantern
