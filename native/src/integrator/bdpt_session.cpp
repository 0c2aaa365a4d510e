// The bidirectional integrators (bdpt, lvc, cis): the settings of a pass, and the schedule
// (integrator/schedule_bdpt.h: Algorithms 1 and 2 of the paper, every reduction in queue order,
// so the image has the same bits for any thread count) on the CPU executor.
#include "backend/cpu/cpu_exec.h"
#include "integrator/schedule_bdpt.h"
#include "integrator/session.h"

namespace lantern {

BdptSettings make_bdpt_settings(const SessionSettings& s, int width, int height,
                                uint64_t iteration, int mode, float r) {
    const double light_paths = double(width) * height * s.spp_per_iteration;
    BdptSettings st{};
    st.max_depth = s.max_depth;
    st.rr_depth = s.rr_depth;
    st.spp_per_iteration = s.spp_per_iteration;
    st.seed = s.seed;
    st.iteration = iteration;
    st.mode = mode;
    st.connections = s.connections;
    st.candidates = s.candidates;
    st.target = s.cis_target == "bsdf" ? kTargetBsdf : kTargetContribution;
    st.naive_ris = s.naive_ris ? 1 : 0;
    st.r = r;
    st.n_lt = float(light_paths / s.spp_per_iteration);
    st.inv_light_paths = float(1.0 / light_paths);
    // cis counts light tracing of direct light as a quarter (bdpt.h, BdptSettings::lt_direct);
    // bdpt and lvc keep the textbook counts
    st.lt_direct = mode == kCisResampled ? 0.25f : 1.0f;
    return st;
}

// The bidirectional iteration on the CPU executor (integrator/schedule_bdpt.h).
template bool wf::bidirectional_iteration<CpuExec>(CpuExec&, Wavefront<CpuExec>&,
                                                   const SceneView&, WavefrontStep&);

}  // namespace lantern
