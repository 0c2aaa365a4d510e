// The bidirectional integrators (bdpt, lvc, cis): the settings of a pass, and the schedule
// (integrator/schedule_bdpt.h: Algorithms 1 and 2 of the paper, every reduction in queue order,
// so the image has the same bits for any thread count) on the CPU executor.
#include <algorithm>
#include <cmath>

#include "backend/cpu/cpu_exec.h"
#include "integrator/schedule_bdpt.h"
#include "integrator/session.h"

namespace lantern {

int64_t bdpt_light_paths(const SessionSettings& s, int width, int height) {
    const int64_t all = int64_t(width) * height * s.spp_per_iteration;
    if (s.light_path_fraction >= 1.0f) return all;
    return std::min<int64_t>(all, std::llround(double(s.light_path_fraction) * double(all)));
}

BdptSettings make_bdpt_settings(const SessionSettings& s, int width, int height,
                                uint64_t iteration, int mode, float r) {
    const double light_paths = double(bdpt_light_paths(s, width, height));
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
    // (no light paths: r = 0 too, and the camera pass's weights are path tracing's)
    st.inv_light_paths = light_paths > 0.0 ? float(1.0 / light_paths) : 0.0f;
    // cis counts light tracing of direct light as a quarter (bdpt.h, BdptSettings::lt_direct);
    // bdpt and lvc keep the textbook counts
    st.lt_direct = mode == kCisResampled ? 0.25f : 1.0f;
    st.moments = s.auto_moments ? 1 : 0;
    st.conn_map = nullptr;  // the schedule's copy in the executor's memory (bdpt_settings)
    st.conn_q = 1.0f;
    st.naive_map = s.naive_map ? 1 : 0;
    return st;
}

std::string connection_map_error(const std::vector<uint8_t>& map, int width, int height,
                                 bool panoramic) {
    if (map.empty()) return "";
    if (map.size() != size_t(width) * size_t(height) * 2)
        return "connection_map must hold (N, M) for each of the film's " +
               std::to_string(width) + " x " + std::to_string(height) + " pixels";
    if (panoramic) return "connection_map is not available with a panoramic camera";
    for (size_t k = 0; k < map.size(); k += 2) {
        if (map[k] > 64 || map[k + 1] > 64 || (map[k] > 0 && map[k + 1] < 1))
            return "connection_map: N must be in [0, 64], M in [1, 64] where N > 0";
    }
    return "";
}

// The bidirectional iteration on the CPU executor (integrator/schedule_bdpt.h).
template bool wf::bidirectional_iteration<CpuExec>(CpuExec&, Wavefront<CpuExec>&,
                                                   const SceneView&, WavefrontStep&);

}  // namespace lantern
