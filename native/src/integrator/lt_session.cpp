// Integrator "lt": what it cannot render, and its schedule (integrator/schedule_lt.h: generate
// light paths, then per bounce test the camera segments and splat the visible ones in slot
// order, so the image has the same bits whatever the thread count) on the CPU executor.
#include <cmath>
#include <stdexcept>
#include <string>

#include "backend/cpu/cpu_exec.h"
#include "integrator/schedule_lt.h"
#include "integrator/session.h"

namespace lantern {

namespace {

// Squared distance from p to triangle abc (closest point by regions: Ericson, Real-Time
// Collision Detection 5.1.5).
float dist2_to_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const float d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) return length_sq(p - a);
    const Vec3 bp = p - b;
    const float d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3) return length_sq(p - b);
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return length_sq(p - (a + ab * (d1 / (d1 - d3))));
    const Vec3 cp = p - c;
    const float d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6) return length_sq(p - c);
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return length_sq(p - (a + ac * (d2 / (d2 - d6))));
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
        return length_sq(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const float denom = 1.0f / (va + vb + vc);
    return length_sq(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// The first mesh with a triangle inside the ball (c, r), or "".
std::string mesh_inside_ball(const SceneInput& in, Vec3 c, float r) {
    for (const MeshInput& m : in.meshes) {
        auto v = [&](uint32_t k) {
            return vec3(m.positions[3 * k], m.positions[3 * k + 1], m.positions[3 * k + 2]);
        };
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3)
            if (dist2_to_triangle(c, v(m.indices[t]), v(m.indices[t + 1]),
                                  v(m.indices[t + 2])) < r * r)
                return m.name.empty() ? std::string("a mesh") : "mesh '" + m.name + "'";
    }
    return "";
}

}  // namespace

// Soft-falloff point/spot lights: lt's paths are lines through the light's ball
// (soft_light_path.h), exact unless a triangle lies inside the ball; in scenes with media (the
// test of HostScene::build_media) the lines are not built (bdpt, lvc and cis start their route
// from the centre there, soft_light_medium.h; lt has no camera-side technique to pair with it).
// lt refuses both cases.
void check_light_tracing(const SceneInput& in) {
    bool media = in.world_medium >= 0;
    for (const MaterialInput& mi : in.materials) media = media || mi.medium >= 0 || mi.volume_only;
    for (size_t k = 0; k < in.lights.size(); ++k) {
        const LightInput& l = in.lights[k];
        if (!((l.type == "point" || l.type == "spot") && l.soft_falloff &&
              std::isfinite(l.radius) && l.radius > 0.0f))
            continue;
        const Vec3 c = l.type == "point" ? l.position
                                         : vec3(l.to_world[3], l.to_world[7], l.to_world[11]);
        const std::string inside = media ? "" : mesh_inside_ball(in, c, l.radius);
        if (!media && inside.empty()) continue;
        throw std::invalid_argument(
            "integrator 'lt' cannot trace light from scene.lights[" + std::to_string(k) + "] (" +
            l.type + ", radius " + std::to_string(l.radius) + " m, soft_falloff on): " +
            (media ? std::string("its light paths are not built in scenes with media")
                   : inside + " lies within its radius, where lt's lines would miss light") +
            " (docs/lvc_notes.md); set soft_falloff off (a sphere light) or radius 0");
    }
}

// The light tracer's chunk on the CPU executor (integrator/schedule_lt.h).
template void wf::lt_chunk<CpuExec>(CpuExec&, Wavefront<CpuExec>&, const SceneView,
                                    WavefrontStep&, int64_t, int);

}  // namespace lantern
