// The majorant bricks of a Volume object's medium at scene load (scene/medium_majorant.h,
// docs/volumes.md): the density grid cut into bricks of kMajorantBrick^3 voxels, each holding
// the extinction of the largest voxel that a trilinear lookup inside it can read (with one voxel
// of margin each way against rounding in the walk), times the extinction per unit density, plus
// the world's part. An emitting medium keeps at least about two tentative collisions per brick
// width everywhere (its emission is estimated at them).
#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace lantern {

void HostScene::build_majorant_grid(int32_t med) {
    Medium& m = media_[size_t(med)];
    const DensityGrid& g = grids_[size_t(m.density_grid)];
    if (g.nx <= 0 || g.ny <= 0 || g.nz <= 0) return;  // empty: the constant majorant
    const int B = kMajorantBrick;
    // index space q (voxel centres at integers; the support is (-1, n)) to brick space
    // u = (q + 1) / B: brick b covers q in [b B - 1, (b + 1) B - 1), whose lookups read voxels
    // b B - 1 .. (b + 1) B - 1 (one more each way as margin)
    const int n[3] = {g.nx, g.ny, g.nz};
    int nb[3];
    for (int k = 0; k < 3; ++k) nb[k] = (n[k] + 1 + B - 1) / B;
    MajorantGrid mg{};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) mg.world_to_brick.m[r][c] = g.world_to_index.m[r][c] / float(B);
        mg.world_to_brick.m[r][3] += 1.0f / float(B);
    }
    mg.nx = nb[0];
    mg.ny = nb[1];
    mg.nz = nb[2];
    mg.offset = majorant_values_.size();
    const Vec3 unit = m.sigma_a + m.sigma_s;  // extinction per unit density
    const Vec3 base = m.sigma_a0 + m.sigma_s0;
    // the emission's floor: two collisions per brick width (an emitting medium only)
    float floor_mu = 0.0f;
    if (m.emits) {
        const Vec3 e = g.world_to_index.vector(Vec3{1.0f, 1.0f, 1.0f});  // voxels per metre x sqrt 3
        floor_mu = 2.0f * length(e) / (std::sqrt(3.0f) * float(B));
    }
    mg.outside = std::fmax(max_component(base), floor_mu);
    const float* vox = grid_voxels_.data() + g.offset;
    auto voxel = [&](int i, int j, int k) {
        return vox[(size_t(k) * size_t(g.ny) + size_t(j)) * size_t(g.nx) + size_t(i)];
    };
    majorant_values_.resize(majorant_values_.size() + size_t(nb[0]) * nb[1] * nb[2]);
    float* out = majorant_values_.data() + mg.offset;
    for (int bk = 0; bk < nb[2]; ++bk)
        for (int bj = 0; bj < nb[1]; ++bj)
            for (int bi = 0; bi < nb[0]; ++bi) {
                const int lo[3] = {std::max(bi * B - 2, 0), std::max(bj * B - 2, 0),
                                   std::max(bk * B - 2, 0)};
                const int hi[3] = {std::min((bi + 1) * B, n[0] - 1),
                                   std::min((bj + 1) * B, n[1] - 1),
                                   std::min((bk + 1) * B, n[2] - 1)};
                float dmax = 0.0f;
                if (m.density_prog >= 0) {
                    // a density program: its bound over the brick's lookups (one voxel of
                    // margin each way, as the voxels'), else the medium's (build_grid_medium)
                    dmax = program_density_bound(med, g, float(bi * B - 2), float(bj * B - 2),
                                                 float(bk * B - 2), float((bi + 1) * B),
                                                 float((bj + 1) * B), float((bk + 1) * B));
                    if (!(dmax >= 0.0f)) dmax = m.density_max;
                } else {
                    for (int k = lo[2]; k <= hi[2]; ++k)
                        for (int j = lo[1]; j <= hi[1]; ++j)
                            for (int i = lo[0]; i <= hi[0]; ++i)
                                dmax = std::fmax(dmax, voxel(i, j, k));
                }
                Vec3 u = unit;
                if (m.color_grid >= 0) {  // the colour's part, per channel over the brick
                    const float qlo[3] = {float(bi * B - 2), float(bj * B - 2), float(bk * B - 2)};
                    const float qhi[3] = {float((bi + 1) * B), float((bj + 1) * B),
                                          float((bk + 1) * B)};
                    u = u + color_bound(m, g, qlo, qhi);
                } else if (m.color_prog >= 0 || m.absorb_prog >= 0) {  // colour programs' bound
                    const float qlo[3] = {float(bi * B - 2), float(bj * B - 2), float(bk * B - 2)};
                    const float qhi[3] = {float((bi + 1) * B), float((bj + 1) * B),
                                          float((bk + 1) * B)};
                    Vec3 wlo, whi;
                    grid_box_world(g, qlo, qhi, &wlo, &whi);
                    bool ok = false;
                    const Vec3 c = color_prog_unit(med, wlo, whi, &ok);
                    u = u + (ok ? c : color_prog_whole_);  // else the medium's (build_grid_medium)
                }
                const float mu = max_component(base + u * std::fmin(dmax, 1e9f));
                out[(size_t(bk) * size_t(nb[1]) + size_t(bj)) * size_t(nb[0]) + size_t(bi)] =
                    std::fmax(mu, floor_mu);
            }
    m.majorant_grid = int32_t(majorant_grids_.size());
    majorant_grids_.push_back(mg);
    view_.majorant_grids = majorant_grids_.data();
    view_.majorant_values = majorant_values_.data();
    view_.num_majorant_grids = int32_t(majorant_grids_.size());
}

}  // namespace lantern
