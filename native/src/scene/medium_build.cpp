// The scene's media (docs/volumes.md): SceneInput::media sanitised into SceneView::media, the
// medium inside each material, the volume boundaries' triangle flags and the camera's medium.
// A mesh medium in a world volume holds both (Cycles sums the volumes it is inside).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.h"
#include "scene/material_program.h"

namespace lantern {

namespace {

// Non-finite or negative coefficients become 0, enormous ones 1e9 / m (a wall, and still
// finite through every product the stages form), each with a warning.
Vec3 clean(Vec3 v, const std::string& what, std::vector<std::string>& warnings) {
    float c[3] = {v.x, v.y, v.z};
    bool bad = false, huge = false;
    for (float& x : c) {
        if (!std::isfinite(x) || x < 0.0f) {
            bad = true;
            x = 0.0f;
        } else if (x > 1e9f) {
            huge = true;
            x = 1e9f;
        }
    }
    if (bad) warnings.push_back(what + ": a non-finite or negative value is taken as 0");
    if (huge) warnings.push_back(what + ": a value above 1e9 per metre is taken as 1e9");
    return Vec3{c[0], c[1], c[2]};
}

Medium to_medium(const MediumInput& in, std::vector<std::string>& warnings) {
    const std::string who = "medium '" + in.name + "'";
    Medium m{};
    m.sigma_a = clean(in.sigma_a, who + " absorption", warnings);
    m.sigma_s = clean(in.sigma_s, who + " scattering", warnings);
    m.emission = clean(in.emission, who + " emission", warnings);
    // Cycles keeps |g| below 1 too: a delta lobe would need a phase sampler of its own
    m.g = std::isfinite(in.g) ? std::fmin(std::fmax(in.g, -0.999f), 0.999f) : 0.0f;
    m.density_prog = -1;
    m.density_grid = -1;
    m.majorant_grid = m.temperature_grid = m.flame_grid = m.color_grid = -1;
    m.emission_prog = -1;
    m.color_prog = m.emission_color_prog = m.absorb_prog = -1;
    return m;
}

void finish(Medium& m) {
    m.sigma_t = m.sigma_a + m.sigma_s;
    m.scatters = max_component(m.sigma_s) > 0.0f ? 1u : 0u;
    m.emits = max_component(m.emission) > 0.0f ? 1u : 0u;
}

// The world's medium added to a mesh's: coefficients add; one Henyey-Greenstein lobe stands
// for both, its g the scattering-weighted mean (exact when only one of them scatters).
Medium combined(const Medium& a, const Medium& w, const std::string& name,
                std::vector<std::string>& warnings) {
    Medium m = a;
    m.sigma_a = a.sigma_a + w.sigma_a;
    m.sigma_s = a.sigma_s + w.sigma_s;
    m.emission = a.emission + w.emission;
    const float sa = luminance(a.sigma_s), sw = luminance(w.sigma_s);
    if (sa + sw > 0.0f) m.g = (a.g * sa + w.g * sw) / (sa + sw);
    if (sa > 0.0f && sw > 0.0f && a.g != w.g)
        warnings.push_back("medium '" + name + "' inside the world's volume: their anisotropies "
                           "differ; one lobe of their mean anisotropy stands for both");
    return m;
}

}  // namespace

std::string media_reason(const SceneInput& in) {
    if (in.world_medium >= 0) return "the world's volume";
    for (const MaterialInput& m : in.materials)
        if (m.medium >= 0 || m.volume_only) return "a volume (material '" + m.name + "')";
    return "";
}

std::string emissive_media_reason(const SceneInput& in) {
    auto emits = [&](int k) {
        if (k < 0 || k >= int(in.media.size())) return false;
        const Vec3 e = in.media[size_t(k)].emission;
        return e.x > 0.0f || e.y > 0.0f || e.z > 0.0f;  // NaN and negative: cleaned to 0
    };
    // lt has no camera gather: an emitting medium would need light paths that start in it
    // (bdpt, lvc and cis gather it on their camera paths; heterogeneous media render in all four)
    if (emits(in.world_medium)) return "an emissive world volume";
    for (const MaterialInput& m : in.materials)
        if (emits(m.medium)) return "an emissive volume (material '" + m.name + "')";
    // a graph on a volume's Emission Color or a Volume object's Emission Strength: emission
    // flame_emission x its value per point
    for (const MaterialInput& m : in.materials) {
        if (m.medium < 0 || m.medium >= int(in.media.size()) || m.program_count <= 0) continue;
        const Vec3 f = in.media[size_t(m.medium)].flame_emission;
        if (!(f.x > 0.0f || f.y > 0.0f || f.z > 0.0f)) continue;
        for (int i = 0; i < m.program_count; ++i) {
            const size_t w = 6 * size_t(m.program_first + i) + 4;
            if (w < in.programs.size() &&
                (in.programs[w] == uint32_t(kTargetVolumeEmissionColor) ||
                 in.programs[w] == uint32_t(kTargetVolumeEmission)))
                return "an emissive volume (a node graph on the emission of material '" +
                       m.name + "')";
        }
    }
    // a Volume object's fire (scene/medium_fire.h): emission from its grids
    for (const MaterialInput& m : in.materials)
        if (m.medium >= 0 && m.density_grid >= 0 && (m.temperature_grid >= 0 || m.flame_grid >= 0))
            return "an emissive volume (the temperature or flame grid of material '" + m.name +
                   "')";
    return "";
}

void HostScene::build_media(const SceneInput& in) {
    bool any = in.world_medium >= 0;
    for (const MaterialInput& mi : in.materials) any = any || mi.medium >= 0 || mi.volume_only;
    if (!any) return;
    const int n_in = int(in.media.size());
    build_grids(in);  // Volume objects' density grids (scene/medium_grid_build.cpp)
    auto check = [&](int k, const std::string& who) {
        if (k < -1 || k >= n_in)
            throw std::invalid_argument(who + ": medium " + std::to_string(k) +
                                        " out of range (the scene has " + std::to_string(n_in) +
                                        " media)");
    };
    check(in.world_medium, "world");
    Medium world{};
    const bool has_world = in.world_medium >= 0;
    if (has_world) {
        world = to_medium(in.media[size_t(in.world_medium)], warnings_);
        finish(world);
        media_.push_back(world);
    }
    std::vector<int32_t> of_input(size_t(n_in), -1);  // input medium -> media_ index
    material_medium_.assign(materials_.size(), -1);
    std::vector<std::pair<int32_t, size_t>> hetero;  // (medium, material)
    for (size_t k = 0; k < in.materials.size(); ++k) {
        const MaterialInput& mi = in.materials[k];
        check(mi.medium, "material '" + mi.name + "'");
        if (mi.medium < 0) continue;
        if (mi.density_grid >= int32_t(grids_.size()))
            throw std::invalid_argument("material '" + mi.name + "': density grid " +
                                        std::to_string(mi.density_grid) + " out of range (the "
                                        "scene has " + std::to_string(grids_.size()) + ")");
        // a Volume object's density program (a graph on its Density reading its grids) stands
        // for its density grid, which then only places its box and bricks
        const int32_t prog = density_program(k);
        // graphs on the Color, Emission Color or (a mesh volume's) Emission Strength make a
        // medium heterogeneous too (its density 1 without a density program or grid)
        const bool colored = program_of(k, kTargetVolumeColor) >= 0 ||
                             program_of(k, kTargetVolumeEmissionColor) >= 0 ||
                             program_of(k, kTargetVolumeAbsorptionColor) >= 0 ||
                             program_of(k, kTargetVolumeEmission) >= 0;
        if (mi.density_grid >= 0 || prog >= 0 || colored) {
            // a heterogeneous medium: the material's own (its density program or grid, its mesh)
            const MediumInput& src = in.media[size_t(mi.medium)];
            Medium m = to_medium(src, warnings_);
            m.hetero = 1;
            m.density_prog = prog;
            m.density_grid = mi.density_grid;
            if (has_world) {
                m.sigma_a0 = world.sigma_a;
                m.sigma_s0 = world.sigma_s;
                m.emission = m.emission + world.emission;
                m.g = combined(m, world, src.name, warnings_).g;
            }
            finish(m);
            m.scatters = max_component(m.sigma_s + m.sigma_s0) > 0.0f ? 1u : 0u;
            if (mi.density_grid >= 0) {
                grid_fire(m, mi, src);  // scene/medium_grid_build.cpp
                // a graph on Emission Strength reading the grids: flame_emission x its value
                m.emission_prog = program_of(k, kTargetVolumeEmission);
                if (m.emission_prog >= 0 && max_component(m.flame_emission) > 0.0f)
                    m.emits = 1u;
                else
                    m.emission_prog = -1;
            }
            if (colored) volume_color_programs(m, src, k);  // scene/medium_color_build.cpp
            material_medium_[k] = int32_t(media_.size());
            media_.push_back(m);
            hetero.push_back({material_medium_[k], k});
            continue;
        }
        int32_t& at = of_input[size_t(mi.medium)];
        if (at < 0) {
            const MediumInput& src = in.media[size_t(mi.medium)];
            Medium m = to_medium(src, warnings_);
            if (has_world) m = combined(m, world, src.name, warnings_);
            finish(m);
            at = int32_t(media_.size());
            media_.push_back(m);
        }
        material_medium_[k] = at;
    }
    for (size_t t = 0; t < indices_.size() / 3; ++t)
        if (tri_material_[t] < in.materials.size() && in.materials[tri_material_[t]].volume_only)
            tri_flags_[t] |= kVolumeBoundary;
    for (uint8_t f : tri_flags_)  // a volume's mesh that casts no shadow (bidir_no_shadow.h)
        if (!(f & kCastShadow) && (f & kVolumeBoundary)) {
            view_.no_shadow_objects = 2;
            break;
        }
    view_.tri_flags = tri_flags_.data();
    view_.media = media_.empty() ? nullptr : media_.data();
    view_.num_media = int32_t(media_.size());
    view_.material_medium = material_medium_.data();
    view_.world_medium = has_world ? 0 : -1;
    for (Medium& m : media_) m.outside = view_.world_medium;
    if (has_world) media_[0].outside = -1;
    nest_media(in, has_world ? &world : nullptr);
    for (const auto& h : hetero) {
        if (media_[size_t(h.first)].density_grid >= 0) {
            // a density program on a grid: its attribute maps (the box's) and its lattice
            // majorant first (the fallback where the program has no bound), then the bricks
            if (media_[size_t(h.first)].density_prog >= 0)
                build_hetero(h.first, h.second, in.materials[h.second].name);
            build_grid_medium(h.first, in.materials[h.second].name);
        } else
            build_hetero(h.first, h.second, in.materials[h.second].name);
    }
    view_.media = media_.data();  // nesting may have added media
    view_.num_media = int32_t(media_.size());
    set_shadow_media(in);
    view_.camera_medium = camera_medium_at(view_.camera.to_world.origin());
    inset_volume_boundaries();  // after the fits and the camera's medium, which read the mesh as given
    // where each light's paths start (lt): the medium at its centre; distant lights the world's
    light_medium_.assign(lights_.size(), view_.world_medium);
    for (size_t k = 0; k < lights_.size(); ++k) {
        const Light& l = lights_[k];
        if (l.type == kLightPoint || l.type == kLightSpot) {
            light_medium_[k] = camera_medium_at(l.position);
        } else if (l.type == kLightArea) {
            light_medium_[k] = camera_medium_at(l.frame.origin());
        } else if (l.type == kLightTriangle) {
            const Vec3 a = positions_[indices_[3 * size_t(l.triangle)]],
                       b = positions_[indices_[3 * size_t(l.triangle) + 1]],
                       c = positions_[indices_[3 * size_t(l.triangle) + 2]];
            light_medium_[k] = camera_medium_at((a + b + c) * (1.0f / 3.0f));
        }
    }
    view_.light_medium = light_medium_.empty() ? nullptr : light_medium_.data();
}

// ---- The medium a shadow ray takes in each (Medium::shadow_as, pt_volume.h shadow_medium):
// itself, or where every triangle of its material (a volume's mesh, or a surface with a
// volume inside) casts no shadow, the enclosing medium's (followed outwards past every such
// mesh): Cycles skips a volume whose object is invisible to shadow rays, from inside too. A
// material whose triangles are of both kinds (objects sharing it, some with Cast Shadow off)
// is taken as casting (a warning). ----
// A casting mesh nested (summed) in a non-casting one: its own medium (with the world's), kept
// by nest_media as it was before the sum, where the enclosing chain skips to the world (a
// casting mesh between them: the sum stays, the skipped one's part in it).
void HostScene::set_shadow_media(const SceneInput& in) {
    const size_t n = media_.size();
    std::vector<int32_t> alone(n);  // the medium before nest_media summed it (else itself)
    for (size_t k = 0; k < n; ++k) {
        alone[k] = media_[k].shadow_as <= -2 ? -2 - media_[k].shadow_as : int32_t(k);
        media_[k].shadow_as = int32_t(k);
    }
    if (!view_.no_shadow_objects) return;
    std::vector<uint8_t> seen(n, 0);  // bit 1: a casting triangle, bit 2: a non-casting one
    for (size_t t = 0; t < tri_flags_.size(); ++t) {
        if (t >= tri_material_.size() || tri_material_[t] >= material_medium_.size()) continue;
        const int32_t med = material_medium_[tri_material_[t]];
        if (med >= 0) seen[size_t(med)] |= (tri_flags_[t] & kCastShadow) ? 1 : 2;
    }
    for (size_t k = 0; k < n; ++k)
        if (seen[k] == 3)
            for (size_t m = 0; m < material_medium_.size(); ++m)
                if (material_medium_[m] == int32_t(k))
                    warnings_.push_back("medium '" + in.materials[m].name +
                                        "' bounds objects with and without Cast Shadow: its "
                                        "volume casts shadows from all of them");
    auto skip = [&](int32_t at) {  // past every non-casting mesh outwards
        for (size_t hop = 0; hop < n && at >= 0 && seen[size_t(at)] == 2; ++hop)
            at = media_[size_t(at)].outside;
        return at;
    };
    for (size_t k = 0; k < n; ++k) {
        int32_t at = skip(int32_t(k));
        const int32_t out = at >= 0 ? media_[size_t(at)].outside : -1;
        if (at >= 0 && alone[size_t(at)] != at && out >= 0 && seen[size_t(out)] == 2 &&
            skip(out) == view_.world_medium)
            at = alone[size_t(at)];
        media_[k].shadow_as = at;
    }
}

// ---- Nesting: the medium around each medium mesh (Medium::outside). A mesh medium whose mesh
// lies inside another's holds both, as Cycles sums the volumes of its stack: its coefficients
// are the enclosing medium's plus its own (computed outer first); a path leaving it is back in
// the enclosing one. The enclosing mesh: of the other medium meshes that hold a point just
// outside one of its faces (an odd number of crossings along a ray), the one of the smallest
// bounding box. Heterogeneous media nest (outside) but are not summed (a warning). ----
void HostScene::nest_media(const SceneInput& in, const Medium* world) {
    struct Mesh {
        size_t material;
        Vec3 lo, hi, q;  // bounds; a point just outside its first face
        bool ok = false;
        double volume = 0.0;
        int parent = -1;  // index into meshes
    };
    std::vector<Mesh> meshes;
    for (size_t k = 0; k < material_medium_.size(); ++k)
        if (material_medium_[k] >= 0) meshes.push_back(Mesh{k, vec3(kInf), vec3(-kInf), {}});
    if (meshes.size() < 2) return;
    std::vector<int> of_material(material_medium_.size(), -1);
    for (size_t j = 0; j < meshes.size(); ++j) of_material[meshes[j].material] = int(j);
    auto tri_p = [&](size_t t, int v) { return positions_[indices_[3 * t + size_t(v)]]; };
    for (size_t t = 0; t < indices_.size() / 3; ++t) {
        if (tri_material_[t] >= of_material.size() || of_material[tri_material_[t]] < 0)
            continue;
        Mesh& m = meshes[size_t(of_material[tri_material_[t]])];
        for (int v = 0; v < 3; ++v) {
            const Vec3 p = tri_p(t, v);
            m.lo = Vec3{std::fmin(m.lo.x, p.x), std::fmin(m.lo.y, p.y), std::fmin(m.lo.z, p.z)};
            m.hi = Vec3{std::fmax(m.hi.x, p.x), std::fmax(m.hi.y, p.y), std::fmax(m.hi.z, p.z)};
        }
        const Vec3 n = cross(tri_p(t, 1) - tri_p(t, 0), tri_p(t, 2) - tri_p(t, 0));
        if (!m.ok && length(n) > 0.0f) {
            m.q = (tri_p(t, 0) + tri_p(t, 1) + tri_p(t, 2)) / 3.0f;
            m.ok = true;
            m.parent = int(t);  // the face, for now
        }
    }
    for (Mesh& m : meshes) {
        if (!m.ok) continue;
        const Vec3 e = m.hi - m.lo;
        m.volume = double(e.x) * e.y * e.z;
        const size_t t = size_t(m.parent);
        const Vec3 n = normalize(cross(tri_p(t, 1) - tri_p(t, 0), tri_p(t, 2) - tri_p(t, 0)));
        m.q = m.q + n * (1e-4f * std::fmax(length(e), 1e-3f));
        m.parent = -1;
    }
    const Vec3 d = normalize(Vec3{0.5773f, 0.5801f, 0.5749f});
    std::vector<int> crossings(meshes.size());
    for (size_t j = 0; j < meshes.size(); ++j) {
        Mesh& m = meshes[j];
        if (!m.ok) continue;
        std::fill(crossings.begin(), crossings.end(), 0);
        for (size_t t = 0; t < indices_.size() / 3; ++t) {
            if (tri_material_[t] >= of_material.size()) continue;
            const int o = of_material[tri_material_[t]];
            if (o < 0 || size_t(o) == j) continue;
            const Vec3 a = tri_p(t, 0), e1 = tri_p(t, 1) - a, e2 = tri_p(t, 2) - a;
            const Vec3 pv = cross(d, e2);
            const float det = dot(e1, pv);
            if (std::fabs(det) < 1e-20f) continue;
            const Vec3 sv = m.q - a;
            const float u = dot(sv, pv) / det;
            const Vec3 qv = cross(sv, e1);
            const float v = dot(d, qv) / det;
            if (u < 0.0f || v < 0.0f || u + v > 1.0f || !(dot(e2, qv) / det > 0.0f)) continue;
            ++crossings[size_t(o)];
        }
        for (size_t o = 0; o < meshes.size(); ++o)
            if ((crossings[o] & 1) &&
                (m.parent < 0 || meshes[o].volume < meshes[size_t(m.parent)].volume))
                m.parent = int(o);
    }
    std::vector<size_t> order(meshes.size());
    for (size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return meshes[a].volume > meshes[b].volume; });
    for (size_t j : order) {
        const Mesh& m = meshes[j];
        if (m.parent < 0) continue;
        const int32_t outer = material_medium_[meshes[size_t(m.parent)].material];
        const int32_t inner = material_medium_[m.material];
        const std::string& name = in.materials[m.material].name;
        if (media_[size_t(inner)].hetero || media_[size_t(outer)].hetero) {
            media_[size_t(inner)].outside = outer;
            warnings_.push_back("medium '" + name + "' lies inside another medium's mesh and "
                                "one of them is heterogeneous: inside it only its own medium "
                                "(and the world's) is rendered, not their sum");
            continue;
        }
        const Medium& a = media_[size_t(inner)];
        const Medium& b = media_[size_t(outer)];
        const Medium w = world ? *world : Medium{};
        Medium m2 = a;  // a + b - the world's (both hold it)
        m2.sigma_a = a.sigma_a + b.sigma_a - w.sigma_a;
        m2.sigma_s = a.sigma_s + b.sigma_s - w.sigma_s;
        m2.emission = a.emission + b.emission - w.emission;
        const float la = luminance(a.sigma_s), lb = luminance(b.sigma_s),
                    lw = luminance(w.sigma_s);
        if (la + lb - lw > 0.0f) m2.g = (a.g * la + b.g * lb - w.g * lw) / (la + lb - lw);
        if (la - lw > 0.0f && lb - lw > 0.0f && a.g != b.g)
            warnings_.push_back("medium '" + name + "' inside another medium: their "
                                "anisotropies differ; one lobe of their mean stands for both");
        m2.sigma_a = Vec3{std::fmax(m2.sigma_a.x, 0.0f), std::fmax(m2.sigma_a.y, 0.0f),
                          std::fmax(m2.sigma_a.z, 0.0f)};
        m2.sigma_s = Vec3{std::fmax(m2.sigma_s.x, 0.0f), std::fmax(m2.sigma_s.y, 0.0f),
                          std::fmax(m2.sigma_s.z, 0.0f)};
        m2.emission = Vec3{std::fmax(m2.emission.x, 0.0f), std::fmax(m2.emission.y, 0.0f),
                           std::fmax(m2.emission.z, 0.0f)};
        m2.sigma_t = m2.sigma_a + m2.sigma_s;
        m2.scatters = max_component(m2.sigma_s) > 0.0f ? 1u : 0u;
        m2.emits = max_component(m2.emission) > 0.0f ? 1u : 0u;
        m2.outside = outer;
        m2.shadow_as = -2 - inner;  // (set_shadow_media: the medium alone, for a shadow ray)
        material_medium_[m.material] = int32_t(media_.size());  // its own: nesting is per mesh
        media_.push_back(m2);
    }
}

