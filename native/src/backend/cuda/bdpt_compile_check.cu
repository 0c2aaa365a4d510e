// Compiles the bidirectional stages (integrator/bdpt.h: light pass, camera pass with next-event
// estimation, uniform and resampled connections) with nvcc: code a kernel cannot run fails the
// build. The CUDA backend (issue 6) launches these same functions.
#include "integrator/bdpt.h"
namespace lantern {
__global__ void bdpt_light_generate_kernel(SceneView s, PathState ps, BdptState bs, BdptSettings st, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) bdpt_light_generate(s, ps, bs, st, i, i);
}
__global__ void bdpt_light_shade_kernel(SceneView s, PathState ps, BdptState bs, BdptSettings st, const int* queue, int n) {
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) bdpt_light_shade(s, ps, bs, st, queue[k], queue[k]);
}
__global__ void bdpt_camera_generate_kernel(SceneView s, PathState ps, BdptState bs, BdptSettings st, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) bdpt_camera_generate(s, ps, bs, st, i, i);
}
__global__ void bdpt_camera_shade_kernel(SceneView s, PathState ps, BdptState bs, BdptSettings st, LightCache c, const int* queue, int n) {
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) bdpt_camera_shade(s, ps, bs, st, c, queue[k], queue[k]);
}
}
