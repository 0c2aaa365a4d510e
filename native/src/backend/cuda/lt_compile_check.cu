// Compiles the light tracer's stages (integrator/lt.h, light_path.h) with nvcc, as compile_check.cu
// does for pt: code a kernel cannot run fails the build.
#include "integrator/lt.h"
namespace lantern {
__global__ void lt_generate_kernel(SceneView s, PathState ps, LightPathState lp, PtSettings st, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) lt_generate(s, ps, lp, st, i, i);
}
__global__ void lt_shade_kernel(SceneView s, PathState ps, LightPathState lp, PtSettings st, const int* queue, int n) {
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) lt_shade(s, ps, lp, st, queue[k]);
}
__global__ void emission_pdf_kernel(SceneView s, const Vec3* d, float* out, int n) {
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) out[k] = emission_pdf(s, s.lights[0], d[k], d[k]).pdf_emit;
}
}
