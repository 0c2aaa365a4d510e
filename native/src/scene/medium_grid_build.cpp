// Volume objects' density grids at scene load (scene/medium_grid.h, docs/volumes.md): each
// SceneInput::grids block checked and cleaned (non-finite or negative voxels 0, enormous ones
// 1e9, each with a warning by the grid's name), its world-to-index map, its largest voxel; and
// the majorant of a medium whose density is a grid (exact: a trilinear value never exceeds the
// largest of its voxels).
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "scene/medium_fire.h"
#include "scene/program_bound.h"
#include "scene/scene.h"

namespace lantern {

namespace {

// The inverse of the affine map m (rows; the last row 0 0 0 1), false when singular.
bool invert_affine(const float m[16], Transform* out) {
    double a[3][3], t[3];
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) a[r][c] = m[4 * r + c];
        t[r] = m[4 * r + 3];
    }
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(std::fabs(det) > 1e-30) || !std::isfinite(det)) return false;
    double inv[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            inv[r][c] = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
        }
    for (int r = 0; r < 3; ++r) {
        double o = 0.0;
        for (int c = 0; c < 3; ++c) {
            out->m[r][c] = float(inv[r][c]);
            o -= inv[r][c] * t[c];
        }
        out->m[r][3] = float(o);
    }
    return true;
}

}  // namespace

void HostScene::build_grids(const SceneInput& in) {
    uint64_t total = 0;
    for (const GridInput& g : in.grids) {
        if (g.channels != 1 && g.channels != 3)
            throw std::invalid_argument("grid '" + g.name + "': " + std::to_string(g.channels) +
                                        " channels (1: a float grid, 3: a colour grid)");
        uint64_t n = uint64_t(g.channels);
        for (int k = 0; k < 3; ++k) {
            if (g.dims[k] < 0)
                throw std::invalid_argument("grid '" + g.name + "': negative dimensions");
            n *= uint64_t(g.dims[k]);
        }
        if (n != g.voxels.size())
            throw std::invalid_argument("grid '" + g.name + "': " +
                                        std::to_string(g.voxels.size()) +
                                        " floats for dimensions " + std::to_string(g.dims[0]) +
                                        " x " + std::to_string(g.dims[1]) + " x " +
                                        std::to_string(g.dims[2]));
        total += n;
    }
    if (total > kMaxGridVoxels)
        throw std::invalid_argument("the scene's grids hold " + std::to_string(total) +
                                    " floats, above the limit of " +
                                    std::to_string(kMaxGridVoxels));
    grids_.clear();
    grid_names_.clear();
    grid_index_to_world_.clear();
    majorant_grids_.clear();
    majorant_values_.clear();
    grid_voxels_.clear();
    grid_voxels_.reserve(size_t(total));
    for (const GridInput& g : in.grids) {
        DensityGrid d{};
        d.nx = g.dims[0];
        d.ny = g.dims[1];
        d.nz = g.dims[2];
        d.channels = g.channels;
        d.offset = grid_voxels_.size();
        if (!invert_affine(g.index_to_world, &d.world_to_index)) {
            warnings_.push_back("grid '" + g.name + "': its transform is singular or not "
                                "finite; the volume renders empty");
            d.nx = d.ny = d.nz = 0;
        }
        size_t bad = 0, huge = 0, negative = 0;
        float mx = 0.0f;
        for (float v : g.voxels) {
            if (std::isnan(v) || v < 0.0f) {
                bad += std::isnan(v) ? 1 : 0;
                negative += v < 0.0f ? 1 : 0;
                v = 0.0f;
            } else if (v > 1e9f) {
                ++huge;
                v = 1e9f;
            }
            mx = std::fmax(mx, v);
            grid_voxels_.push_back(v);
        }
        if (bad)
            warnings_.push_back("grid '" + g.name + "': " + std::to_string(bad) +
                                (g.channels == 3 ? " NaN colour components" : " NaN voxels") +
                                " are taken as 0");
        // a negative density is none (Cycles, silently); Cycles keeps a negative colour (it
        // would scatter negatively), Lantern takes it as 0 and says so
        if (negative && g.channels == 3)
            warnings_.push_back("grid '" + g.name + "': " + std::to_string(negative) +
                                " negative colour components are taken as 0");
        if (huge)
            warnings_.push_back("grid '" + g.name + "': " + std::to_string(huge) +
                                " voxels above 1e9 (or infinite) are taken as 1e9");
        d.max_value = d.nx > 0 ? mx : 0.0f;
        grids_.push_back(d);
        grid_names_.push_back(g.name);
        grid_index_to_world_.insert(grid_index_to_world_.end(), g.index_to_world,
                                    g.index_to_world + 16);
    }
    view_.grids = grids_.empty() ? nullptr : grids_.data();
    view_.grid_voxels = grid_voxels_.empty() ? nullptr : grid_voxels_.data();
    view_.num_grids = int32_t(grids_.size());
}

