// Compiles the host+device stages with nvcc so CI catches code that cannot run on the GPU.
// The CUDA backend proper (kernels launching these stages, its BVH) is a later issue.
#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/oren_nayar.h"
#include "bsdf/sheen.h"
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

// Every lobe's eval and sample on the device (native/src/bsdf/): one thread per direction pair.
__global__ void bsdf_lobes_kernel(const Vec3* wo, const Vec3* wi, const Vec2* u, Vec3* out, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    ConductorParams c = conductor_complex(0.3f, vec3(0.2f), vec3(3.0f));
    ConductorParams c82 = conductor_f82(0.3f, vec3(0.9f), vec3(0.8f));
    DielectricParams d = dielectric(0.2f, 1.5f, Transport::Radiance);
    OrenNayarParams on{vec3(0.8f), 0.5f};
    SheenParams sh{vec3(1.0f), 0.4f};
    Vec3 acc = conductor_eval(c, wo[i], wi[i]).f + conductor_eval(c82, wo[i], wi[i]).f +
               dielectric_eval(d, wo[i], wi[i]).f + oren_nayar_eval(on, wo[i], wi[i]).f +
               sheen_eval(sh, wo[i], wi[i]).f;
    acc += conductor_sample(c, wo[i], u[i]).weight +
           dielectric_sample(d, wo[i], u[i], u[i].x).weight +
           oren_nayar_sample(on, wo[i], u[i]).weight + sheen_sample(sh, wo[i], u[i]).weight;
    out[i] = acc;
}

}  // namespace lantern
