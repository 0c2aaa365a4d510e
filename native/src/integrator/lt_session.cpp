// Integrator "lt": what it cannot render, and its schedule (integrator/schedule_lt.h: generate
// light paths, then per bounce test the camera segments and splat the visible ones in slot
// order, so the image has the same bits whatever the thread count) on the CPU executor.
#include <cmath>
#include <stdexcept>

#include "backend/cpu/cpu_exec.h"
#include "integrator/schedule_lt.h"
#include "integrator/session.h"

namespace lantern {

void check_light_tracing(const SceneInput& in) {
    for (size_t k = 0; k < in.lights.size(); ++k) {
        const LightInput& l = in.lights[k];
        if ((l.type == "point" || l.type == "spot") && l.soft_falloff && std::isfinite(l.radius) &&
            l.radius > 0.0f) {
            throw std::invalid_argument(
                "integrator 'lt' cannot trace light from scene.lights[" + std::to_string(k) +
                "] (" + l.type + ", radius " + std::to_string(l.radius) +
                " m, soft_falloff on): its disk faces each shaded point, and light paths from "
                "its centre never reach the points that see the disk but not the centre "
                "(penumbrae; bdpt, lvc and cis render those from the camera side, "
                "docs/lvc_notes.md); set soft_falloff off (a sphere light) or radius 0");
        }
    }
}

// The light tracer's chunk on the CPU executor (integrator/schedule_lt.h).
template void wf::lt_chunk<CpuExec>(CpuExec&, Wavefront<CpuExec>&, const SceneView,
                                    WavefrontStep&, int64_t, int);

}  // namespace lantern