// A Volume object's fire (scene/medium_fire.h): the material's temperature and flame grids and
// the medium's blackbody and flame parameters, checked (a grid index out of range is an error;
// a parameter that is not finite or negative is 0, with a warning).
void HostScene::grid_fire(Medium& m, const MaterialInput& mi, const MediumInput& src) {
    auto check = [&](int k, const char* what) {
        if (k < -1 || k >= int32_t(grids_.size()))
            throw std::invalid_argument("material '" + mi.name + "': " + what + " grid " +
                                        std::to_string(k) + " out of range (the scene has " +
                                        std::to_string(grids_.size()) + ")");
        return int32_t(k);
    };
    auto clean = [&](float v, const char* what) {
        if (std::isfinite(v) && v >= 0.0f) return v;
        warnings_.push_back("medium '" + src.name + "': " + what + " " + std::to_string(v) +
                            " is taken as 0");
        return 0.0f;
    };
    auto clean3 = [&](Vec3 v, const char* what) {
        return Vec3{clean(v.x, what), clean(v.y, what), clean(v.z, what)};
    };
    m.temperature_grid = check(mi.temperature_grid, "temperature");
    m.flame_grid = check(mi.flame_grid, "flame");
    for (int32_t k : {m.density_grid, m.temperature_grid, m.flame_grid})
        if (k >= 0 && grids_[size_t(k)].channels != 1)
            throw std::invalid_argument("material '" + mi.name + "': grid '" +
                                        grid_names_[size_t(k)] + "' is a colour (vec3) grid; a "
                                        "density, temperature or flame needs a float grid");
    // the colour grid (Principled Volume's Color Attribute)
    m.color_grid = check(mi.color_grid, "colour");
    if (m.color_grid >= 0 && grids_[size_t(m.color_grid)].channels != 3)
        throw std::invalid_argument("material '" + mi.name + "': colour grid '" +
                                    grid_names_[size_t(m.color_grid)] + "' is a float grid; "
                                    "a colour needs a vec3 grid (3 channels)");
    m.color_scatter = clean3(src.color_scatter, "colour scattering");
    m.color_absorb = clean3(src.color_absorb, "colour absorption");
    m.color_base = clean3(src.color_base, "Color");
    if (m.color_grid >= 0 && max_component(m.color_scatter) > 0.0f) m.scatters = 1u;
    if (m.color_grid >= 0 && !(max_component(m.color_scatter + m.color_absorb) > 0.0f))
        m.color_grid = -1;  // the colour changes nothing
    m.bb_intensity = std::fmin(clean(src.blackbody_intensity, "Blackbody Intensity"), 1e9f);
    m.bb_temperature = std::fmin(clean(src.temperature, "Temperature"), 1e6f);
    m.bb_tint = clean3(src.blackbody_tint, "Blackbody Tint");
    m.flame_emission = clean3(src.flame_emission, "flame emission");
    if (m.flame_grid >= 0 && max_component(m.flame_emission) > 0.0f) m.emits = 1u;
    if (m.temperature_grid >= 0 && max_component(m.bb_tint) > 0.0f &&
        (m.bb_intensity > 0.0f)) {
        m.emits = 1u;
        view_.blackbody_table = blackbody_table_host();
    } else {
        m.temperature_grid = -1;  // emits nothing
    }
    if (m.flame_grid >= 0 && !(max_component(m.flame_emission) > 0.0f)) m.flame_grid = -1;
}

