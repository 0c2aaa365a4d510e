// Every BSDF lobe in a kernel of its own, so that nvcc checks each lobe by itself (the backend,
// cuda_renderer.cu, compiles them only through the materials that dispatch to them).
#include "bsdf/conductor.h"
#include "bsdf/dielectric.h"
#include "bsdf/oren_nayar.h"
#include "bsdf/sheen.h"
#include "bsdf/material.h"

namespace lantern {

// Every lobe's eval and sample on the device (native/src/bsdf/): one thread per direction pair.
__global__ void __launch_bounds__(256, 2) bsdf_lobes_kernel(const Vec3* wo, const Vec3* wi, const Vec2* u, const float* sheen_ltc, Vec3* out, int n) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    ConductorParams c = conductor_complex(0.3f, vec3(0.2f), vec3(3.0f));
    ConductorParams c82 = conductor_f82(0.3f, vec3(0.9f), vec3(0.8f));
    DielectricParams d = dielectric(0.2f, 1.5f, Transport::Radiance);
    OrenNayarParams on{vec3(0.8f), 0.5f};
    SheenParams sh{vec3(1.0f), sheen_ltc};
    Vec3 acc = conductor_eval(c, wo[i], wi[i]).f + conductor_eval(c82, wo[i], wi[i]).f +
               dielectric_eval(d, wo[i], wi[i]).f + oren_nayar_eval(on, wo[i], wi[i]).f +
               sheen_eval(sh, wo[i], wi[i], Transport::Radiance).f;
    acc += conductor_sample(c, wo[i], u[i]).weight +
           dielectric_sample(d, wo[i], u[i], u[i].x).weight +
           oren_nayar_sample(on, wo[i], u[i]).weight + sheen_sample(sh, wo[i], u[i], Transport::Importance).weight;
    out[i] = acc;
}

}  // namespace lantern