// The medium at p: the nearest medium boundary along a fixed ray from p, left through its back
// (p is inside that material's medium) or entered through its front (p is outside: the medium
// around it, Medium::outside). Closed meshes with outward normals, nested or apart, as pt's
// tracking assumes.
int32_t HostScene::camera_medium_at(Vec3 p) const {
    const Vec3 d = normalize(Vec3{0.5773f, 0.5801f, 0.5749f});  // off every axis and diagonal
    float best = kInf;
    int32_t medium = view_.world_medium;
    for (size_t t = 0; t < indices_.size() / 3; ++t) {
        const uint32_t mat = tri_material_[t];
        if (mat >= material_medium_.size() || material_medium_[mat] < 0) continue;
        const Vec3 a = positions_[indices_[3 * t]], b = positions_[indices_[3 * t + 1]],
                   c = positions_[indices_[3 * t + 2]];
        const Vec3 e1 = b - a, e2 = c - a, q = cross(d, e2);
        const float det = dot(e1, q);
        if (std::fabs(det) < 1e-20f) continue;
        const Vec3 s = p - a;
        const float u = dot(s, q) / det;
        const Vec3 r = cross(s, e1);
        const float v = dot(d, r) / det;
        const float th = dot(e2, r) / det;
        if (u < 0.0f || v < 0.0f || u + v > 1.0f || !(th > 0.0f) || th >= best) continue;
        best = th;
        medium = dot(cross(e1, e2), d) > 0.0f ? material_medium_[mat]
                                               : media_[size_t(material_medium_[mat])].outside;
    }
    return medium;
}

}  // namespace lantern
