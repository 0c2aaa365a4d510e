// Colour programs of heterogeneous media at scene load (docs/volumes.md "Node graphs on volume
// inputs"): graphs on a volume shader's Color (kTargetVolumeColor), Principled Volume's
// Absorption Color (kTargetVolumeAbsorptionColor) or Emission Color (kTargetVolumeEmissionColor)
// set on the medium, and the colour's part of the majorant. The colour c and the absorption
// colour a (each channel clamped to [0, 1e9], scene/medium_fire.h medium_color_at) scatter
// color_scatter x c and absorb color_absorb x max(1 - c, 0) x max(1 - sqrt(a), 0) per unit of
// density; over a box their interval bounds (scene/program_bound.h) bound that per channel by
// color_scatter x c.hi + color_absorb x max(1 - c.lo, 0) x max(1 - sqrt(a.lo), 0). Where a
// program has no bound, the scattering's part is c's largest value on a lattice x 1.5 (the
// absorption's is at most color_absorb, a true bound), with a warning.
#include <algorithm>
#include <cmath>
#include <string>

#include "scene/medium_hetero.h"
#include "scene/program_bound.h"
#include "scene/scene.h"

namespace lantern {

namespace {

Vec3 clean_rgb(Vec3 v) {
    auto c = [](float x) { return std::isfinite(x) && x > 0.0f ? std::fmin(x, 1e9f) : 0.0f; };
    return Vec3{c(v.x), c(v.y), c(v.z)};
}

}  // namespace

void HostScene::volume_color_programs(Medium& m, const MediumInput& src, size_t material) {
    const int32_t cprog = program_of(material, kTargetVolumeColor);
    const int32_t aprog = program_of(material, kTargetVolumeAbsorptionColor);
    const int32_t eprog = program_of(material, kTargetVolumeEmissionColor);
    if (cprog >= 0 || aprog >= 0) {
        // the colour's part per unit of density (the add-on took it out of sigma_a, sigma_s);
        // without a Color program the colour is the constant color_base
        m.color_scatter = clean_rgb(src.color_scatter);
        m.color_absorb = clean_rgb(src.color_absorb);
        m.color_base = cprog >= 0 ? vec3(1.0f) : clean_rgb(src.color_base);
        // an Absorption Color graph beside another shader's Color graph: its own absorption
        m.absorb_alone = cprog >= 0 && aprog >= 0 ? clean_rgb(src.absorb_alone) : vec3(0.0f);
        if (max_component(m.color_scatter + m.color_absorb + m.absorb_alone) > 0.0f) {
            if (m.color_grid >= 0)
                warnings_.push_back("medium '" + src.name + "': a colour grid and a graph on "
                                    "the Color or Absorption Color: the grid is not rendered");
            m.color_grid = -1;
            m.color_prog = cprog;
            m.absorb_prog =
                max_component(m.color_absorb + m.absorb_alone) > 0.0f ? aprog : -1;
            if (max_component(m.color_scatter) > 0.0f) m.scatters = 1u;
        }
    }
    if (eprog >= 0) {
        m.flame_emission = clean_rgb(src.flame_emission);
        if (max_component(m.flame_emission) > 0.0f) {
            m.emission_color_prog = eprog;
            m.emits = 1u;
        }
    }
    // a mesh volume's Emission Strength graph: flame_emission (the weight x the constant
    // Emission Color, or the weight where a colour graph gives it) x max(its value, 0) per
    // point (scene/medium_fire.h; a Volume object's: build_media, beside its grids)
    const int32_t sprog = program_of(material, kTargetVolumeEmission);
    if (sprog >= 0 && m.density_grid < 0) {
        m.flame_emission = clean_rgb(src.flame_emission);
        if (max_component(m.flame_emission) > 0.0f) {
            m.emission_prog = sprog;
            m.emits = 1u;
        }
    }
}

Vec3 HostScene::color_prog_unit(int32_t med, Vec3 lo, Vec3 hi, bool* ok) const {
    const Medium& m = media_[size_t(med)];
    SceneView host = view_;
    host.media = media_.data();
    // c's interval (the program's, else color_base) and the absorption factor's top
    Interval c[3] = {{m.color_base.x, m.color_base.x}, {m.color_base.y, m.color_base.y},
                     {m.color_base.z, m.color_base.z}};
    float ka[3] = {1.0f, 1.0f, 1.0f};
    *ok = true;
    if (m.color_prog >= 0 &&
        !program_bound(host, programs_[size_t(m.color_prog)], med, lo, hi, c, 3))
        *ok = false;
    if (m.absorb_prog >= 0) {
        Interval a[3];
        if (!program_bound(host, programs_[size_t(m.absorb_prog)], med, lo, hi, a, 3)) {
            *ok = false;
        } else {
            for (int k = 0; k < 3; ++k)
                ka[k] = std::fmax(1.0f - std::sqrt(std::fmin(std::fmax(a[k].lo, 0.0f), 1e9f)),
                                  0.0f);
        }
    }
    if (!*ok) return vec3(0.0f);
    // (absorb_alone: the absorption factor multiplies it alone, color_absorb max(1 - c, 0))
    const bool alone = max_component(m.absorb_alone) > 0.0f;
    float sc[3], ab[3];
    for (int k = 0; k < 3; ++k) {
        sc[k] = std::fmin(std::fmax(c[k].hi, 0.0f), 1e9f);
        ab[k] = std::fmax(1.0f - std::fmin(std::fmax(c[k].lo, 0.0f), 1e9f), 0.0f) *
                (alone ? 1.0f : ka[k]);
    }
    return m.color_scatter * Vec3{sc[0], sc[1], sc[2]} + m.color_absorb * Vec3{ab[0], ab[1], ab[2]} +
           m.absorb_alone * Vec3{ka[0], ka[1], ka[2]};
}

Vec3 HostScene::color_prog_fallback(int32_t med, Vec3 lo, Vec3 hi,
                                    const std::string& name) {
    const Medium& m = media_[size_t(med)];
    // the absorption's factors are at most 1 (a true bound); the scattering's the colour's
    // largest value on a lattice x 1.5 (color_base without a Color program: exact)
    if (m.color_prog < 0) return m.color_scatter * m.color_base + m.color_absorb + m.absorb_alone;
    if (!(max_component(m.color_scatter) > 0.0f))  // absorbing only
        return m.color_absorb + m.absorb_alone;
    SceneView host = view_;
    host.media = media_.data();
    constexpr int kLattice = 24;
    Vec3 cmax = vec3(0.0f);
    for (int z = 0; z <= kLattice; ++z)
        for (int y = 0; y <= kLattice; ++y)
            for (int x = 0; x <= kLattice; ++x) {
                const Vec3 f{float(x) / kLattice, float(y) / kLattice, float(z) / kLattice};
                const Vec3 c = medium_color_at(host, m.color_prog,
                                               medium_shade_point(med, lo + (hi - lo) * f,
                                                                  Vec3{0, 0, 1}));
                cmax = Vec3{std::fmax(cmax.x, c.x), std::fmax(cmax.y, c.y),
                            std::fmax(cmax.z, c.z)};
            }
    warnings_.push_back("medium '" + name + "': its colour's node graph has no bound Lantern "
                        "can compute (a node without an interval rule, or an unbounded value); "
                        "its majorant takes the largest colour on a lattice x 1.5, which may "
                        "miss peaks (biased there)");
    return m.color_scatter * (cmax * 1.5f) + m.color_absorb + m.absorb_alone;
}

float HostScene::mesh_color_majorant(int32_t med, Vec3 lo, Vec3 hi, const std::string& name) {
    const Medium& m = media_[size_t(med)];
    SceneView host = view_;
    host.media = media_.data();
    const Vec3 unit = m.sigma_a + m.sigma_s, base = m.sigma_a0 + m.sigma_s0;
    constexpr int kSplit = 12;
    const Vec3 step = (hi - lo) * (1.0f / kSplit);
    float mu = 0.0f;
    bool ok = true;
    for (int z = 0; z < kSplit && ok; ++z)
        for (int y = 0; y < kSplit && ok; ++y)
            for (int x = 0; x < kSplit && ok; ++x) {
                const Vec3 a = lo + step * Vec3{float(x), float(y), float(z)};
                const Vec3 c{x + 1 == kSplit ? hi.x : a.x + step.x,
                             y + 1 == kSplit ? hi.y : a.y + step.y,
                             z + 1 == kSplit ? hi.z : a.z + step.z};
                float d = 1.0f;
                bool dok = true, cok = true;
                if (m.density_prog >= 0) {
                    Interval r[3];
                    dok = program_bound(host, programs_[size_t(m.density_prog)], med, a, c, r, 1);
                    d = std::fmin(std::fmax(r[0].hi, 0.0f), 1e9f);
                }
                const Vec3 u = unit + color_prog_unit(med, a, c, &cok);
                ok = dok && cok;
                mu = std::fmax(mu, max_component(base + u * d));
            }
    if (ok) return mu;
    // no bound: the colour's lattice bound times the density's (build_hetero's, kept in
    // density_max; 1 without a density program)
    const float d = m.density_prog >= 0 ? m.density_max : 1.0f;
    bool cok = false;
    Vec3 u = color_prog_unit(med, lo, hi, &cok);
    if (!cok) u = color_prog_fallback(med, lo, hi, name);
    return max_component(base + (unit + u) * d);
}

void HostScene::grid_box_world(const DensityGrid& g, const float lo[3], const float hi[3],
                               Vec3* wlo, Vec3* whi) const {
    const float* to_world = grid_index_to_world_.data() + 16 * size_t(&g - grids_.data());
    *wlo = vec3(kInf);
    *whi = vec3(-kInf);
    for (int k = 0; k < 8; ++k) {
        const float q[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        float w[3];
        for (int r = 0; r < 3; ++r)
            w[r] = to_world[4 * r] * q[0] + to_world[4 * r + 1] * q[1] +
                   to_world[4 * r + 2] * q[2] + to_world[4 * r + 3];
        *wlo = Vec3{std::fmin(wlo->x, w[0]), std::fmin(wlo->y, w[1]), std::fmin(wlo->z, w[2])};
        *whi = Vec3{std::fmax(whi->x, w[0]), std::fmax(whi->y, w[1]), std::fmax(whi->z, w[2])};
    }
}

}  // namespace lantern
