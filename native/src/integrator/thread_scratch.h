// Per-thread scratch a GPU keeps off its kernels' stacks (bench/results/2026-12-03-progregs):
// node programs' registers (SceneView::program_regs, kProgramRegs floats a thread), cis's
// p-hats and pick counts (cis_candidates, 2 x kCisCandidates) and a mix's resolved leaves
// (mix_leaves, kMixLeaves Materials), one column or slot per thread of a launch of at most
// `threads` threads, each allocated only where the scene or the integrator uses it. The stages
// read them on the device only (the CPU keeps its stack arrays); this plan, written once for
// any executor's arrays, is the CUDA renderer's, and tests/cpp runs it on the CPU's.
#pragma once

#include <string>

#include "bsdf/material.h"
#include "integrator/bdpt.h"
#include "scene/material_program.h"

namespace lantern {

// A mix with a leaf whose inputs are resolved at a hit (textures, programs).
inline bool scene_has_textured_mix_leaf(const SceneView& s) {
    for (int k = 0; k < s.num_materials; ++k) {
        const Material& m = s.materials[k];
        if (m.type != kMaterialMix) continue;
        for (int i = 0; i < m.mix_count; ++i)
            if (s.materials[m.mix_child[i]].tex_flags & kTexShading) return true;
    }
    return false;
}

template <class Exec>
struct ThreadScratch {
    typename Exec::template Array<float> program_regs, cis_candidates;
    typename Exec::template Array<Material> mix_leaves;

    void bind(MemoryMeter* m) {
        program_regs.bind(m);
        cis_candidates.bind(m);
        mix_leaves.bind(m);
    }
    // What the scene needs (host: the scene's own view, for its materials), pointed at from
    // `view` (the executor's copy). Returns whether view changed.
    bool prepare_scene(const SceneView& host, SceneView& view, int threads) {
        const size_t n = size_t(threads);
        if (host.material_bits & kScenePrograms) program_regs.grow(size_t(kProgramRegs) * n);
        if (scene_has_textured_mix_leaf(host)) mix_leaves.grow(size_t(kMixLeaves) * n);
        return point(view, threads);
    }
    // What the integrator needs: cis's candidates, at its first step.
    bool prepare_integrator(const std::string& integrator, SceneView& view, int threads) {
        if (integrator != "cis" || cis_candidates.data()) return false;
        cis_candidates.grow(size_t(2 * kCisCandidates) * size_t(threads));
        return point(view, threads);
    }
    int64_t bytes() const {
        return int64_t((program_regs.capacity() + cis_candidates.capacity()) * sizeof(float) +
                       mix_leaves.capacity() * sizeof(Material));
    }

private:
    bool point(SceneView& view, int threads) {
        view.program_regs = program_regs.data();
        view.cis_candidates = cis_candidates.data();
        view.mix_leaves = mix_leaves.data();
        const bool any = view.program_regs || view.cis_candidates || view.mix_leaves;
        view.device_threads = any ? uint32_t(threads) : 0u;
        return any;
    }
};

}  // namespace lantern
