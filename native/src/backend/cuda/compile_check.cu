// Compiles the host+device stages with nvcc so CI catches code that cannot run on the GPU.
// The CUDA backend proper (kernels launching these stages, its BVH) is a later issue.
#include "integrator/pt.h"

namespace lantern {

__global__ void pt_generate_kernel(SceneView s, PathState ps, PtSettings st, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) pt_generate(s, ps, st, i, i);
}

__global__ void pt_shade_kernel(SceneView s, PathState ps, PtSettings st, const int* queue, int n) {
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) pt_shade(s, ps, st, queue[k]);
}

__global__ void pt_shadow_kernel(PathState ps, const uint8_t* occluded, const int* queue, int n) {
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n && ps.shadow_valid[queue[k]]) pt_shadow_result(ps, queue[k], occluded[queue[k]] != 0);
}

}  // namespace lantern
