// Host side of principled subsurface scattering (integrator/pt_sss.h): MaterialInput's
// Subsurface Weight, Radius x Scale, IOR, Anisotropy and method into Material's ss_* fields,
// with Cycles' clamps (IOR [1.01, 3.8], anisotropy [0, 0.9]) and a message for bad input.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace lantern {

// The largest mean free path kept (metres): beyond it the walk leaves in one step anyway, and
// 1 / radius stays a normal float.
constexpr float kSubsurfaceMaxRadius = 1e6f;
// Below this (Cycles' BSSRDF_MIN_RADIUS) a channel does not scatter under the surface.
constexpr float kSubsurfaceMinRadius = 1e-8f;

inline void set_material_subsurface(Material& m, const MaterialInput& mi, size_t k,
                                    std::vector<std::string>& warnings) {
    m.subsurface = 0.0f;
    m.ss_radius = Vec3{0.0f, 0.0f, 0.0f};
    m.ss_ior = 1.4f;
    m.ss_anisotropy = 0.0f;
    m.ss_skin = 0u;
    const std::string who = "material " + std::to_string(k) + " ('" + mi.name + "')";
    if (mi.subsurface_method != "random_walk" && mi.subsurface_method != "random_walk_skin")
        throw std::invalid_argument(who + ": unknown subsurface_method '" + mi.subsurface_method +
                                    "' (random_walk, random_walk_skin)");
    const float w = mi.subsurface_weight;
    if (!(w > 0.0f)) return;  // NaN too
    float r[3], r_max = 0.0f;
    bool clamped = false;
    for (int c = 0; c < 3; ++c) {
        float v = mi.subsurface_radius[c];
        if (!std::isfinite(v) && !(v > 0.0f)) v = 0.0f;  // NaN, -inf
        v = std::max(v, 0.0f);
        if (v > kSubsurfaceMaxRadius) {
            v = kSubsurfaceMaxRadius;
            clamped = true;
        }
        r[c] = v;
        r_max = std::max(r_max, v);
    }
    if (!(r_max >= kSubsurfaceMinRadius)) {
        warnings.push_back(who + ": Subsurface Radius x Scale is 0: rendered as the diffuse "
                                 "base, as Cycles does");
        return;
    }
    if (clamped)
        warnings.push_back(who + ": Subsurface Radius x Scale above 1e6 m is clamped there");
    for (int c = 0; c < 3; ++c) {
        // a channel with no radius beside others: a tiny one (it leaves next to the entry)
        if (r[c] < kSubsurfaceMinRadius) r[c] = std::max(r_max * 1e-4f, kSubsurfaceMinRadius);
    }
    m.subsurface = std::min(w, 1.0f);
    m.ss_radius = Vec3{r[0], r[1], r[2]};
    const float ior = std::isfinite(mi.subsurface_ior) ? mi.subsurface_ior : 1.4f;
    m.ss_ior = std::min(std::max(ior, 1.01f), 3.8f);
    const float g = std::isfinite(mi.subsurface_anisotropy) ? mi.subsurface_anisotropy : 0.0f;
    m.ss_anisotropy = std::min(std::max(g, 0.0f), 0.9f);
    m.ss_skin = mi.subsurface_method == "random_walk_skin" ? 1u : 0u;
}

// The reason a scene renders with pt only because of subsurface scattering, or "".
inline std::string subsurface_reason(const SceneInput& in) {
    for (const MaterialInput& m : in.materials) {
        if (m.type != "principled" || !(m.subsurface_weight > 0.0f)) continue;
        const Vec3 r = m.subsurface_radius;
        if (std::max(std::max(r.x, r.y), r.z) >= kSubsurfaceMinRadius)
            return "subsurface scattering (material '" + m.name + "')";
    }
    return "";
}

// The reason lt, bdpt, lvc and cis hand a scene to pt (session.cpp): a material with subsurface
// scattering and a volume of its own, or "". Their walks leave into the medium their path arrived
// in (pt's rule: media around the object are exact); a volume inside the walking mesh would be
// crossed at the entry and its medium kept by the walk, which their exits do not follow.
inline std::string subsurface_volume_reason(const SceneInput& in) {
    for (const MaterialInput& m : in.materials) {
        if (m.type != "principled" || !(m.subsurface_weight > 0.0f) || m.medium < 0) continue;
        const Vec3 r = m.subsurface_radius;
        if (std::max(std::max(r.x, r.y), r.z) >= kSubsurfaceMinRadius)
            return "subsurface scattering in a mesh with a volume inside (material '" + m.name +
                   "')";
    }
    return "";
}

// The reason lt hands a scene to pt (session.cpp): a material walking by Random Walk (not Skin),
// or "". lt's adjoint walk (integrator/lt_sss.h) leaves through the entry's rough refraction
// lobe: with short walks in a hollow lit from inside its estimates have tails so heavy that
// renders of 16 k samples a pixel read 15-30 % low (it agrees with pt only at about 10 x that:
// docs/subsurface.md, "The adjoint walk"); Skin's half-cosine entry keeps the weights tame.
inline std::string subsurface_random_walk_reason(const SceneInput& in) {
    for (const MaterialInput& m : in.materials) {
        if (m.type != "principled" || !(m.subsurface_weight > 0.0f) ||
            m.subsurface_method == "random_walk_skin")
            continue;
        const Vec3 r = m.subsurface_radius;
        if (std::max(std::max(r.x, r.y), r.z) >= kSubsurfaceMinRadius)
            return "Random Walk subsurface (material '" + m.name + "')";
    }
    return "";
}

}  // namespace lantern
