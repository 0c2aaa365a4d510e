// Random-walk subsurface scattering in pt (docs/subsurface.md), the model of Cycles' Principled
// BSDF: at a hit on a material with Subsurface Weight W, pt_sss_choose sends the path under the
// surface with probability P (the rest of the base, 1 - W, stays a surface lobe); the walk stage
// pt_sss_walk then refracts in (rough GGX interface; Skin: half the entries diffuse), walks a
// homogeneous medium whose single-scattering albedo is inverted from the base colour and whose
// mean free path is Radius x Scale (one-sample MIS over RGB for distances, Henyey-Greenstein
// directions), and where it reaches a surface leaves through a white Lambert lobe there: next-
// event estimation and a cosine continuation. Host+device; rays through the executor's query.
// Run only where SceneView::has_subsurface; a path waiting for its walk has alive == 2.
#pragma once

#include "integrator/motion_stage.h"  // the walk at the path's time (motion blur)
#include "integrator/terminator.h"
#include "scene/medium.h"

namespace lantern {

constexpr int kSssMaxBounces = 256;       // scatterings before a walk is given up (lost)
constexpr int kSssSimilarityBounce = 9;   // after it: isotropic with reduced scattering
constexpr uint8_t kAliveSss = 2;          // PathState::alive: the walk stage has this path

// ---- Albedo inversion: the single-scattering albedo that makes a semi-infinite medium of
// anisotropy g reflect `albedo` (Chiang, Kutz, Burley 2016, extended to g by the fit Cycles
// uses: subsurface_random_walk_remap); sigma_t from the mean free path d ----
LANTERN_HD inline float sss_poly7(const float* c, float g) {
    float r = c[7];
    for (int k = 6; k >= 0; --k) r = r * g + c[k];
    return r;
}

LANTERN_HD inline void sss_remap(float albedo, float d, float g, float* sigma_t, float* alpha) {
    // the fit's six terms, each a polynomial (or 1 + c exp(polynomial)) of degree 7 in g
    const float ca[8] = {1.8260523782f, -1.28451056436f, -1.79904629312f, 9.19393289202f,
                         -22.8215585862f, 32.0234874259f, -23.6264803333f, 7.21067002658f};
    const float cb[8] = {0.0f, 31.1491581433f, -201.847017512f, 841.576016723f,
                         -2018.09288505f, 2731.71560286f, -1935.41424244f, 559.009054474f};
    const float cc[8] = {1.09686102424f, -0.394704063468f, 1.05258115941f, -8.83963712726f,
                         28.8643230661f, -46.8802913581f, 38.5402837518f, -12.7181042538f};
    const float cd[8] = {0.496310210422f, 0.360146581622f, -2.15139309747f, 17.8896899217f,
                         -55.2984010333f, 82.065982243f, -58.5106008578f, 15.8478295021f};
    const float ce[8] = {0.0f, 76.7316253952f, -594.356773233f, 2448.8834203f,
                         -5576.68528998f, 7116.60171912f, -4763.54467887f, 1303.5318055f};
    const float cf[8] = {2.40602999408f, -2.51814844609f, 9.18494908356f, -79.2191708682f,
                         259.082868209f, -403.613804597f, 302.85712436f, -87.4370473567f};
    const float A = sss_poly7(ca, g);
    const float B = 4.98511194385f + 0.127355959438f * expf(sss_poly7(cb, g));
    const float C = sss_poly7(cc, g);
    const float D = sss_poly7(cd, g);
    const float E = 4.23190299701f + 0.00310603949088f * expf(sss_poly7(ce, g));
    const float F = sss_poly7(cf, g);
    const float blend = sqrtf(sqrtf(albedo));
    const float a = (1.0f - blend) * A * powf(atanf(B * albedo), C) +
                    blend * D * powf(atanf(E * albedo), F);
    *alpha = clampf(a, 0.0f, 0.999999f);
    *sigma_t = 1.0f / (fmaxf(d, 1e-16f) * (1.0f - g));
}

// ---- The mean free path from Radius x Scale, as Cycles reads it: Random Walk takes
// radius / (4 pi); Skin scales it by sqrt(3 (1 - a')), a' the single-scattering albedo whose
// classical dipole (Jensen et al. 2001, boundary term of the IOR) reflects the base colour ----
LANTERN_HD inline float sss_dipole_rd(float a, float four_thirds_A) {
    const float s = sqrtf(3.0f * (1.0f - a));
    return 0.5f * a * (1.0f + expf(-four_thirds_A * s)) * expf(-s);
}

LANTERN_HD inline float sss_mean_free_path(const Material& m, float radius, float albedo) {
    if (!m.ss_skin) return radius * (0.25f * kInvPi);
    const float e = m.ss_ior, ie = 1.0f / e;
    const float fdr = -1.440f * ie * ie + 0.710f * ie + 0.668f + 0.0636f * e;
    const float k = (4.0f / 3.0f) * (1.0f + fdr) / (1.0f - fdr);
    float a;
    if (albedo < 1e-4f) {
        a = 0.0f;
    } else if (albedo >= 0.995f) {
        a = 0.999999f;
    } else {  // Rd grows with a: bisection
        float lo = 0.0f, hi = 1.0f;
        for (int it = 0; it < 12; ++it) {
            a = 0.5f * (lo + hi);
            if (sss_dipole_rd(a, k) < albedo) lo = a; else hi = a;
        }
    }
    return radius * sqrtf(3.0f * (1.0f - a));
}

// ---- The probability of the walk at a hit (wo local, +Z the shading normal on its side):
// the walk's share of the lobes' albedos, the same in pt_sss_choose and pt_sss_walk ----
LANTERN_HD inline float sss_pick_prob(const Material& m, float mu_o) {
    if (!(m.subsurface > 0.0f) || !(mu_o > 0.0f)) return 0.0f;
    const PrincipledWeights w = principled_weights(m);
    const float es = principled_spec_albedo(m, mu_o);
    const float lum = clampf(luminance(m.base_color), 0.05f, 1.0f);
    const float base = w.spec * (1.0f - es) * lum;
    const float q_walk = m.subsurface * base;
    const float q_rest = (1.0f - m.subsurface) * base + w.spec * es + w.metal + w.glass +
                         m.coat_weight * 0.5f + fminf(m.sheen_weight, 1.0f) * 0.1f;
    if (!(q_walk > 0.0f) || !(q_walk + q_rest <= kInf)) return 0.0f;
    if (!(q_rest > 0.0f)) return 1.0f;  // nothing else to choose
    // (a rest too small to move the float sum still gets its branch: unbiased for every P < 1)
    return fminf(q_walk / (q_walk + q_rest), 0.999999f);
}

// ---- At a shaded hit (after emission, before next-event estimation): true when the path
// goes under the surface (alive = kAliveSss; the walk stage takes it from there), false when
// it stays a surface path; either way the throughput carries 1 / the branch's probability ----
// (ng_l: the geometric normal in the shading frame; where the shading normal turns away from
// the viewer, the walk enters about the geometric normal: sss_entry_frame)
LANTERN_HD inline bool pt_sss_choose(const PathState& ps, int i, const Material& m, Vec3 wo,
                                     Vec3 ng_l, Rng& rng) {
    const float p = sss_pick_prob(m, wo.z > 0.0f ? wo.z : dot(wo, ng_l));
    if (!(p > 0.0f)) return false;
    if (rng.uniform() < p) {
        ps.throughput[i] = ps.throughput[i] * (1.0f / p);
        ps.alive[i] = kAliveSss;
        return true;
    }
    ps.throughput[i] = ps.throughput[i] * (1.0f / (1.0f - p));
    return false;
}

// ---- Entry: the direction into the surface (local frame, wo above). Random Walk refracts
// about a GGX normal of the surface's roughness with the subsurface IOR; Skin enters half the
// time by a cosine lobe, otherwise refracts with roughness 1. Like Cycles, the direction only:
// no interface weight (the base's weight carries the specular layer's share). ----
LANTERN_HD inline bool sss_entry(const Material& m, Vec3 wo, Vec2 u, Vec3* wi) {
    if (!(wo.z > 0.0f)) return false;
    float alpha = m.roughness * m.roughness;
    if (m.ss_skin) {
        if (u.x < 0.5f) {
            float pdf = 0.0f;
            Vec3 c = sample_cosine_hemisphere(Vec2{fminf(2.0f * u.x, 0.99999994f), u.y}, &pdf);
            *wi = Vec3{c.x, c.y, -c.z};
            return true;
        }
        u.x = fminf(2.0f * (u.x - 0.5f), 0.99999994f);
        alpha = 1.0f;
    }
    const Vec3 h = Ggx::isotropic(alpha).sample_visible(wo, u);
    const float neta = 1.0f / m.ss_ior;
    const float cos_h = dot(h, wo);
    const float arg = 1.0f - neta * neta * (1.0f - cos_h * cos_h);
    const float k = neta * cos_h - sqrtf(fmaxf(arg, 1e-14f));
    *wi = normalize(wo * (-neta) + h * k);
    return is_finite(*wi);
}

// ---- The entry's density q(wi | wo) of the direction sss_entry samples (solid angle, wo above):
// the refraction about a GGX visible normal (Walter et al. 2007's Jacobian; Skin: half that of
// roughness 1 and half a cosine lobe). A rough refraction may leave above the frame's plane: the
// caller's geometric test decides (sss_walk_path: below the geometric normal). The adjoint walk
// (lt_sss.h) evaluates it at its exit, with wi the reverse of the walk's last direction ----
LANTERN_HD inline float sss_entry_pdf(const Material& m, Vec3 wo, Vec3 wi) {
    if (!(wo.z > 0.0f)) return 0.0f;
    float alpha = m.roughness * m.roughness, share = 1.0f, pdf = 0.0f;
    if (m.ss_skin) {
        pdf = wi.z < 0.0f ? 0.5f * (-wi.z) * kInvPi : 0.0f;
        share = 0.5f;
        alpha = 1.0f;
    }
    const float eta = m.ss_ior;
    Vec3 h = wo + wi * eta;  // wo + eta wi lies along -h for a refraction into the medium
    if (!(length_sq(h) > 1e-20f)) return pdf;
    h = normalize(h);
    if (h.z < 0.0f) h = -h;
    const float wo_h = dot(wo, h), wi_h = dot(wi, h);
    if (!(wo_h > 0.0f) || !(wi_h < 0.0f)) return pdf;
    const float denom = sqr(wi_h + wo_h / eta);
    const float q = Ggx::isotropic(alpha).pdf_visible(wo, h) * (-wi_h) / denom;
    return is_finite(q) ? pdf + share * q : pdf;
}

// ---- beta times the walk's weight at the entry for the view wo (local, above): the base's
// weight under the layers above it (coat, sheen), the specular layer's 1 - E_s(mu_o) and W; the
// base colour enters through the medium's albedo (sss_medium). coat_n: the hit's coat normal ----
LANTERN_HD inline Vec3 sss_entry_weight(const Material& m, Vec3 coat_n, Vec3 wo, Vec3 beta) {
    const PrincipledWeights pw = principled_weights(m);
    const Vec3 below = principled_below_coat(m, wo.z, coat_cos(m, coat_n, wo));
    const float base = pw.spec * (1.0f - principled_spec_albedo(m, wo.z)) * m.subsurface;
    return beta * below * base;
}

// ---- The walk's medium: the single-scattering albedo per channel inverted from the base colour
// (clamped to [0, 1], as Cycles), sigma_t from the mean free path; a channel whose albedo falls
// below 0.2 walks at 0.2 with its throughput scaled by low (as Cycles); after
// kSssSimilarityBounce scatterings the reduced coefficients (similarity theory, isotropic) ----
struct SssMedium {
    Vec3 sigma_t, sigma_s, sigma_t_sim, sigma_s_sim, alpha, low;
    float g;
};

LANTERN_HD inline SssMedium sss_medium(const Material& m) {
    SssMedium md;
    md.g = m.ss_anisotropy;
    float st3[3], al3[3], low[3];
    for (int c = 0; c < 3; ++c) {
        const float albedo = clampf(m.base_color[c], 0.0f, 1.0f);
        sss_remap(albedo, sss_mean_free_path(m, m.ss_radius[c], albedo), md.g, &st3[c], &al3[c]);
        low[c] = 1.0f;
        if (al3[c] < 0.2f) {  // a low albedo walks as 0.2 with the throughput scaled (as Cycles)
            low[c] = al3[c] / 0.2f;
            al3[c] = 0.2f;
        }
    }
    md.low = Vec3{low[0], low[1], low[2]};
    md.sigma_t = Vec3{st3[0], st3[1], st3[2]};
    md.alpha = Vec3{al3[0], al3[1], al3[2]};
    md.sigma_s = md.sigma_t * md.alpha;
    md.sigma_s_sim = md.sigma_s * (1.0f - md.g);
    md.sigma_t_sim = md.sigma_t - md.sigma_s + md.sigma_s_sim;
    return md;
}

// ---- The walk in medium md from o along dir (the first direction, already sampled) with
// throughput beta (low included): distances from one channel chosen by throughput x albedo,
// weighted by the pmf-weighted mean of the channels' pdfs (one-sample MIS), Henyey-Greenstein
// directions, at most kSssMaxBounces scatterings. Where it reaches a surface:
// exit(prim, uv, dir, beta) with the direction that found it; a strand, a lost walk: nothing.
// Shared by the camera side's walk (sss_walk_path) and the adjoint walk (lt_sss.h). ----
template <class Rays, class Kind, class Exit>
LANTERN_HD inline void sss_walk_medium(const SceneView& s, const Rays& rays, Kind kind,
                                       const SssMedium& md, Vec3 o, Vec3 dir, Vec3 beta,
                                       Rng& rng, float time, const Exit& exit) {
    for (int b = 0; b < kSssMaxBounces; ++b) {
        const bool sim = b > kSssSimilarityBounce;
        const Vec3 st_b = sim ? md.sigma_t_sim : md.sigma_t;
        const Vec3 ss_b = sim ? md.sigma_s_sim : md.sigma_s;
        if (b > 0) {
            float pdf_w = 0.0f;  // the phase function's own sample: weight 1
            dir = hg_sample(sim ? 0.0f : md.g, dir, rng.uniform2(), &pdf_w);
        }
        const Vec3 pmf = medium_channel_pmf(beta * md.alpha);
        const float u_c = rng.uniform();
        const int c = u_c < pmf.x ? 0 : (u_c < pmf.x + pmf.y ? 1 : 2);
        const float t_s = -log1pf(-fminf(rng.uniform(), 0.99999994f)) / st_b[c];
        const auto hit = rays.closest(Ray{o, dir, 0.0f, t_s, time}, kind);
        const bool out = hit.prim >= 0 && hit.t < t_s;
        const float t = out ? hit.t : t_s;
        const Vec3 tr{expf(-st_b.x * t), expf(-st_b.y * t), expf(-st_b.z * t)};
        const Vec3 pdf = out ? tr : st_b * tr;
        const float denom = dot(pmf, pdf);
        if (!(denom > 0.0f)) break;
        beta = beta * (out ? tr : ss_b * tr) * (1.0f / denom);
        if (!is_finite(beta)) break;
        if (out) {
            if (hit.prim >= s.num_triangles) break;  // a strand inside the mesh: the walk ends
            exit(int(hit.prim), hit.uv, dir, beta);
            break;
        }
        o = o + dir * t;
        if (!(max_component(beta) > 1e-7f)) break;
    }
}

// ---- The exit at p (normals ng, ns outward): next-event estimation with a white Lambert lobe,
// then a cosine continuation; beta is the walk's throughput, depth the exit vertex's ----
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void pt_sss_exit(const SceneView& s, const PathState& ps, const PtSettings& st,
                                   int i, int tri, Vec3 p, Vec3 ng, Vec3 ns, Vec3 beta, int depth,
                                   Rng& rng) {
    if (depth >= st.max_depth) return;
    // the terminator (integrator/terminator.h) and lamps without shadows as at pt_shade's
    // surfaces
    const Vec3 n_pick = (terminator_cutoff(s, tri) > 0.0f || s.light_rays) &&
                                dot(ns, ng) < 0.99999f
                            ? vec3(0.0f)
                            : light_pick_normal(s, tri, ng);
    const Vec2 u_pick = rng.uniform2();
    const Vec2 u_light = rng.uniform2();
    const LightPick pick = light_pick(s, p, n_pick, u_pick.x);
    if (pick.pmf > 0.0f) {
        const float time = s.motion.num_objects > 0 ? motion_time(rng) : 0.0f;  // the path's
        LightSample ls = sample_light(s, s.lights[pick.light], p, u_light, time);
        if ((pick.light == s.world_light || s.lights[pick.light].of_world) &&
            !(s.world_rays & kWorldDiffuse))
            ls.valid = false;  // the world hidden from diffuse rays lights nothing here
        if (pt_light_hidden(s, pick.light, kRayKindSubsurface)) ls.valid = false;
        if (!pt_light_links(s, pick.light, pt_receiver_set(s, tri))) ls.valid = false;
        const float cos_i = dot(ls.wi, ns);
        const float pdf_light = pick.pmf * ls.pdf_w;
        const bool geo_side = dot(ls.wi, ng) > 0.0f;  // else the terminator's alone
        const bool unshadowed = pt_lamp_unshadowed(s, pick.light);  // any side, MIS (pt.h)
        if (ls.valid && !is_black(ls.le) && cos_i > 0.0f &&
            (geo_side || terminator_cutoff(s, tri) > 0.0f || unshadowed) && pdf_light > 0.0f) {
            const float pdf_bsdf = cos_i * kInvPi;
            const float w = ls.delta || (!geo_side && !unshadowed) ||
                                    pt_shadow_linked(s, pick.light)
                                ? 1.0f
                                : power_heuristic(pdf_light, pdf_bsdf);
            const Vec3 so = offset_ray_origin(terminator_origin(s, tri, p, ng, ns, ls.wi, time), ng,
                                              ls.wi, s.offset_scale);
            Vec3 sd = ls.wi;
            float tmax = kInf;
            if (ls.dist < kInf) {  // shortened at both ends, as pt_shade's
                Vec3 target = ls.p_light;
                if (!is_black(ls.n_light))
                    target = offset_ray_origin(target, ls.n_light, -ls.wi, s.offset_scale);
                const Vec3 seg = target - so;
                const float len = length(seg);
                if (len > 0.0f) sd = seg / len;
                tmax = len * (1.0f - 1e-4f);
            }
            ps.shadow_o[i] = so;
            ps.shadow_d[i] = sd;
            ps.shadow_tmax[i] = tmax;
            ps.shadow_contrib[i] = beta * ls.le * (kInvPi * cos_i * w / pdf_light);
            ps.shadow_valid[i] = 1;
            if (s.light_blockers && ps.shadow_light) {  // shadow linking: pt_light_linking.h
                ps.shadow_light[i] = pick.light;
                pt_keep_shadow_mis(ps, i,
                                   pt_shadow_linked(s, pick.light) && !ls.delta && geo_side &&
                                           pt_linked_mis_pt(s)
                                       ? power_heuristic(pdf_light, pdf_bsdf)
                                       : 1.0f);
            }
            if (s.num_media > 0) ps.shadow_medium[i] = ps.medium[i];
            if (unshadowed) {  // Cast Shadow off: no shadow ray
                add_radiance(ps, i, ps.shadow_contrib[i]);
                ps.shadow_valid[i] = 0;
            }
        }
    }
    float pdf_w = 0.0f;
    const Vec3 c = sample_cosine_hemisphere(rng.uniform2(), &pdf_w);
    const Vec3 wi = Frame::from_normal(ns).to_world(c);
    if (!(pdf_w > 0.0f) || !(dot(wi, ng) > 0.0f)) return;
    if (!russian_roulette(beta, depth, st.rr_depth, rng) || !(max_component(beta) > 0.0f) ||
        !is_finite(beta))
        return;
    ps.throughput[i] = beta;
    ps.depth[i] = depth + 1;
    if (s.world_rays != kWorldRaysAll && ps.world_hidden)
        ps.world_hidden[i] = (s.world_rays & kWorldDiffuse) ? 0 : 1;
    pt_set_ray_kind(s, ps, i, kRayKindSubsurface);
    pt_set_receiver(s, ps, i, tri);
    set_next_ray(ps, i, p, ng, wi, pdf_w, s.offset_scale);
    if (s.light_tree_on || s.num_media > 0 || s.tri_rays) {  // (pt_light_pdf_w)
        ps.prev_p[i] = p;
        ps.prev_n[i] = n_pick;
    }
}

// ---- The entry's frame for the view w (world; h's normals facing it): the shading normal's,
// or where that turns away from the viewer (smooth normals at a silhouette) the geometric
// normal's (Cycles bends N there instead). The camera side's walk (sss_walk_path, and the
// split's r in bdpt_sss.h / bdpt_sss_light.h) and the adjoint exit's lobe (lt_sss_exit_f) ----
LANTERN_HD inline Frame sss_entry_frame(const SurfaceHit& h, Vec3 w) {
    const Frame shading = h.frame();
    return shading.to_local(w).z > 0.0f ? shading : Frame::from_normal(h.ng);
}

// ---- The material at a walk's entry h (triangle tri, barycentrics uv, reached along d),
// resolved into scratch as the shade stage's (the camera side's and lt's entries) ----
LANTERN_HD inline const Material& sss_entry_material(const SceneView& s, const SurfaceHit& h,
                                                     int tri, Vec2 uv, Vec3 d,
                                                     MaterialScratch& scratch) {
    return material_at_point(
        s, s.tri_material[tri], [h, tri, uv, wo = -d] { return shade_point(h, tri, uv, wo); },
        scratch);
}

// The walk's start (sss_walk_path's): the entry's medium, first direction, origin and
// throughput; false: no walk. Out of line on the device (LANTERN_DEVICE_NOINLINE): the entry's
// material evaluation keeps its locals out of the walk kernel's frame, which holds the walk's
// ray query (docs/cuda_backend.md "Strands and motion blur").
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool sss_walk_start(const SceneView& s, int tri, Vec2 uv, Vec3 d, Vec3 beta_in,
                                      Rng& rng, float time, SssMedium* md, Vec3* o, Vec3* dir,
                                      Vec3* beta) {
    const SurfaceHit h = surface_at_time(s, tri, uv, d, time);
    MaterialScratch scratch;
    const Material& m = sss_entry_material(s, h, tri, uv, d, scratch);
    const Frame frame = sss_entry_frame(h, -d);
    const Vec3 wo = frame.to_local(-d);
    // the walk's weight at the entry (sss_entry_weight); the caller has divided by the walk's
    // probability
    const Vec3 beta0 = sss_entry_weight(m, h.coat_n, wo, beta_in);
    Vec3 wi_l;
    const bool entered = sss_entry(m, wo, rng.uniform2(), &wi_l);
    *dir = frame.to_world(wi_l);
    if (!entered || !(dot(*dir, h.ng) < 0.0f) || is_black(beta0)) return false;
    *md = sss_medium(m);
    *o = offset_ray_origin(h.p, h.ng, *dir, s.offset_scale);
    *beta = beta0 * md->low;
    return true;
}

// ---- The walk from a hit: the entry at triangle tri (barycentrics uv, reached along d), the
// walk, and at its end exit(tri, uv, dir, p, ng, ns, beta, depth): the exit's triangle,
// barycentrics, the direction that found it (pt_surface orients the normals against it, so the
// exit's are negated: they face along dir, out of the walk), the exit point, its outward
// normals, the throughput and the exit vertex's depth, the entry's (Cycles' subsurface_bounce
// and subsurface_scatter advance no bounce: the exit shades at the entry's, so Max Bounces 0
// keeps it lit; D41). Every hit walks, after any bounce, as Cycles 5.0's Random Walk does
// (only its Christensen-Burley turns into a Lambert lobe after a diffuse ancestor; a Lambert
// lobe here trapped light in closed parts inside the medium: docs/subsurface.md). beta_in: the
// path's throughput with the walk's probability divided out. Shared by pt and the
// bidirectional camera paths (bdpt_sss.h). Rays: the executor's ray query
// (closest(r, kind)). time: the path's shutter time (motion blur: the entry, every ray of the
// walk and the exit see the meshes there). ----
template <class Rays, class Kind, class Exit>
LANTERN_HD inline void sss_walk_path(const SceneView& s, const Rays& rays, Kind kind, int tri,
                                     Vec2 uv, Vec3 d, Vec3 beta_in, int depth, Rng& rng,
                                     float time, const Exit& exit) {
    SssMedium md;
    Vec3 o, dir, beta;
    if (!sss_walk_start(s, tri, uv, d, beta_in, rng, time, &md, &o, &dir, &beta)) return;
    sss_walk_medium(s, rays, kind, md, o, dir, beta, rng, time,
                    [&](int prim, Vec2 huv, Vec3 last, Vec3 beta) {
                        // (faces inside: negated)
                        const SurfaceHit x = surface_at_time(s, prim, huv, last, time);
                        exit(prim, huv, last, x.p, -x.ng, -x.ns, beta, depth);
                    });
}

// ---- The walk stage, after pt_shade on the same queue: for a path with alive == kAliveSss,
// the entry at its hit (the hit and the ray are still those pt_shade shaded), the walk, the
// exit. Rays: the executor's ray query (closest(r, kind)), kind its indirect rays' RayKind. ----
template <class Rays, class Kind>
LANTERN_HD inline void pt_sss_walk(const SceneView& s, const Rays& rays, Kind kind,
                                   const PathState& ps, const PtSettings& st, int i) {
    if (ps.alive[i] != kAliveSss) return;
    ps.alive[i] = 0;
    Rng rng = ps.rng[i];
    const float time = s.motion.rays_timed() ? motion_time(rng) : 0.0f;  // (the path's)
    sss_walk_path(s, rays, kind, ps.hit_prim[i], ps.hit_uv[i], ps.ray_d[i], ps.throughput[i],
                  ps.depth[i], rng, time,
                  [&](int tri, Vec2, Vec3, Vec3 p, Vec3 ng, Vec3 ns, Vec3 beta, int depth) {
                      pt_sss_exit(s, ps, st, i, tri, p, ng, ns, beta, depth, rng);
                  });
    ps.rng[i] = rng;
}

}  // namespace lantern
