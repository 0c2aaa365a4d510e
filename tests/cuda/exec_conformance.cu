// CudaExec against the plain references of tests/cpp/exec_conformance.h: one line per
// primitive ("ok" or "FAIL" and what differed). tools/gpu_check.sh runs it first, so that a GPU
// run fails fast and names the primitive. Exit: 0 all passed, 1 a primitive failed, 3 no GPU.
#include <cstdio>
#include <vector>

#include "accel/bvh_builder.h"
#include "backend/cuda/cuda_exec.cuh"
#include "exec_conformance.h"

namespace {

using namespace lantern;

// The ray queries on the device copy of ray_scene() and its BVH (as the renderer uploads them).
std::string check_rays_on_device(CudaExec& ex) {
    HostScene scene(conformance::ray_scene());
    std::vector<void*> mem;
    auto upload = [&](const void* host, size_t bytes) -> void* {
        if (!host || bytes == 0) return nullptr;
        void* d = nullptr;
        cuda_detail::check(cudaMalloc(&d, bytes), "cudaMalloc (scene)");
        mem.push_back(d);
        cuda_detail::check(cudaMemcpy(d, host, bytes, cudaMemcpyHostToDevice), "cudaMemcpy");
        return d;
    };
    std::string failure;
    try {
        const SceneView sv = scene.copied_view(upload);
        std::vector<std::string> warnings;
        Bvh bvh = build_bvh(scene.view(), BvhBuildOptions{}, warnings);
        BvhView bv = bvh.view();
        bv.nodes = static_cast<const BvhNode*>(upload(bvh.nodes.data(), bvh.nodes.size() * sizeof(BvhNode)));
        bv.tris = static_cast<const BvhTri*>(upload(bvh.tris.data(), bvh.tris.size() * sizeof(BvhTri)));
        ex.set_rays(bv, sv);
        std::mt19937 rng(5);
        for (int n : {0, 1, 7, 4001}) {
            failure = conformance::check_rays(ex, scene.view(), scene.num_triangles(), n, rng);
            if (!failure.empty()) break;
        }
    } catch (const std::exception& e) {
        failure = e.what();
    }
    for (void* p : mem) cudaFree(p);
    return failure;
}

}  // namespace

int main() {
    const CudaInfo info = cuda_info();
    if (!info.available) {
        std::printf("exec_conformance: no usable GPU (%s)\n", info.reason.c_str());
        return 3;
    }
    int failed = 0;
    try {
        CudaExec ex(0);
        std::vector<conformance::Result> results = conformance::run_all(ex);
        results.push_back({"closest/occluded", check_rays_on_device(ex)});
        for (const conformance::Result& r : results) {
            std::printf("%-16s %s%s\n", r.primitive.c_str(), r.failure.empty() ? "ok" : "FAIL ",
                        r.failure.c_str());
            failed += !r.failure.empty();
        }
    } catch (const std::exception& e) {
        std::printf("exec_conformance: CUDA error: %s\n", e.what());
        return 1;
    }
    std::printf("exec_conformance: CudaExec on %s: %s\n", info.name.c_str(),
                failed ? "FAILED" : "all primitives passed");
    return failed ? 1 : 0;
}
