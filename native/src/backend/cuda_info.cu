// Whether this build's CUDA backend can run here (device 0, its driver, kernels for its
// compute capability): device discovery, not the backend (backend/cuda/), which only ever runs
// once this says yes. Compiled by nvcc when the backend is built; cuda_stub.cpp otherwise.
#include <cstdlib>
#include <string>

#include <cuda_runtime.h>

#include "backend/cuda/cuda_renderer.h"

namespace lantern {
namespace {

__global__ void probe_kernel() {}  // present only when the build has code for the device

}  // namespace

CudaInfo cuda_info() {
    CudaInfo info;
    info.compiled = true;
    const char* off = std::getenv("LANTERN_DISABLE_CUDA");
    if (off && *off && std::string(off) != "0") {
        info.reason = "disabled by LANTERN_DISABLE_CUDA";
        return info;
    }
    int count = 0;
    cudaError_t e = cudaGetDeviceCount(&count);
    if (e != cudaSuccess) {
        cudaGetLastError();
        const std::string err = std::string(" (CUDA: ") + cudaGetErrorString(e) + ")";
        info.reason = e == cudaErrorInsufficientDriver
                          ? "no NVIDIA driver found, or one too old for this build's CUDA " +
                                std::to_string(CUDART_VERSION / 1000) + "." +
                                std::to_string(CUDART_VERSION % 1000 / 10) + " runtime" + err
                      : e == cudaErrorNoDevice ? "no CUDA-capable GPU found" + err
                                               : "the CUDA driver cannot be used" + err;
        return info;
    }
    cudaDeviceProp prop{};
    if (count == 0 || cudaGetDeviceProperties(&prop, 0) != cudaSuccess) {
        cudaGetLastError();
        info.reason = count == 0 ? "no CUDA device" : "cannot read the properties of CUDA device 0";
        return info;
    }
    info.name = prop.name;
    info.memory_bytes = int64_t(prop.totalGlobalMem);
    info.compute_capability = std::to_string(prop.major) + "." + std::to_string(prop.minor);
    int driver = 0;
    if (cudaDriverGetVersion(&driver) == cudaSuccess) info.driver_version = driver;
    cudaFuncAttributes attr{};
    e = cudaFuncGetAttributes(&attr, probe_kernel);
    if (e != cudaSuccess) {
        cudaGetLastError();
        info.reason = "this build has no kernels for compute capability " +
                      info.compute_capability + " (" + cudaGetErrorString(e) + ")";
        return info;
    }
    info.available = true;
    return info;
}

}  // namespace lantern
