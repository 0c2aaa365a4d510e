// The path tracer's stages (integrator "pt"): unidirectional paths with next-event estimation,
// combined by the power heuristic. Each stage is one host+device function over one path slot;
// the backend launches them over queues and traces the rays they leave in the slots.
#pragma once

#include "bsdf/material.h"
#include "core/offset.h"
#include "integrator/camera.h"
#include "integrator/path_state.h"
#include "scene/lights.h"

namespace lantern {

// ---- Generate: slot i starts path `path` of the iteration, in pixel path / spp_per_iteration ----
LANTERN_HD inline void pt_generate(const SceneView& s, const PathState& ps, const PtSettings& st,
                                   int i, int64_t path) {
    Rng rng = Rng::for_path(st.seed, st.iteration, uint64_t(path));
    Ray r = generate_camera_ray(s.camera, int(path / st.spp_per_iteration), rng);
    ps.ray_o[i] = r.o;
    ps.ray_d[i] = r.d;
    ps.ray_tmin[i] = r.tmin;
    ps.ray_tmax[i] = r.tmax;
    ps.throughput[i] = vec3(1.0f);
    ps.radiance[i] = vec3(0.0f);
    ps.rng[i] = rng;
    ps.depth[i] = 1;
    ps.prev_pdf_w[i] = 0.0f;
    ps.alive[i] = 1;
    ps.dropped[i] = 0;
    ps.shadow_valid[i] = 0;
}

// MIS weight of emission found by a BSDF-sampled ray (depth > 1); camera rays and rays from a
// delta lobe (prev_pdf_w 0: next-event estimation cannot find that light) take it all.
LANTERN_HD inline float pt_emission_weight(const PathState& ps, int i, float light_pdf) {
    if (ps.depth[i] <= 1 || !(ps.prev_pdf_w[i] > 0.0f)) return 1.0f;
    return power_heuristic(ps.prev_pdf_w[i], light_pdf);
}

// ---- Lights along the segment: lights are not opaque; a ray collects every light it crosses ----
LANTERN_HD inline void pt_collect_lights(const SceneView& s, const PathState& ps, int i, Vec3 o,
                                         Vec3 d, float tmin, float tmax) {
    bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_hittable_lights; ++k) {
        const Light& l = s.lights[s.hittable_lights[k]];
        if (camera && !l.visible_camera) continue;
        LightHit h = intersect_light(l, o, d, tmin, tmax);
        if (!h.hit || is_black(h.le)) continue;
        float pdf = l.pick_pdf * light_pdf_w(l, o, d, h.t, h.n);
        add_radiance(ps, i, ps.throughput[i] * h.le * pt_emission_weight(ps, i, pdf));
    }
}

// ---- Miss: world background and the sun's disk ----
LANTERN_HD inline void pt_shade_miss(const SceneView& s, const PathState& ps, int i, Vec3 d) {
    bool camera = ps.depth[i] <= 1;
    for (int k = 0; k < s.num_miss_lights; ++k) {
        const Light& l = s.lights[s.miss_lights[k]];
        if (l.type == kLightWorld) {
            float pdf = l.pick_pdf * light_pdf_w(l, vec3(0.0f), d, kInf, vec3(0.0f));
            add_radiance(ps, i, ps.throughput[i] * l.radiance * pt_emission_weight(ps, i, pdf));
        } else if (l.type == kLightSun && l.cos_sun < 1.0f && !camera) {
            if (dot(d, -l.direction) < l.cos_sun) continue;
            float pdf = l.pick_pdf * light_pdf_w(l, vec3(0.0f), d, kInf, vec3(0.0f));
            add_radiance(ps, i, ps.throughput[i] * l.radiance * pt_emission_weight(ps, i, pdf));
        }
    }
}

struct SurfaceHit {
    Vec3 p;
    Vec3 ng;    // geometric normal, facing the incoming ray
    Vec3 ns;    // shading normal, same hemisphere as ng
    bool front; // the ray arrived on the triangle's front (counter-clockwise) side
};

// A direction leaving a surface is usable when the geometric and the shading normal agree on
// its side (reflection or transmission); otherwise light would leak through the shading normal.
LANTERN_HD inline bool sides_agree(Vec3 w, Vec3 ng, Vec3 ns) {
    return dot(w, ng) * dot(w, ns) > 0.0f;
}

LANTERN_HD inline SurfaceHit pt_surface(const SceneView& s, int tri, Vec2 uv, Vec3 d) {
    Vec3 a = triangle_vertex(s, tri, 0), b = triangle_vertex(s, tri, 1),
         c = triangle_vertex(s, tri, 2);
    float w0 = 1.0f - uv.x - uv.y;
    SurfaceHit h;
    h.p = a * w0 + b * uv.x + c * uv.y;
    h.ng = normalize(cross(b - a, c - a));
    h.front = dot(h.ng, d) <= 0.0f;
    if (!h.front) h.ng = -h.ng;
    h.ns = h.ng;
    if (s.normals) {
        const uint32_t* idx = s.indices + 3 * tri;
        Vec3 n = s.normals[idx[0]] * w0 + s.normals[idx[1]] * uv.x + s.normals[idx[2]] * uv.y;
        if (is_finite(n) && length_sq(n) > 1e-12f) {
            n = normalize(n);
            h.ns = dot(n, h.ng) < 0.0f ? -n : n;
        }
    }
    return h;
}

