// Compiles the BVH traversal (accel/bvh.h) with nvcc: one thread per ray, closest hit for camera
// and indirect rays and occlusion for shadow rays, the two-level BVH and the composed query of
// accel/scene_query.h; this only keeps those headers device-clean.
#include "accel/bvh.h"
#include "accel/scene_query.h"
#include "accel/tlas.h"

// At most 128 registers a thread, as the backend's kernels (each_kernel's bound): the alpha-tested
// traversals took 178-222 without it.
#define LANTERN_TRAVERSAL_BOUNDS __launch_bounds__(256, 2)
// The scene stays in kernel-parameter memory (__grid_constant__), as each_kernel's functor: the
// alpha test takes it by reference, and a by-value parameter was copied to the stack for it (568
// B: tlas_intersect_alpha_kernel measured 2,176 B of stack, over the 2 KB line).

namespace lantern {

__global__ void LANTERN_TRAVERSAL_BOUNDS bvh_intersect_kernel(BvhView bvh, const Ray* rays, BvhHit* hits, int n,
                                     uint32_t need) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) hits[i] = bvh_intersect(bvh, rays[i], need);
}

__global__ void LANTERN_TRAVERSAL_BOUNDS bvh_occluded_kernel(BvhView bvh, const Ray* rays, uint8_t* occluded, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) occluded[i] = bvh_occluded(bvh, rays[i], kBvhNeedShadow) ? 1 : 0;
}

// With the scene's stochastic alpha test (scene/alpha.h), as the backend will call it.
__global__ void LANTERN_TRAVERSAL_BOUNDS bvh_intersect_alpha_kernel(BvhView bvh, const __grid_constant__ SceneView scene, const Ray* rays,
                                           BvhHit* hits, int n, uint32_t need) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) hits[i] = bvh_intersect(bvh, rays[i], need, BvhAlphaTest{scene, rays[i]});
}

__global__ void LANTERN_TRAVERSAL_BOUNDS bvh_occluded_alpha_kernel(BvhView bvh, const __grid_constant__ SceneView scene, const Ray* rays,
                                          uint8_t* occluded, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n)
        occluded[i] = bvh_occluded(bvh, rays[i], kBvhNeedShadow, BvhAlphaTest{scene, rays[i]}) ? 1 : 0;
}

// The two-level traversal (accel/tlas.h): instances over per-mesh bottom levels.
__global__ void LANTERN_TRAVERSAL_BOUNDS tlas_intersect_alpha_kernel(TlasView tl, const __grid_constant__ SceneView scene, const Ray* rays,
                                            BvhHit* hits, int n, uint32_t need) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) hits[i] = tlas_intersect(tl, rays[i], need, BvhAlphaTest{scene, rays[i]});
}

__global__ void LANTERN_TRAVERSAL_BOUNDS tlas_occluded_kernel(TlasView tl, const Ray* rays, uint8_t* occluded, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) occluded[i] = tlas_occluded(tl, rays[i], kBvhNeedShadow) ? 1 : 0;
}

// The built-in query of accel/scene_query.h (written for the CUDA executor, which does not call
// it yet: docs/cuda_backend.md "Strands and motion blur"): triangles (one or two levels), then
// the strands (accel/curve_query.h: the curve BVH per kind, moving sets through their
// matrices). Closest hit and occlusion in kernels of their own: inlined, each traversal keeps
// its own stack in the kernel's frame.
__global__ void LANTERN_TRAVERSAL_BOUNDS scene_query_closest_kernel(
    BvhView bvh, const SceneQueryView* x, const __grid_constant__ SceneView scene, const Ray* rays,
    BvhHit* hits, int n, int kind, uint32_t need) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) hits[i] = scene_query_closest(bvh, x, rays[i], kind, need, BvhAlphaTest{scene, rays[i]});
}

__global__ void LANTERN_TRAVERSAL_BOUNDS scene_query_occluded_kernel(
    BvhView bvh, const SceneQueryView* x, const __grid_constant__ SceneView scene, const Ray* rays,
    uint8_t* occluded, int n, int kind, uint32_t need) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n)
        occluded[i] =
            scene_query_occluded(bvh, x, rays[i], kind, need, BvhAlphaTest{scene, rays[i]}) ? 1 : 0;
}

}  // namespace lantern
