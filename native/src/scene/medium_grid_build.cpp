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
        uint64_t n = 1;
        for (int k = 0; k < 3; ++k) {
            if (g.dims[k] < 0)
                throw std::invalid_argument("grid '" + g.name + "': negative dimensions");
            n *= uint64_t(g.dims[k]);
        }
        if (n != g.voxels.size())
            throw std::invalid_argument("grid '" + g.name + "': " +
                                        std::to_string(g.voxels.size()) +
                                        " voxels for dimensions " + std::to_string(g.dims[0]) +
                                        " x " + std::to_string(g.dims[1]) + " x " +
                                        std::to_string(g.dims[2]));
        total += n;
    }
    if (total > kMaxGridVoxels)
        throw std::invalid_argument("the scene's density grids hold " + std::to_string(total) +
                                    " voxels, above the limit of " +
                                    std::to_string(kMaxGridVoxels));
    grids_.clear();
    majorant_grids_.clear();
    majorant_values_.clear();
    grid_voxels_.clear();
    grid_voxels_.reserve(size_t(total));
    for (const GridInput& g : in.grids) {
        DensityGrid d{};
        d.nx = g.dims[0];
        d.ny = g.dims[1];
        d.nz = g.dims[2];
        d.offset = grid_voxels_.size();
        if (!invert_affine(g.index_to_world, &d.world_to_index)) {
            warnings_.push_back("grid '" + g.name + "': its transform is singular or not "
                                "finite; the volume renders empty");
            d.nx = d.ny = d.nz = 0;
        }
        size_t bad = 0, huge = 0;
        float mx = 0.0f;
        for (float v : g.voxels) {
            if (std::isnan(v) || v < 0.0f) {
                bad += std::isnan(v) ? 1 : 0;
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
                                " NaN voxels are taken as 0");
        if (huge)
            warnings_.push_back("grid '" + g.name + "': " + std::to_string(huge) +
                                " voxels above 1e9 (or infinite) are taken as 1e9");
        d.max_value = d.nx > 0 ? mx : 0.0f;
        grids_.push_back(d);
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

// The majorant of heterogeneous medium med whose density is grid density_grid, and its bricks.
void HostScene::build_grid_medium(int32_t med) {
    Medium& m = media_[size_t(med)];
    const DensityGrid& g = grids_[size_t(m.density_grid)];
    m.density_max = std::fmin(g.max_value, 1e9f);
    m.majorant = max_component(m.sigma_a0 + m.sigma_s0 + (m.sigma_a + m.sigma_s) * m.density_max);
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
