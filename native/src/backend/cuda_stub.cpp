// The CUDA backend in a build without nvcc: never available, with the reason (cuda_info.cu and
// backend/cuda/ otherwise).
#include "backend/cuda/cuda_renderer.h"

namespace lantern {

CudaInfo cuda_info() {
    CudaInfo info;
    info.reason = "this build of Lantern has no CUDA backend (nvcc was not found when it was built)";
    return info;
}

std::unique_ptr<CudaRenderer> make_cuda_renderer(const HostScene&, const SessionSettings&,
                                                 std::vector<std::string>&) {
    throw CudaUnavailable(cuda_info().reason);
}

}  // namespace lantern
