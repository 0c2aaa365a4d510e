// Light selection for next-event estimation: a light BVH with power, bounds and an orientation
// cone per node (Conty Estevez & Kulla 2018), distant lights (sun, world) beside it, picked with
// one uniform number at a shading point (p, n); light_pick_pmf is the exact probability of the
// same choice, for MIS. Scenes built without a tree (one light) pick from the global power CDF.
#pragma once

#include "core/sampling.h"
#include "scene/light_estimate.h"
#include "scene/scene_view.h"

namespace lantern {

struct LightPick {
    int32_t light;  // -1: no light can reach the point
    float pmf;
};

// cos(max(theta - delta, 0)) for theta with cosine c (sine sn) and an angle delta in [0, pi]
// given by cos_d, sin_d: 1 where theta <= delta (trigonometry-free, as the importance needs).
LANTERN_HD inline float cos_clamped_difference(float c, float sn, float cos_d, float sin_d) {
    if (c >= cos_d) return 1.0f;  // theta <= delta
    return c * cos_d + sn * sin_d;
}

// Importance of a node at p: its intensity times the bounds of the emitter's and the
// receiver's cosines over the node's bounding sphere, over the squared distance (clamped to
// the sphere's radius). n = 0 (a point that transmits) drops the receiver's cosine. Zero only
// where no light of the node can reach p or its front side [Conty Estevez & Kulla (3)].
LANTERN_HD inline float light_node_importance(const LightTreeNode& nd, Vec3 p, Vec3 n) {
    if (!(nd.energy > 0.0f)) return 0.0f;
    const Vec3 w = (nd.lo + nd.hi) * 0.5f - p;  // towards the node's centre
    const float d2 = length_sq(w);
    const float r2 = 0.25f * length_sq(nd.hi - nd.lo);
    float cos_t = 1.0f, cos_i = 1.0f;
    if (d2 > r2) {  // outside the bounding sphere: the angles it subtends bound the cosines
        const float inv_d = 1.0f / sqrtf(d2);
        const Vec3 wh = w * inv_d;
        const float sin_u = fminf(sqrtf(r2) * inv_d, 1.0f), cos_u = sqrtf(1.0f - sin_u * sin_u);
        // theta' = max(theta - theta_o - theta_u, 0): theta_o + theta_u as one angle
        const float sin_o = sqrtf(fmaxf(1.0f - nd.cos_o * nd.cos_o, 0.0f));
        const float sin_ou = sin_o * cos_u + nd.cos_o * sin_u;
        const float cos_ou = sin_ou < 0.0f ? -1.0f : nd.cos_o * cos_u - sin_o * sin_u;
        const float ct = clampf(-dot(nd.axis, wh), -1.0f, 1.0f);
        cos_t = cos_clamped_difference(ct, sqrtf(fmaxf(1.0f - ct * ct, 0.0f)), cos_ou,
                                       sin_ou < 0.0f ? 0.0f : sin_ou);
        if (cos_t <= nd.cos_e) return 0.0f;  // theta' >= theta_e
        if (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f) {
            const float ci = clampf(dot(n, wh), -1.0f, 1.0f);
            cos_i = cos_clamped_difference(ci, sqrtf(fmaxf(1.0f - ci * ci, 0.0f)), cos_u, sin_u);
            if (cos_i <= 0.0f) return 0.0f;  // theta_i - theta_u >= pi / 2
        }
    }
    const float v = nd.energy * fmaxf(cos_t, 1e-7f) * fmaxf(cos_i, 1e-7f) /
                    fmaxf(fmaxf(d2, r2), 1e-20f);
    return v < 1e37f ? v : 1e37f;  // overflow and NaN: large, never zero
}

// Importance of a distant light: its irradiance on a surface facing it (sun), or the world's
// irradiance on one side (pi L) or both (2 pi L), times the bound of the receiver's cosine over
// the sun's disk. The same unit as a node's importance (W/m^2), so that they compete fairly.
LANTERN_HD inline float light_distant_importance(const Light& l, Vec3 n) {
    const bool two_sided = n.x == 0.0f && n.y == 0.0f && n.z == 0.0f;
    if (l.type == kLightWorld) return l.tree_energy * (two_sided ? 2.0f * kPi : kPi);
    if (two_sided) return l.tree_energy;
    const float ci = clampf(dot(n, -l.direction), -1.0f, 1.0f);
    const float cos_h = fminf(l.cos_sun, 1.0f), sin_h = sqrtf(fmaxf(1.0f - cos_h * cos_h, 0.0f));
    const float c = cos_clamped_difference(ci, sqrtf(fmaxf(1.0f - ci * ci, 0.0f)), cos_h, sin_h);
    if (c <= 0.0f) return 0.0f;
    return l.tree_energy * fmaxf(c, 1e-7f);
}

// The top level's total: the tree's root and every distant light (without distant lights, 1).
LANTERN_HD inline float light_top_total(const SceneView& s, Vec3 p, Vec3 n, float* w_tree) {
    if (s.num_distant_lights == 0) {  // the tree alone: chosen with probability one
        *w_tree = 1.0f;
        return 1.0f;
    }
    *w_tree = s.num_tree_nodes > 0 ? light_node_importance(s.light_tree[0], p, n) : 0.0f;
    float total = *w_tree;
    for (int k = 0; k < s.num_distant_lights; ++k)
        total += light_distant_importance(s.lights[s.distant_lights[k]], n);
    return total;
}

// What one leaf gives (p, n), for the choice between subtrees of a few lights: the light's own
// unshadowed irradiance there (scene/light_estimate.h), so that lights compete by what they
// give, not by bounds that differ in looseness (a rectangle's bounding sphere beside a small
// point's); kept above 1e-4 of the bound, which is positive wherever the light reaches p; the
// bound for a light the estimate does not model (a spot). Zero behind a one-sided area light's
// plane, where it gives nothing (the bound's sphere reaches behind it).
LANTERN_HD inline float light_leaf_importance(const SceneView& s, int c, bool estimate, Vec3 p,
                                              Vec3 n) {
    const LightTreeNode& nd = s.light_tree[c];
    const Light& l = s.lights[nd.light];
    if (l.type == kLightArea && !(dot(l.frame.origin() - p, l.frame.axis(2)) > 0.0f))
        return 0.0f;  // behind the emitting side (-Z) or in its plane
    const float bound = light_node_importance(nd, p, n);
    if (!estimate || !(bound > 0.0f)) return bound;
    const float e = light_irradiance_estimate(s, l, p, n);
    if (e < 0.0f) return bound;  // a spot: its bound
    const float v = fmaxf(e, 1e-4f * bound);
    return v < 1e37f ? v : 1e37f;
}

// Subtrees of at most this many lights, none of them an emissive triangle, are weighed by the
// sum of their lights' estimates (light_leaf_importance), others by their node's bound.
constexpr int kExactSubtreeLights = 8;

// The sum of light_leaf_importance over the lights below node c, or -1 where there are more
// than kExactSubtreeLights of them (depth-first, the right children waiting on a small stack).
LANTERN_HD inline float light_subtree_estimate(const SceneView& s, int c, Vec3 p, Vec3 n) {
    int pending[kExactSubtreeLights];
    int top = 0, leaves = 0, node = c;
    float sum = 0.0f;
    for (;;) {
        const LightTreeNode& nd = s.light_tree[node];
        if (nd.right >= 0) {
            if (top == kExactSubtreeLights) return -1.0f;
            pending[top++] = nd.right;
            node = node + 1;
            continue;
        }
        if (++leaves > kExactSubtreeLights) return -1.0f;
        // a mesh emitter's triangles: their bounds are tight and alike, and the estimate
        // (irradiance, blind to the BSDF) made veach-mis's glossy plates noisier (3404804)
        if (s.lights[s.light_tree[node].light].type == kLightTriangle) return -1.0f;
        sum += light_leaf_importance(s, node, true, p, n);
        if (top == 0) break;
        node = pending[--top];
    }
    return sum < 1e37f ? sum : 1e37f;
}

// Importance of child node c of a split at (p, n) when the split's two sides are not both
// small and free of triangles: a subtree's bound; a leaf's bound (zero behind an area light's
// plane), or its estimate where it faces a leaf (leaf_pair: a mesh emitter's two triangles).
LANTERN_HD inline float light_child_importance(const SceneView& s, int c, bool leaf_pair, Vec3 p,
                                               Vec3 n) {
    const LightTreeNode& nd = s.light_tree[c];
    if (nd.right >= 0) return light_node_importance(nd, p, n);
    return light_leaf_importance(s, c, leaf_pair, p, n);
}

// Probability of the left child of interior node nd at (p, n); false where neither child can
// reach the point (a dead end: the lights below contribute nothing there). Where both sides
// hold at most kExactSubtreeLights lights and no emissive triangle, each weighs what its
// lights give (a pick in proportion to the estimates when the scene has that few); else the
// bounds [Conty Estevez & Kulla], and estimates between two leaves. Measured on the differential tester's light sets (bench/light_sets_noise.py): with
// bounds above leaf pairs, three area lights around objects in the void read 1.42x Cycles'
// noise at equal samples, each light alone at most 1.01x.
LANTERN_HD inline bool light_split(const SceneView& s, int node, Vec3 p, Vec3 n, float* p_left) {
    const int left = node + 1, right = s.light_tree[node].right;
    float il = light_subtree_estimate(s, left, p, n);
    float ir = il >= 0.0f ? light_subtree_estimate(s, right, p, n) : -1.0f;
    if (!(il >= 0.0f && ir >= 0.0f)) {
        const bool leaf_pair = s.light_tree[left].right < 0 && s.light_tree[right].right < 0;
        il = light_child_importance(s, left, leaf_pair, p, n);
        ir = light_child_importance(s, right, leaf_pair, p, n);
    }
    const float sum = il + ir;
    if (!(sum > 0.0f)) return false;
    *p_left = il / sum;
    return true;
}

// One light for next-event estimation at p (normal n, zero for both sides), from u in [0, 1).
// Out of line on the device, as light_pick_pmf (LANTERN_DEVICE_NOINLINE: a copy per call site
// in every shade kernel before).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline LightPick light_pick(const SceneView& s, Vec3 p, Vec3 n, float u) {
    LightPick r{-1, 0.0f};
    if (s.num_lights <= 0) return r;
    if (!s.light_tree_on) {
        if (!s.nee_cdf) return r;
        r.light = sample_cdf(s.nee_cdf, s.num_lights, u);
        r.pmf = s.lights[r.light].nee_pdf;
        return r;
    }
    float w_tree;
    const float total = light_top_total(s, p, n, &w_tree);
    if (!(total > 0.0f)) return r;
    float x = u * total;
    if (!(x < w_tree) || s.num_tree_nodes == 0) {  // a distant light
        x -= w_tree;
        for (int k = 0; k < s.num_distant_lights; ++k) {
            const float w = light_distant_importance(s.lights[s.distant_lights[k]], n);
            if (!(w > 0.0f)) continue;
            r = {s.distant_lights[k], w / total};
            if (x < w) break;
            x -= w;
        }
        if (r.light >= 0 || !(w_tree > 0.0f)) return r;
        x = w_tree * 0.99999994f;  // rounding past the last distant light: the tree
    }
    float pmf = w_tree / total;
    u = fminf(x / w_tree, 0.99999994f);
    int node = 0;
    while (s.light_tree[node].right >= 0) {
        float pl;
        if (!light_split(s, node, p, n, &pl)) return r;
        if (u < pl) {
            u = fminf(u / pl, 0.99999994f);
            pmf *= pl;
            node = node + 1;
        } else {
            u = fminf((u - pl) / (1.0f - pl), 0.99999994f);
            pmf *= 1.0f - pl;
            node = s.light_tree[node].right;
        }
    }
    r = {s.light_tree[node].light, pmf};
    return r;
}