// The bound of medium med's density program over the points of index box [lo, hi] of grid g
// (scene/program_bound.h: a true bound, clamped to [0, 1e9] as medium_density clamps), or -1
// where the program has none.
float HostScene::program_density_bound(int32_t med, const DensityGrid& g, float lx, float ly,
                                       float lz, float hx, float hy, float hz) const {
    const Medium& m = media_[size_t(med)];
    const float* to_world = grid_index_to_world_.data() + 16 * size_t(&g - grids_.data());
    Vec3 wlo = vec3(kInf), whi = vec3(-kInf);
    for (int k = 0; k < 8; ++k) {
        const float q[3] = {k & 1 ? hx : lx, k & 2 ? hy : ly, k & 4 ? hz : lz};
        float w[3];
        for (int r = 0; r < 3; ++r)
            w[r] = to_world[4 * r] * q[0] + to_world[4 * r + 1] * q[1] +
                   to_world[4 * r + 2] * q[2] + to_world[4 * r + 3];
        wlo = Vec3{std::fmin(wlo.x, w[0]), std::fmin(wlo.y, w[1]), std::fmin(wlo.z, w[2])};
        whi = Vec3{std::fmax(whi.x, w[0]), std::fmax(whi.y, w[1]), std::fmax(whi.z, w[2])};
    }
    SceneView host = view_;
    host.media = media_.data();
    Interval b[3];
    if (!program_bound(host, programs_[size_t(m.density_prog)], med, wlo, whi, b, 1)) return -1.0f;
    return std::fmin(std::fmax(b[0].hi, 0.0f), 1e9f);
}

// The largest extinction per unit density of m's colour part over the points whose index in
// density grid g lies in the box [lo, hi] (per channel: color_scatter x the largest colour
// component + color_absorb x max(1 - base x the smallest, 0), over the colour voxels that a
// trilinear lookup at those points can read, one more each way; a lookup reaching outside the
// colour block reads 0 there). The colour grid may have a transform of its own.
Vec3 HostScene::color_bound(const Medium& m, const DensityGrid& g, const float lo[3],
                            const float hi[3]) const {
    const DensityGrid& c = grids_[size_t(m.color_grid)];
    const float* to_world = grid_index_to_world_.data() + 16 * size_t(&g - grids_.data());
    float qmin[3] = {1e30f, 1e30f, 1e30f}, qmax[3] = {-1e30f, -1e30f, -1e30f};
    for (int k = 0; k < 8; ++k) {
        const float p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        Vec3 w;
        float* wp[3] = {&w.x, &w.y, &w.z};
        for (int r = 0; r < 3; ++r)
            *wp[r] = to_world[4 * r] * p[0] + to_world[4 * r + 1] * p[1] +
                     to_world[4 * r + 2] * p[2] + to_world[4 * r + 3];
        const Vec3 q = c.world_to_index.point(w);
        const float qa[3] = {q.x, q.y, q.z};
        for (int a = 0; a < 3; ++a) {
            qmin[a] = std::fmin(qmin[a], qa[a]);
            qmax[a] = std::fmax(qmax[a], qa[a]);
        }
    }
    const int n[3] = {c.nx, c.ny, c.nz};
    int a0[3], a1[3];
    bool outside = false;
    for (int a = 0; a < 3; ++a) {
        const float f0 = std::floor(qmin[a]) - 1.0f, f1 = std::floor(qmax[a]) + 2.0f;
        if (!(f1 >= 0.0f && f0 <= float(n[a] - 1))) return m.color_absorb;  // all outside: c = 0
        outside = outside || f0 < 0.0f || f1 > float(n[a] - 1);
        a0[a] = int(std::fmax(f0, 0.0f));
        a1[a] = int(std::fmin(f1, float(n[a] - 1)));
    }
    Vec3 cmax = vec3(0.0f), cmin = outside ? vec3(0.0f) : vec3(1e30f);
    const float* vox = grid_voxels_.data() + c.offset;
    for (int k = a0[2]; k <= a1[2]; ++k)
        for (int j = a0[1]; j <= a1[1]; ++j)
            for (int i = a0[0]; i <= a1[0]; ++i) {
                const float* x = vox + 3 * ((size_t(k) * size_t(c.ny) + size_t(j)) * c.nx + i);
                cmax = Vec3{std::fmax(cmax.x, x[0]), std::fmax(cmax.y, x[1]),
                            std::fmax(cmax.z, x[2])};
                cmin = Vec3{std::fmin(cmin.x, x[0]), std::fmin(cmin.y, x[1]),
                            std::fmin(cmin.z, x[2])};
            }
    const Vec3 ab = vec3(1.0f) - m.color_base * cmin;
    return m.color_scatter * cmax +
           m.color_absorb * Vec3{std::fmax(ab.x, 0.0f), std::fmax(ab.y, 0.0f),
                                 std::fmax(ab.z, 0.0f)};
}

