// HostScene's lights: the scene's extent (distant lights' disk), point, spot, area and sun
// lights from the input, emissive triangles, the world; pick probabilities by power (all
// lights, next-event estimation, light sub-paths) and the light tree.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "bsdf/material.h"
#include "integrator/light_path.h"
#include "scene/light_tree_build.h"
#include "accel/curve_bvh_build.h"
#include "scene/scene.h"
#include "scene/scene_checks.h"
#include "scene/scene_limits.h"

namespace lantern {

namespace {

// Pick probabilities proportional to `weight`, handed to set(k, pdf) (0 where the weights sum to
// 0), and their CDF appended to `cdf` (the last entry exactly 1; all 0 when nothing can be
// picked). True when some light can be picked.
template <class SetPdf>
bool build_pick_cdf(const std::vector<double>& weight, std::vector<float>& cdf, SetPdf set) {
    double total = 0.0;
    for (double w : weight) total += w;
    double acc = 0.0;
    for (size_t k = 0; k < weight.size(); ++k) {
        set(k, total > 0.0 ? float(weight[k] / total) : 0.0f);
        acc += weight[k];
        cdf.push_back(total > 0.0 ? float(acc / total) : 0.0f);
    }
    if (total > 0.0) cdf.back() = 1.0f;
    return total > 0.0;
}

}  // namespace

void HostScene::add_lights(const SceneInput& in) {
    std::vector<float> power;
    // scene extent, for the power of distant lights
    Vec3 lo = vec3(kInf), hi = vec3(-kInf);
    for (const Vec3& p : positions_) {
        if (!within_limit(p)) continue;  // non-finite or far: no triangle of the scene uses it
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    // strands (scene_curves.cpp): their boxes, a moving one's at every step (curve_motion.cpp)
    const CurveKeys keys{curve_keys_.data(), curve_steps_, int32_t(curve_segs_.size())};
    for (const CurveSeg& g : curve_segs_) {
        Vec3 a, b;
        curve_seg_bounds(g, keys, &a, &b);
        lo = {std::min(lo.x, a.x), std::min(lo.y, a.y), std::min(lo.z, a.z)};
        hi = {std::max(hi.x, b.x), std::max(hi.y, b.y), std::max(hi.z, b.z)};
    }
    float radius = lo.x <= hi.x ? 0.5f * length(hi - lo) : 1.0f;
    view_.scene_center = lo.x <= hi.x ? (lo + hi) * 0.5f : vec3(0.0f);
    view_.scene_radius = std::max(radius, 1e-3f);
    view_.offset_scale = std::min(1.0f, view_.scene_radius);
    // the pure light tracer's sun and world paths leave the disk of the sphere about the same
    // centre through the farthest vertex: no larger than the box's (kept where they round alike,
    // a box's corners), a third of its area about a ball (light_path.h, kTightDisk)
    float reach = 0.0f;
    for (const Vec3& p : positions_) {
        if (within_limit(p)) reach = std::max(reach, length(p - view_.scene_center));
    }
    for (const std::vector<CurveSeg>* v : {&curve_segs_, &curve_keys_})
        for (const CurveSeg& g : *v)
            reach = std::max(reach, std::max(length(g.p0 - view_.scene_center) + g.r0,
                                             length(g.p1 - view_.scene_center) + g.r1));
    view_.emit_radius = lo.x <= hi.x ? std::max(std::min(view_.scene_radius,
                                                         reach * (1.0f + 1e-5f)), 1e-3f)
                                     : view_.scene_radius;  // no geometry: as the box's
    const float disk_area = kPi * view_.scene_radius * view_.scene_radius;

    for (size_t k = 0; k < in.lights.size(); ++k) {
        const LightInput& li = in.lights[k];
        if (!light_within_limit(li, k, warnings_)) continue;
        Light l{};
        l.triangle = -1;
        l.visible_camera = li.visible_camera ? 1 : 0;
        const Vec3 pw = sanitize_color(li.power, 1e30f);
        if (li.type == "point" || li.type == "spot") {
            l.type = li.type == "point" ? kLightPoint : kLightSpot;
            l.frame = rigid(li.to_world);
            l.position = li.type == "point" ? li.position : l.frame.origin();
            l.radius = finite_in(li.radius, 0.0f, kInf, 0.0f);
            l.soft_falloff = li.soft_falloff ? 1 : 0;
            l.intensity = pw * (0.25f * kInvPi);                 // W/sr
            if (l.radius > 0.0f) l.radiance = l.intensity * (1.0f / (kPi * l.radius * l.radius));
            float half = 0.5f * clampf(li.spot_size, 1e-4f, kPi);
            l.cos_half_spot = cosf(half);
            l.spot_smooth = (1.0f - l.cos_half_spot) * clampf(li.spot_blend, 0.0f, 1.0f);
            power.push_back(luminance(pw));
        } else if (li.type == "area") {
            l.type = kLightArea;
            l.frame = rigid(li.to_world);
            bool ellipse = li.shape == "disk" || li.shape == "ellipse";
            bool square = li.shape == "square" || li.shape == "disk";
            l.shape = ellipse ? kShapeEllipse : kShapeRectangle;
            l.half_x = 0.5f * std::fabs(li.size_x);
            l.half_y = 0.5f * std::fabs(square ? li.size_x : li.size_y);
            l.area = ellipse ? kPi * l.half_x * l.half_y : 4.0f * l.half_x * l.half_y;
            if (!(l.area > 0.0f) || !std::isfinite(l.area)) {
                warnings_.push_back(light_label(li, k) + ": an area light of zero (or " +
                                    "non-finite) size was skipped");
                continue;
            }
            l.radiance = pw * (1.0f / (kPi * l.area));
            power.push_back(luminance(pw));
        } else if (li.type == "sun") {
            l.type = kLightSun;
            l.direction = normalize(li.direction);
            const Vec3 s = sanitize_color(li.strength, 1e30f);
            float half = 0.5f * clampf(std::isfinite(li.angle) ? li.angle : 0.0f, 0.0f, kPi);
            if (half < 1e-5f) {
                l.cos_sun = 1.0f;
                l.intensity = s;
            } else {
                l.cos_sun = cosf(half);
                float sin2 = 1.0f - l.cos_sun * l.cos_sun;
                l.radiance = s * (1.0f / (kPi * sin2));
            }
            power.push_back(luminance(s) * disk_area);
            if (li.of_world) {  // the world's disc: the camera sees it where it sees the world
                l.of_world = 1;
                l.visible_camera = in.world_visible_camera && !in.film_transparent ? 1 : 0;
            }
        } else {
            warnings_.push_back("unknown light type '" + li.type + "' was skipped");
            continue;
        }
        if (power.back() <= 0.0f || !std::isfinite(power.back())) {
            power.pop_back();
            continue;
        }
        lamp_input_.resize(lights_.size(), -1);
        lamp_input_.push_back(int32_t(k));
        lights_.push_back(l);
    }
    // emissive triangles
    for (size_t t = 0; t < tri_material_.size(); ++t) {
        const Material& m = materials_[tri_material_[t]];
        if (is_black(m.emission)) continue;
        Vec3 a = positions_[indices_[3 * t]], b = positions_[indices_[3 * t + 1]],
             c = positions_[indices_[3 * t + 2]];
        // in double: the float cross product's squared length overflows for edges over ~4e9 m
        float area = float(0.5 * triangle_area2(a, b, c));
        if (!(area > 0.0f) || !std::isfinite(area)) continue;
        Light l{};
        l.type = kLightTriangle;
        l.triangle = int32_t(t);
        l.radiance = m.emission;
        l.area = area;
        l.visible_camera = 1;
        tri_light_[t] = int32_t(lights_.size());
        lights_.push_back(l);
        power.push_back(luminance(m.emission) * area * 2.0f * kPi);
    }
    Vec3 world = sanitize_color(in.world_color, 1e30f);
    if (in.world_map.width > 0) {  // an environment map replaces the constant colour
        env_ = build_envmap_cached(in.world_map, warnings_);  // once per content
        world = env_->view.width > 0 ? env_->mean : vec3(0.0f);
    }
    view_.world_color = world;
    if (!is_black(world)) {
        Light l{};
        l.type = kLightWorld;
        l.triangle = -1;
        l.radiance = world;  // with a map: its mean (the light's power), SceneView::env per ray
        l.visible_camera = in.world_visible_camera && !in.film_transparent ? 1 : 0;
        view_.world_light = int32_t(lights_.size());
        lights_.push_back(l);
        power.push_back(luminance(world) * kPi * 4.0f * disk_area);
    }
    double total = 0.0;
    for (float p : power) total += p;
    double acc = 0.0;
    for (size_t k = 0; k < lights_.size(); ++k) {
        lights_[k].pick_pdf = float(power[k] / total);
        acc += power[k];
        light_cdf_.push_back(float(acc / total));
    }
    if (!light_cdf_.empty()) light_cdf_.back() = 1.0f;
    // Next-event estimation leaves out a constant world: BSDF sampling alone is the better
    // strategy there (its integrand is the BSDF times visibility), and saves the shadow ray.
    // Cycles' "Auto" world sampling does the same for a solid colour (its manual: importance
    // sampling "for non-solid colors is recommended"). A map (HDRI, sky) is sampled.
    const bool world_map = env_->view.width > 0;
    std::vector<double> weight(lights_.size());
    for (size_t k = 0; k < lights_.size(); ++k)
        weight[k] = lights_[k].type == kLightWorld && !world_map ? 0.0 : double(power[k]);
    has_nee_lights_ = build_pick_cdf(weight, nee_cdf_,
                                     [&](size_t k, float pdf) { lights_[k].nee_pdf = pdf; });
    // Light sub-paths (bdpt, lvc, cis) start by power too. A soft-falloff point/spot's leave
    // its centre and take y0 on the disk facing their first hit (integrator/soft_light_path.h;
    // through homogeneous media: soft_light_medium.h). None start on them in scenes with a
    // heterogeneous medium (a density grid or program, build_media's test: the tracking's
    // weight cannot be turned into the y0 -> x1 transmittance's), nor with strands (the soft
    // route's first hit is a triangle's: bdpt_light.h, no fiber measure), nor in a scene meant
    // for the GPU (HostScene's soft_light_paths). docs/lvc_notes.md.
    bool camera_side = !in.curves.empty() || !soft_light_paths_;
    for (size_t k = 0; k < in.materials.size(); ++k) {
        const MaterialInput& mi = in.materials[k];
        if (mi.medium >= 0 && (mi.density_grid >= 0 || density_program(k) >= 0))
            camera_side = true;
    }
    for (size_t k = 0; k < lights_.size(); ++k)
        weight[k] = camera_side && light_receiver_dependent(lights_[k]) ? 0.0 : double(power[k]);
    has_emitters_ = build_pick_cdf(weight, emit_cdf_,
                                   [&](size_t k, float pdf) { lights_[k].emit_pick_pdf = pdf; });
    // Next-event estimation picks by the light tree where there is a choice (a scene with one
    // light keeps light_cdf); LANTERN_LIGHT_TREE=0 keeps the global CDF, for benchmarks.
    const char* tree_env = std::getenv("LANTERN_LIGHT_TREE");
    light_tree_on_ = lights_.size() >= 2 && !(tree_env && std::string(tree_env) == "0");
    for (Light& l : lights_) l.tree_leaf = -1;
    if (light_tree_on_) build_light_tree(lights_, positions_, indices_, light_tree_);
}

}  // namespace lantern