// ---- Shade: emission, next-event estimation (a shadow ray), BSDF sampling, roulette ----
LANTERN_HD inline void pt_shade(const SceneView& s, const PathState& ps, const PtSettings& st,
                                int i) {
    Vec3 o = ps.ray_o[i], d = ps.ray_d[i];
    float t_hit = ps.hit_t[i];
    int tri = ps.hit_prim[i];
    ps.shadow_valid[i] = 0;
    ps.alive[i] = 0;
    pt_collect_lights(s, ps, i, o, d, ps.ray_tmin[i], tri >= 0 ? t_hit : ps.ray_tmax[i]);
    if (tri < 0) {  // past the far clip plane too: the background shows, as in Cycles
        pt_shade_miss(s, ps, i, d);
        return;
    }
    SurfaceHit h = pt_surface(s, tri, ps.hit_uv[i], d);
    const Material& m = s.materials[s.tri_material[tri]];
    if (!is_black(m.emission)) {
        float pdf = 0.0f;
        int li = s.tri_light ? s.tri_light[tri] : -1;
        if (li >= 0) {
            const Light& l = s.lights[li];
            pdf = l.pick_pdf * light_pdf_w(l, o, d, t_hit, h.ng);
        }
        add_radiance(ps, i, ps.throughput[i] * m.emission * pt_emission_weight(ps, i, pdf));
    }
    int depth = ps.depth[i];
    if (depth >= st.max_depth) return;

    Frame frame = Frame::from_normal(h.ns);
    Vec3 wo = frame.to_local(-d);
    Rng rng = ps.rng[i];

    // next-event estimation
    const bool delta_material = material_is_delta(m);
    Vec2 u_pick = rng.uniform2();
    Vec2 u_light = rng.uniform2();
    if (s.num_lights > 0) {
        int li = sample_cdf(s.light_cdf, s.num_lights, u_pick.x);
        const Light& l = s.lights[li];
        LightSample ls = sample_light(s, l, h.p, u_light);
        if (ls.valid && !delta_material && sides_agree(ls.wi, h.ng, h.ns) && !is_black(ls.le)) {
            BsdfEval e = material_eval(m, h.front, wo, frame.to_local(ls.wi), Transport::Radiance);
            float pdf_light = l.pick_pdf * ls.pdf_w;
            if (e.pdf_fwd_w > 0.0f && pdf_light > 0.0f) {
                float w = ls.delta ? 1.0f : power_heuristic(pdf_light, e.pdf_fwd_w);
                float cos_i = fabsf(dot(ls.wi, h.ns));
                Vec3 c = ps.throughput[i] * e.f * ls.le * (cos_i * w / pdf_light);
                // Shortened at both ends: from the offset origin to the offset point on the
                // light, aimed between the two offset points (aiming along wi from the un-offset
                // point ends behind a light seen at a grazing angle, and the ray hits the light).
                Vec3 so = offset_ray_origin(h.p, h.ng, ls.wi, s.offset_scale);
                Vec3 sd = ls.wi;
                float tmax = kInf;
                if (ls.dist < kInf) {
                    Vec3 target = ls.p_light;
                    if (!is_black(ls.n_light)) target = offset_ray_origin(target, ls.n_light, -ls.wi, s.offset_scale);
                    Vec3 seg = target - so;
                    float len = length(seg);
                    if (len > 0.0f) sd = seg / len;
                    tmax = len * (1.0f - 1e-4f);
                }
                ps.shadow_o[i] = so;
                ps.shadow_d[i] = sd;
                ps.shadow_tmax[i] = tmax;
                ps.shadow_contrib[i] = c;
                ps.shadow_valid[i] = 1;
            }
        }
    }

    // continue the path
    Vec2 u_dir = rng.uniform2();
    BsdfSample bs = material_sample(m, h.front, wo, Vec3{u_dir.x, u_dir.y, rng.uniform()},
                                    Transport::Radiance);
    Vec3 wi = frame.to_world(bs.wi);
    if (bs.valid && sides_agree(wi, h.ng, h.ns)) {
        Vec3 beta = ps.throughput[i] * bs.weight;
        if (russian_roulette(beta, depth, st.rr_depth, rng) && max_component(beta) > 0.0f &&
            is_finite(beta)) {
            ps.throughput[i] = beta;
            ps.depth[i] = depth + 1;
            set_next_ray(ps, i, h.p, h.ng, wi, bs.delta ? 0.0f : bs.pdf_fwd_w,
                         s.offset_scale);
        }
    }
    ps.rng[i] = rng;
}

// ---- Shadow result: the backend reports whether the segment was free ----
LANTERN_HD inline void pt_shadow_result(const PathState& ps, int i, bool occluded) {
    if (!occluded) add_radiance(ps, i, ps.shadow_contrib[i]);
}

}  // namespace lantern