// The probability that light_pick at (p, n) chooses light li: the same products in the same
// order (subtrees are contiguous in depth-first order, so the leaf's index says the way down).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline float light_pick_pmf(const SceneView& s, int li, Vec3 p, Vec3 n) {
    const Light& l = s.lights[li];
    if (!s.light_tree_on) return l.nee_pdf;
    float w_tree;
    const float total = light_top_total(s, p, n, &w_tree);
    if (!(total > 0.0f)) return 0.0f;
    if (l.tree_leaf < 0) return light_distant_importance(l, n) / total;
    float pmf = w_tree / total;
    int node = 0;
    while (s.light_tree[node].right >= 0) {
        float pl;
        if (!light_split(s, node, p, n, &pl)) return 0.0f;
        if (l.tree_leaf < s.light_tree[node].right) {
            pmf *= pl;
            node = node + 1;
        } else {
            pmf *= 1.0f - pl;
            node = s.light_tree[node].right;
        }
    }
    return pmf;
}

// The normal a light pick sees at a point of triangle tri whose geometric normal ng faces the
// arriving ray: ng, or zero (both sides) where the triangle's material may transmit. It reads
// the material as built (never the per-hit resolution), so that the camera and the light
// sub-path see the same value at the same vertex; node-graph materials count as transmitting.
LANTERN_HD inline Vec3 light_pick_normal(const SceneView& s, int tri, Vec3 ng) {
    if (!s.light_tree_on) return ng;
    const Material& m = s.materials[s.tri_material[tri]];
    auto transmits = [](const Material& x) {
        return x.type == kMaterialDielectric || x.type == kMaterialTranslucent ||
               x.type == kMaterialHair ||
               (x.type == kMaterialPrincipled && x.transmission > 0.0f) ||
               (x.tex_flags & kTexProgram) != 0;
    };
    bool t = transmits(m);
    if (m.type == kMaterialMix)
        for (int k = 0; k < m.mix_count; ++k)
            t = t || m.mix_child[k] < 0 || transmits(s.materials[m.mix_child[k]]);
    return t ? vec3(0.0f) : ng;
}

}  // namespace lantern