// The majorant of heterogeneous medium med whose density is grid density_grid, and its bricks.
void HostScene::build_grid_medium(int32_t med, const std::string& name) {
    const ProgramBoundScope bound_scope;  // the bounds below (and the bricks') share it
    Medium& m = media_[size_t(med)];
    const DensityGrid& g = grids_[size_t(m.density_grid)];
    if (m.density_prog >= 0) {
        // a density program (a node graph reading grids): its interval bound over the grid's
        // support; without one, build_hetero's lattice maximum x 1.5 stays (not a true bound)
        const float b = program_density_bound(med, g, -1.0f, -1.0f, -1.0f, float(g.nx),
                                              float(g.ny), float(g.nz));
        if (b >= 0.0f)
            m.density_max = b;
        else
            warnings_.push_back(unbounded_density_warning(name));
    } else {
        m.density_max = std::fmin(g.max_value, 1e9f);
    }
    // the extinction per unit density at most: with a colour grid, its largest component scales
    // the scattering and the absorption's factor max(1 - base c, 0) is at most 1
    Vec3 unit = m.color_grid >= 0
                    ? m.sigma_a + m.sigma_s + m.color_absorb +
                          m.color_scatter * grids_[size_t(m.color_grid)].max_value
                    : m.sigma_a + m.sigma_s;
    if (m.color_prog >= 0 || m.absorb_prog >= 0) {
        // a colour program (scene/medium_color_build.cpp): its bound over the grid's support,
        // else its lattice maximum x 1.5 (warned)
        const float qlo[3] = {-1.0f, -1.0f, -1.0f};
        const float qhi[3] = {float(g.nx), float(g.ny), float(g.nz)};
        Vec3 wlo, whi;
        grid_box_world(g, qlo, qhi, &wlo, &whi);
        bool ok = false;
        Vec3 c = color_prog_unit(med, wlo, whi, &ok);
        if (!ok) c = color_prog_fallback(med, wlo, whi, name);
        color_prog_whole_ = c;
        unit = unit + c;
    }
    m.majorant = max_component(m.sigma_a0 + m.sigma_s0 + unit * m.density_max);
    if (m.emits && !(m.majorant > 0.0f)) {
        // emission is estimated at tentative collisions: about one per grid diagonal
        const Vec3 e = g.world_to_index.vector(Vec3{1.0f, 1.0f, 1.0f});
        const float voxels =
            std::sqrt(float(g.nx) * g.nx + float(g.ny) * g.ny + float(g.nz) * g.nz);
        m.majorant = std::fmax(length(e), 1e-6f) / std::fmax(voxels, 1.0f);
    }
    // the bricks (scene/medium_majorant_build.cpp); LANTERN_MAJORANT_BRICKS=0 keeps the one
    // majorant (benchmarks: bench/fire_majorant.py measures both)
    const char* bricks = std::getenv("LANTERN_MAJORANT_BRICKS");
    if (!(bricks && std::string(bricks) == "0")) build_majorant_grid(med);
}

}  // namespace lantern
