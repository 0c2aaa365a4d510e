// Heterogeneous media at scene load (scene/medium_hetero.h, docs/volumes.md): the medium of a
// material whose volume Density is driven by a node program (kTargetDensity), its attribute
// channels as affine maps of the world position (fitted to the vertices of the material's
// triangles: Generated and Object coordinates are affine in position for an undeformed mesh)
// and its majorant (the program's interval bound over the triangles' bounds, scene/
// program_bound.h; where an op has no rule, the density's largest value on a lattice with a
// margin, which a peak between lattice points exceeds: a bias there, with a warning).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "scene/medium_hetero.h"
#include "scene/program_bound.h"
#include "scene/scene.h"

namespace lantern {

namespace {

// Solves the 4x4 system a x = b (Gaussian elimination, partial pivoting); false if singular.
bool solve4(double a[4][4], double b[4]) {
    for (int c = 0; c < 4; ++c) {
        int piv = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
        if (!(std::fabs(a[piv][c]) > 1e-30)) return false;
        std::swap(a[c], a[piv]);
        std::swap(b[c], b[piv]);
        for (int r = c + 1; r < 4; ++r) {
            const double f = a[r][c] / a[c][c];
            for (int k = c; k < 4; ++k) a[r][k] -= f * a[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int c = 3; c >= 0; --c) {
        for (int k = c + 1; k < 4; ++k) b[c] -= a[c][k] * b[k];
        b[c] /= a[c][c];
    }
    return true;
}

// The largest density (program_run's x, as medium_density reads it, in [0, 1e9]) of program
// p over the world box [lo, hi]: the largest interval bound over kSplit^3 sub-boxes (an
// interval bound over the whole box overestimates where the program's value varies), or -1
// where some op has no rule.
float mesh_density_bound(const SceneView& s, const MaterialProgram& p, int32_t med, Vec3 lo,
                         Vec3 hi) {
    constexpr int kSplit = 16;
    const Vec3 step = (hi - lo) * (1.0f / kSplit);
    float b = 0.0f;
    for (int z = 0; z < kSplit; ++z)
        for (int y = 0; y < kSplit; ++y)
            for (int x = 0; x < kSplit; ++x) {
                const Vec3 a = lo + step * Vec3{float(x), float(y), float(z)};
                const Vec3 c{x + 1 == kSplit ? hi.x : a.x + step.x,
                             y + 1 == kSplit ? hi.y : a.y + step.y,
                             z + 1 == kSplit ? hi.z : a.z + step.z};
                Interval r[3];
                if (!program_bound(s, p, med, a, c, r, 1)) return -1.0f;
                b = std::fmax(b, r[0].hi);
            }
    // a density of 0 everywhere: program_bound's widening (1e-30) is not a majorant to keep
    // (an emitting medium then takes its floor of collisions, below)
    return b <= 2e-30f ? 0.0f : std::fmin(b, 1e9f);
}

// The largest emission of a mesh volume's emission programs over the world box [lo, hi]
// (scene/medium_fire.h medium_emission_at): flame_emission x c x k, c the Emission Color
// program's colour, k the Emission Strength program's value (each 1 without its program, both
// clamped as there), over kSplit^3 sub-boxes: the largest channel's top (0: no point emits
// more than 1e-5 of the programs' range above 0); -1 where an op has no rule.
float mesh_emission_bound(const SceneView& host, const std::vector<MaterialProgram>& programs,
                          const Medium& m, int32_t med, Vec3 lo, Vec3 hi) {
    constexpr int kSplit = 12;
    const Vec3 step = (hi - lo) * (1.0f / kSplit);
    float e = 0.0f;
    for (int z = 0; z < kSplit; ++z)
        for (int y = 0; y < kSplit; ++y)
            for (int x = 0; x < kSplit; ++x) {
                const Vec3 a = lo + step * Vec3{float(x), float(y), float(z)};
                const Vec3 b{x + 1 == kSplit ? hi.x : a.x + step.x,
                             y + 1 == kSplit ? hi.y : a.y + step.y,
                             z + 1 == kSplit ? hi.z : a.z + step.z};
                Interval c[3] = {{1.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 1.0f}}, k[3] = {{1.0f, 1.0f}};
                if (m.emission_color_prog >= 0 &&
                    !program_bound(host, programs[size_t(m.emission_color_prog)], med, a, b, c,
                                   3))
                    return -1.0f;
                if (m.emission_prog >= 0 &&
                    !program_bound(host, programs[size_t(m.emission_prog)], med, a, b, k, 1))
                    return -1.0f;
                // program_bound widens by 1e-5 of the interval's size: a top within that of 0
                // is a value <= 0 (a strength Lantern takes as 0)
                auto top = [](Interval v) {
                    const float m = 1.1e-5f * std::fmax(std::fabs(v.lo), std::fabs(v.hi)) + 1e-29f;
                    return v.hi <= m ? 0.0f : std::fmin(v.hi, 1e9f);
                };
                const Vec3 ch{top(c[0]), top(c[1]), top(c[2])};
                e = std::fmax(e, max_component(m.flame_emission * ch) * top(k[0]));
            }
    return e;
}

// The majorant bricks of a mesh volume's density program (volleft; scene/medium_majorant.h):
// kMeshBricks^3 bricks over the world box [lo, hi], each the program's interval bound over
// the brick's box widened by 2 % of a brick each way (the walk's brick and the point's may
// differ by rounding at a face), in [0, 1e9] as medium_density clamps. False where a brick
// has no bound or the box is flat.
constexpr int kMeshBricks = 16;

bool mesh_brick_densities(const SceneView& s, const MaterialProgram& p, int32_t med, Vec3 lo,
                          Vec3 hi, std::vector<float>& out) {
    const int n = kMeshBricks;
    const Vec3 step = (hi - lo) * (1.0f / float(n));
    if (!(step.x > 0.0f && step.y > 0.0f && step.z > 0.0f)) return false;
    const float scale = std::fmax(std::fmax(std::fabs(lo.x), std::fabs(lo.y)),
                                  std::fmax(std::fmax(std::fabs(lo.z), std::fabs(hi.x)),
                                            std::fmax(std::fabs(hi.y), std::fabs(hi.z))));
    const Vec3 margin = step * 0.02f + vec3(1e-5f * scale);
    out.assign(size_t(n) * n * n, 0.0f);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const Vec3 a = lo + step * Vec3{float(x), float(y), float(z)};
                Interval r[3];
                if (!program_bound(s, p, med, a - margin, a + step + margin, r, 1)) return false;
                const float d = r[0].hi <= 2e-30f ? 0.0f : std::fmin(r[0].hi, 1e9f);
                out[(size_t(z) * n + size_t(y)) * n + size_t(x)] = d;
            }
    return true;
}

}  // namespace

int32_t HostScene::density_program(size_t material) const {
    return program_of(material, kTargetDensity);
}

int32_t HostScene::program_of(size_t material, int32_t target) const {
    const Material& m = materials_[material];
    if (!(m.tex_flags & kTexProgram)) return -1;
    for (int i = 0; i < m.prog_count; ++i)
        if (programs_[size_t(m.prog_first + i)].target == target) return m.prog_first + i;
    return -1;
}

// The maps of medium `med` (media_ index) from the vertices of material `material`'s
// triangles, and its majorant. Warns (by the medium's name) when a channel its program reads
// is not affine in position (a deformed mesh, or two objects of different texture spaces
// sharing the material): that channel then reads its best affine fit.
void HostScene::build_hetero(int32_t med, size_t material, const std::string& name) {
    const ProgramBoundScope bound_scope;  // the bounds below scan each image texture once
    Medium& m = media_[size_t(med)];
    const int nch = num_attribute_channels_;
    std::vector<uint32_t> verts;
    Vec3 lo = vec3(kInf), hi = vec3(-kInf);
    for (size_t t = 0; t < indices_.size() / 3; ++t) {
        if (tri_material_[t] != material) continue;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = indices_[3 * t + size_t(k)];
            verts.push_back(v);
            const Vec3 q = positions_[v];
            lo = Vec3{std::min(lo.x, q.x), std::min(lo.y, q.y), std::min(lo.z, q.z)};
            hi = Vec3{std::max(hi.x, q.x), std::max(hi.y, q.y), std::max(hi.z, q.z)};
        }
    }
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    if (nch > 0) {
        if (medium_maps_.empty()) medium_maps_.assign(media_.size() * size_t(nch), Transform{});
        // the channels the medium's programs read (kOpInput, mode 4: an attribute)
        std::vector<bool> read(size_t(nch), false);
        for (int32_t prog : {m.density_prog, m.color_prog, m.emission_color_prog, m.absorb_prog,
                             m.emission_prog}) {
            if (prog < 0) continue;
            const MaterialProgram& p = programs_[size_t(prog)];
            for (int k = 0; k < p.num_instr; ++k) {
                const NodeInstr& n = program_code_[size_t(p.first_instr + k)];
                if (n.op == kOpInput && n.mode == 4 && n.aux >= 0 && n.aux < nch)
                    read[size_t(n.aux)] = true;
            }
        }
        // least squares per channel over the vertices: attr = M (p, 1)
        double ata[4][4] = {};
        for (uint32_t v : verts) {
            const double x[4] = {positions_[v].x, positions_[v].y, positions_[v].z, 1.0};
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) ata[r][c] += x[r] * x[c];
        }
        for (int c = 0; c < nch; ++c) {
            Transform tf{};
            double worst = 0.0, scale = 0.0;
            bool ok = true;
            for (int j = 0; j < 3 && ok; ++j) {
                double atb[4] = {}, a[4][4];
                for (uint32_t v : verts) {
                    const double x[4] = {positions_[v].x, positions_[v].y, positions_[v].z, 1.0};
                    const double y = attributes_[size_t(v) * 3 * size_t(nch) + 3 * size_t(c) +
                                                 size_t(j)];
                    for (int r = 0; r < 4; ++r) atb[r] += x[r] * y;
                }
                std::copy(&ata[0][0], &ata[0][0] + 16, &a[0][0]);
                ok = solve4(a, atb);
                for (int r = 0; r < 4 && ok; ++r) tf.m[j][r] = float(atb[r]);
            }
            if (!ok) continue;  // flat or degenerate: the channel reads 0
            for (uint32_t v : verts) {
                const Vec3 f = tf.point(positions_[v]);
                const float* y = &attributes_[size_t(v) * 3 * size_t(nch) + 3 * size_t(c)];
                worst = std::max({worst, std::fabs(double(f.x) - y[0]),
                                  std::fabs(double(f.y) - y[1]), std::fabs(double(f.z) - y[2])});
                scale = std::max({scale, std::fabs(double(y[0])), std::fabs(double(y[1])),
                                  std::fabs(double(y[2]))});
            }
            if (read[size_t(c)] && worst > 1e-3 * std::max(scale, 1.0))
                warnings_.push_back("medium '" + name + "': attribute channel " +
                                    std::to_string(c) + " that its node graphs read is not an "
                                    "affine function of position over the mesh (deformed, or "
                                    "the material on objects of different texture spaces); "
                                    "inside the volume it reads its affine fit");
            medium_maps_[size_t(med) * size_t(nch) + size_t(c)] = tf;
        }
        view_.medium_maps = medium_maps_.data();
    }
    // the majorant. A mesh volume's program: its interval bound (scene/program_bound.h), a
    // true bound, where every op it runs has a rule. Else (and for a Volume object's program,
    // which build_grid_medium bounds over its grid, this being its fallback) the density's
    // largest value on a lattice over the bounds, times 1.5, which a peak between lattice
    // points exceeds (biased there): for a mesh volume with a warning
    SceneView host = view_;
    host.media = media_.data();
    const bool mesh_program = m.density_grid < 0 && !verts.empty() && m.density_prog >= 0;
    const float bound =
        mesh_program ? mesh_density_bound(host, programs_[size_t(m.density_prog)], med, lo, hi)
        : m.density_prog < 0 ? 1.0f  // colour programs alone: the density is 1
                             : -1.0f;
    if (bound >= 0.0f) {
        m.density_max = bound;
    } else {
        constexpr int kLattice = 24;
        float dmax = 0.0f;
        if (!verts.empty()) {
            for (int z = 0; z <= kLattice; ++z)
                for (int y = 0; y <= kLattice; ++y)
                    for (int x = 0; x <= kLattice; ++x) {
                        const Vec3 f{float(x) / kLattice, float(y) / kLattice,
                                     float(z) / kLattice};
                        const Vec3 p = lo + (hi - lo) * f;
                        dmax = std::max(dmax, medium_density(host, m, med, p, Vec3{0, 0, 1}));
                    }
        }
        m.density_max = std::min(dmax * 1.5f, 1e9f);
        if (mesh_program) warnings_.push_back(unbounded_density_warning(name));
    }
    m.majorant = max_component(m.sigma_a0 + m.sigma_s0 + (m.sigma_a + m.sigma_s) * m.density_max);
    // a colour program's part (scene/medium_color_build.cpp), over the mesh's sub-boxes
    if ((m.color_prog >= 0 || m.absorb_prog >= 0) && m.density_grid < 0 && !verts.empty())
        m.majorant = mesh_color_majorant(med, lo, hi, name);
    // a mesh volume's emission graphs whose bound is 0 everywhere (a strength of 0 or less:
    // Lantern emits none there) leave the medium's emission to its constant part
    if ((m.emission_prog >= 0 || m.emission_color_prog >= 0) && m.density_grid < 0 &&
        !verts.empty() && mesh_emission_bound(host, programs_, m, med, lo, hi) == 0.0f) {
        m.emission_prog = m.emission_color_prog = -1;
        m.emits = max_component(m.emission) > 0.0f ? 1u : 0u;
    }
    // an emitting medium needs tentative collisions even where nothing extinguishes: its
    // emission is estimated at them (one per bounding-box diagonal on average)
    if (m.emits && !(m.majorant > 0.0f) && !verts.empty())
        m.majorant = 1.0f / std::max(length(hi - lo), 1e-6f);
    // majorant bricks over the mesh's box (a density program with a bound; not where a colour
    // program or emission takes part: they keep the one majorant), as a Volume object's grid
    // has (LANTERN_MAJORANT_BRICKS=0: none, the one majorant)
    const char* bricks = std::getenv("LANTERN_MAJORANT_BRICKS");
    std::vector<float> dens;
    if (mesh_program && bound >= 0.0f && m.majorant > 0.0f && !m.emits && m.color_prog < 0 &&
        m.absorb_prog < 0 && !(bricks && std::string(bricks) == "0") &&
        mesh_brick_densities(host, programs_[size_t(m.density_prog)], med, lo, hi, dens)) {
        const float step[3] = {(hi.x - lo.x) / kMeshBricks, (hi.y - lo.y) / kMeshBricks,
                               (hi.z - lo.z) / kMeshBricks};
        const float o[3] = {lo.x, lo.y, lo.z};
        MajorantGrid mg{};
        for (int r = 0; r < 3; ++r) {
            mg.world_to_brick.m[r][r] = 1.0f / step[r];
            mg.world_to_brick.m[r][3] = -o[r] / step[r];
        }
        mg.nx = mg.ny = mg.nz = kMeshBricks;
        mg.offset = majorant_values_.size();
        mg.outside = m.majorant;  // past the box (rounding at its faces): the medium's bound
        const Vec3 unit = m.sigma_a + m.sigma_s, base = m.sigma_a0 + m.sigma_s0;
        for (float d : dens) majorant_values_.push_back(max_component(base + unit * d));
        m.majorant_grid = int32_t(majorant_grids_.size());
        majorant_grids_.push_back(mg);
        view_.majorant_grids = majorant_grids_.data();
        view_.majorant_values = majorant_values_.data();
        view_.num_majorant_grids = int32_t(majorant_grids_.size());
    }
}

}  // namespace lantern
