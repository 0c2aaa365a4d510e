// Builds the light tree of scene/light_tree.h on the host: one leaf per local light, interior
// nodes split by the surface area orientation heuristic (SAOH) of Conty Estevez & Kulla 2018.
#include "scene/light_tree_build.h"

#include <algorithm>
#include <cmath>

#include "scene/lights.h"  // triangle_vertex

namespace lantern {
namespace {

// What the tree knows of one local light (or a set of them).
struct Bounds {
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    float energy = 0.0f;
    Vec3 axis{0.0f, 0.0f, 1.0f};
    float theta_o = 0.0f, theta_e = 0.0f;
    bool empty = true;
};

Vec3 vmin(Vec3 a, Vec3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
Vec3 vmax(Vec3 a, Vec3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
float comp(Vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

// The smallest cone holding both cones [Conty Estevez & Kulla, Algorithm 1], widened by a
// little so that rounding never leaves a child's direction outside.
void merge_cone(const Bounds& a0, const Bounds& b0, Vec3* axis, float* theta_o) {
    const Bounds& a = a0.theta_o >= b0.theta_o ? a0 : b0;
    const Bounds& b = a0.theta_o >= b0.theta_o ? b0 : a0;
    const float theta_d = std::acos(clampf(dot(a.axis, b.axis), -1.0f, 1.0f));
    if (std::min(theta_d + b.theta_o, kPi) <= a.theta_o) {
        *axis = a.axis;
        *theta_o = a.theta_o;
        return;
    }
    const float o = 0.5f * (a.theta_o + theta_d + b.theta_o);
    if (o >= kPi) {
        *axis = a.axis;
        *theta_o = kPi;
        return;
    }
    const float rot = o - a.theta_o;
    Vec3 perp = b.axis - a.axis * dot(a.axis, b.axis);
    if (!(length_sq(perp) > 1e-12f)) perp = Frame::from_normal(a.axis).s;  // opposite axes
    perp = normalize(perp);
    *axis = normalize(a.axis * std::cos(rot) + perp * std::sin(rot));
    *theta_o = std::min(kPi, o + 1e-4f);
}

void merge(Bounds& into, const Bounds& b) {
    if (b.empty) return;
    if (into.empty) {
        into = b;
        return;
    }
    into.lo = vmin(into.lo, b.lo);
    into.hi = vmax(into.hi, b.hi);
    merge_cone(into, b, &into.axis, &into.theta_o);
    into.theta_e = std::max(into.theta_e, b.theta_e);
    into.energy += b.energy;
}

// The orientation measure M_Omega [Conty Estevez & Kulla (1)].
float orientation_measure(float theta_o, float theta_e) {
    const float theta_w = std::min(theta_o + theta_e, kPi);
    return 2.0f * kPi * (1.0f - std::cos(theta_o)) +
           0.5f * kPi * (2.0f * theta_w * std::sin(theta_o) - std::cos(theta_o - 2.0f * theta_w) -
                         2.0f * theta_o * std::sin(theta_o) + std::cos(theta_o));
}

float surface_area(const Bounds& b) {
    const Vec3 e = b.hi - b.lo;
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

Bounds light_bounds(const Light& l, const std::vector<Vec3>& pos,
                    const std::vector<uint32_t>& idx) {
    Bounds b;
    b.empty = false;
    b.theta_e = 0.5f * kPi;
    switch (l.type) {
    case kLightPoint:
    case kLightSpot: {
        const Vec3 r = vec3(std::max(l.radius, 0.0f));
        b.lo = l.position - r;
        b.hi = l.position + r;
        b.energy = luminance(l.intensity);
        if (l.type == kLightSpot) {
            b.axis = -l.frame.axis(2);
            b.theta_e = std::min(std::acos(clampf(l.cos_half_spot, -1.0f, 1.0f)), 0.5f * kPi);
        } else {
            b.theta_o = kPi;
        }
        break;
    }
    case kLightArea: {
        const Vec3 c = l.frame.origin(), x = l.frame.axis(0) * l.half_x,
                   y = l.frame.axis(1) * l.half_y;
        for (float sx : {-1.0f, 1.0f})
            for (float sy : {-1.0f, 1.0f}) {
                b.lo = vmin(b.lo, c + x * sx + y * sy);
                b.hi = vmax(b.hi, c + x * sx + y * sy);
            }
        b.axis = -l.frame.axis(2);
        b.energy = luminance(l.radiance) * l.area;
        break;
    }
    default: {  // an emissive triangle: both sides
        const uint32_t* t = idx.data() + 3 * l.triangle;
        for (int k = 0; k < 3; ++k) {
            b.lo = vmin(b.lo, pos[t[k]]);
            b.hi = vmax(b.hi, pos[t[k]]);
        }
        b.theta_o = kPi;
        b.energy = luminance(l.radiance) * l.area;
        break;
    }
    }
    if (!(b.energy > 0.0f) || !std::isfinite(b.energy)) b.energy = b.energy > 0.0f ? 1e30f : 0.0f;
    return b;
}

struct Prim {
    int32_t light;
    Bounds b;
    Vec3 centroid;
};

class Builder {
public:
    Builder(std::vector<Prim>& prims, std::vector<LightTreeNode>& nodes)
        : prims_(prims), nodes_(nodes) {}

    // Emits the subtree of prims_[begin, end) and returns its bounds.
    Bounds build(int begin, int end, int depth) {
        const int me = int(nodes_.size());
        nodes_.push_back(LightTreeNode{});
        Bounds all;
        for (int k = begin; k < end; ++k) merge(all, prims_[k].b);
        if (end - begin == 1) {
            set(me, all, -1, prims_[begin].light);
            return all;
        }
        const int mid = split(begin, end, all, depth);
        build(begin, mid, depth + 1);
        const int right = int(nodes_.size());
        build(mid, end, depth + 1);
        set(me, all, right, -1);
        return all;
    }

private:
    void set(int node, const Bounds& b, int right, int light) {
        LightTreeNode& n = nodes_[node];
        n.lo = b.lo;
        n.hi = b.hi;
        n.energy = b.energy;
        n.axis = b.axis;
        n.cos_o = b.theta_o >= kPi ? -1.0f : std::cos(b.theta_o);
        n.cos_e = b.theta_e >= 0.5f * kPi ? 0.0f : std::cos(b.theta_e);
        n.right = right;
        n.light = light;
    }

    // The SAOH split over 12 buckets on each axis; the count's median where it cannot choose
    // (coincident centroids) or the tree grows deep.
    int split(int begin, int end, const Bounds& all, int depth) {
        constexpr int kBuckets = 12;
        Vec3 clo = vec3(kInf), chi = vec3(-kInf);
        for (int k = begin; k < end; ++k) {
            clo = vmin(clo, prims_[k].centroid);
            chi = vmax(chi, prims_[k].centroid);
        }
        const Vec3 ext = chi - clo;
        const float max_ext = std::max(ext.x, std::max(ext.y, ext.z));
        float best = kInf;
        int best_axis = -1, best_cut = 0;
        const Vec3 diag = all.hi - all.lo;
        const float eps_area = 1e-6f * length_sq(diag) + 1e-30f;
        for (int axis = 0; axis < 3 && depth < 48; ++axis) {
            const float e = comp(ext, axis);
            if (!(e > 0.0f)) continue;
            Bounds bucket[kBuckets];
            for (int k = begin; k < end; ++k) merge(bucket[bucket_of(prims_[k], clo, e, axis)],
                                                    prims_[k].b);
            for (int cut = 1; cut < kBuckets; ++cut) {
                Bounds l, r;
                for (int j = 0; j < cut; ++j) merge(l, bucket[j]);
                for (int j = cut; j < kBuckets; ++j) merge(r, bucket[j]);
                if (l.empty || r.empty) continue;
                const float kr = max_ext / e;  // regularises long thin splits
                const float cost =
                    kr * (l.energy * orientation_measure(l.theta_o, l.theta_e) *
                              (surface_area(l) + eps_area) +
                          r.energy * orientation_measure(r.theta_o, r.theta_e) *
                              (surface_area(r) + eps_area));
                if (cost < best) {
                    best = cost;
                    best_axis = axis;
                    best_cut = cut;
                }
            }
        }
        if (best_axis >= 0) {
            const float e = comp(ext, best_axis);
            Prim* mid = std::partition(prims_.data() + begin, prims_.data() + end,
                                       [&](const Prim& p) {
                                           return bucket_of(p, clo, e, best_axis) < best_cut;
                                       });
            const int m = int(mid - prims_.data());
            if (m > begin && m < end) return m;
        }
        const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
        const int m = begin + (end - begin) / 2;
        std::nth_element(prims_.begin() + begin, prims_.begin() + m, prims_.begin() + end,
                         [&](const Prim& a, const Prim& b) {
                             return comp(a.centroid, axis) < comp(b.centroid, axis);
                         });
        return m;
    }

    static int bucket_of(const Prim& p, Vec3 clo, float extent, int axis) {
        const int b = int(12.0f * (comp(p.centroid, axis) - comp(clo, axis)) / extent);
        return std::min(std::max(b, 0), 11);
    }

    std::vector<Prim>& prims_;
    std::vector<LightTreeNode>& nodes_;
};

}  // namespace

bool light_shutter_boxes(const SceneView& v, const std::vector<Light>& lights,
                         std::vector<Vec3>& boxes) {
    boxes.assign(2 * lights.size(), vec3(0.0f));
    for (size_t k = 0; k < lights.size(); ++k) {
        boxes[2 * k] = vec3(kInf);
        boxes[2 * k + 1] = vec3(-kInf);
    }
    if (v.motion.num_objects == 0) return false;
    const MotionView& mv = v.motion;
    std::vector<std::vector<Transform>> at(size_t(mv.num_objects));  // per object, per time
    bool any = false;
    for (size_t k = 0; k < lights.size(); ++k) {
        const Light& l = lights[k];
        if (l.type != kLightTriangle) continue;
        const ObjectMotion* o = object_motion_of(mv, l.triangle);
        if (!o) continue;
        const int samples = (std::max(2, o->num_steps) - 1) * 16;
        std::vector<Transform>& m = at[size_t(o - mv.objects)];
        if (m.empty())
            for (int s = 0; s <= samples; ++s)
                m.push_back(object_motion_to_world(mv, *o, float(s) / float(samples)));
        const DeformMesh* dm = deform_of(mv, *o);
        Vec3 lo = vec3(kInf), hi = vec3(-kInf);
        for (int s = 0; s <= samples; ++s) {
            Vec3 c[3];
            for (int j = 0; j < 3; ++j) c[j] = triangle_vertex(v, l.triangle, j);
            if (dm) deform_triangle(mv, *dm, l.triangle, float(s) / float(samples), c);
            for (int j = 0; j < 3; ++j) {
                const Vec3 p = m[size_t(s)].point(c[j]);
                lo = vmin(lo, p);
                hi = vmax(hi, p);
            }
        }
        if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z) || !is_finite(lo) || !is_finite(hi))
            continue;
        boxes[2 * k] = lo;
        boxes[2 * k + 1] = hi;
        any = true;
    }
    return any;
}

void build_light_tree(std::vector<Light>& lights, const std::vector<Vec3>& positions,
                      const std::vector<uint32_t>& indices, LightTreeStorage& out,
                      const std::vector<Vec3>* shutter) {
    out.nodes.clear();
    out.distant.clear();
    std::vector<Prim> prims;
    for (size_t k = 0; k < lights.size(); ++k) {
        Light& l = lights[k];
        l.tree_leaf = -1;
        if (l.type == kLightSun) {
            l.tree_energy = luminance(l.cos_sun >= 1.0f
                                          ? l.intensity
                                          : l.radiance * (kPi * (1.0f - l.cos_sun * l.cos_sun)));
            out.distant.push_back(int32_t(k));
        } else if (l.type == kLightWorld) {
            l.tree_energy = l.nee_pdf > 0.0f ? luminance(l.radiance) : 0.0f;  // 0: never picked
            out.distant.push_back(int32_t(k));
        } else {
            Prim p{int32_t(k), light_bounds(l, positions, indices), vec3(0.0f)};
            if (shutter && (*shutter)[2 * k].x <= (*shutter)[2 * k + 1].x) {  // it moves
                p.b.lo = vmin(p.b.lo, (*shutter)[2 * k]);
                p.b.hi = vmax(p.b.hi, (*shutter)[2 * k + 1]);
            }
            p.centroid = (p.b.lo + p.b.hi) * 0.5f;
            l.tree_energy = p.b.energy;
            prims.push_back(p);
        }
    }
    if (prims.empty()) return;
    out.nodes.reserve(2 * prims.size());
    Builder(prims, out.nodes).build(0, int(prims.size()), 0);
    for (size_t n = 0; n < out.nodes.size(); ++n)
        if (out.nodes[n].right < 0) lights[out.nodes[n].light].tree_leaf = int32_t(n);
}

}  // namespace lantern
