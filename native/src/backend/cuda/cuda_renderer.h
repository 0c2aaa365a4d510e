// The CUDA backend as the session sees it: plain C++ (no CUDA types), so session.cpp compiles
// with or without CUDA. cuda_renderer.cu implements it when nvcc is found; cuda_stub.cpp says
// "not compiled" otherwise. The renderer runs the CPU session's schedule (integrator/wavefront.h)
// on CudaExec; docs/cuda_backend.md.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace lantern {

class HostScene;
struct SessionSettings;
struct SessionStats;

struct CudaInfo {
    bool compiled = false;   // this build has the CUDA backend
    bool available = false;  // a device with a driver this build can run on
    std::string reason;      // why not, when !available
    std::string name;        // device 0
    int64_t memory_bytes = 0;
    std::string compute_capability;
    int driver_version = 0;  // cudaDriverGetVersion: 13000 for 13.0 (0: unknown)
};

// Device 0 and whether kernels of this build run on it. LANTERN_DISABLE_CUDA=1 hides the GPU.
CudaInfo cuda_info();

// The GPU cannot render this (no usable device, out of memory): the session falls back to the
// CPU with the message as a warning.
struct CudaUnavailable : std::runtime_error {
    using std::runtime_error::runtime_error;
};

class CudaRenderer {
public:
    virtual ~CudaRenderer() = default;
    // One iteration of settings.spp_per_iteration samples per pixel (the bidirectional
    // integrators may run it as several passes; `iteration` counts them as the CPU session
    // does). Returns false when cancelled: the image is unchanged then. Throws CudaUnavailable
    // when the GPU runs out of memory (the image so far stays readable through accum()).
    virtual bool step(const SessionSettings& settings, uint64_t& iteration, SessionStats& stats,
                      const std::atomic<bool>& cancel, std::vector<std::string>& warnings) = 0;
    // The running sum of finished iterations (3 doubles per pixel, top row first) and, in
    // *samples, the samples per pixel it holds (the two always match: a reader on another
    // thread never sees a new sum with an old count).
    virtual std::vector<double> accum(int64_t* samples) = 0;
    virtual std::string device_name() const = 0;
};

// Uploads the scene and builds its BVH on the device. Throws CudaUnavailable.
std::unique_ptr<CudaRenderer> make_cuda_renderer(const HostScene& scene,
                                                 const SessionSettings& settings,
                                                 std::vector<std::string>& warnings);

}  // namespace lantern
