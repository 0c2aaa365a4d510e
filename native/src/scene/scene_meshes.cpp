// HostScene's triangles: each mesh's arrays checked and appended (normals, uvs, tangents and
// attribute channels where any mesh has them), triangles beyond the ray queries' range left out
// with a warning, per-triangle material and visibility flags.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace lantern {

void HostScene::add_meshes(const SceneInput& in) {
    bool any_normals = false, any_uvs = false, any_tangents = false;
    bool any_rays_hidden = false;  // some mesh hidden from some kind of ray: tri_rays_
    bool any_terminator = false;   // some smooth-shaded mesh with a terminator offset
    for (const MeshInput& m : in.meshes) {
        if (!(m.terminator >= 0.0f && m.terminator <= 1.0f)) {
            throw std::invalid_argument("mesh '" + m.name + "': terminator offset must be in "
                                        "[0, 1], got " + std::to_string(m.terminator));
        }
        any_terminator |= m.terminator > 0.0f && !m.normals.empty() && !m.flat;
        any_rays_hidden |= (m.rays & kRayKindsAll) != kRayKindsAll;
        any_normals |= !m.normals.empty() && !m.flat;  // (flat: the triangles' own)
        any_uvs |= !m.uvs.empty();
        any_tangents |= !m.tangents.empty();
    }
    for (const MeshInput& m : in.meshes) {
        const size_t nv = m.positions.size() / 3, nt = m.indices.size() / 3;
        if (m.positions.size() % 3 || m.indices.size() % 3) {
            throw std::invalid_argument("mesh '" + m.name + "': positions and indices need 3 values each");
        }
        if (!m.normals.empty() && m.normals.size() != 3 * nv) {
            throw std::invalid_argument("mesh '" + m.name + "': normals must match positions");
        }
        if (!m.uvs.empty() && m.uvs.size() != 2 * nv) {
            throw std::invalid_argument("mesh '" + m.name + "': uvs must have one pair per vertex");
        }
        if (!m.tangents.empty() && m.tangents.size() != 4 * nv) {
            throw std::invalid_argument("mesh '" + m.name + "': tangents need 4 values per vertex");
        }
        if (m.material_ids.size() != nt) {
            throw std::invalid_argument("mesh '" + m.name + "': one material id per triangle needed");
        }
        const uint32_t base = uint32_t(positions_.size());
        MeshRange range{int32_t(tri_material_.size()), 0, int32_t(base), int32_t(nv)};
        add_mesh_attributes(m, nv, size_t(num_attribute_channels_), attributes_);
        for (size_t v = 0; v < nv; ++v) {
            positions_.push_back({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
            if (any_normals) {
                normals_.push_back(m.normals.empty() || m.flat ? Vec3{0, 0, 0}
                                                     : Vec3{m.normals[3 * v], m.normals[3 * v + 1],
                                                            m.normals[3 * v + 2]});
            }
            if (any_uvs) {
                uvs_.push_back(m.uvs.empty() ? Vec2{0, 0} : Vec2{m.uvs[2 * v], m.uvs[2 * v + 1]});
            }
            if (any_tangents) {  // a mesh without: zero, i.e. the uv-derived tangent per triangle
                for (int c = 0; c < 4; ++c) {
                    float x = m.tangents.empty() ? 0.0f : m.tangents[4 * v + c];
                    tangents_.push_back(std::isfinite(x) ? x : 0.0f);
                }
            }
        }
        const uint8_t flags = uint8_t((m.visible_camera ? kVisibleCamera : 0) |
                                      (m.cast_shadow ? kCastShadow : 0) |
                                      (m.shadow_catcher ? kShadowCatcher : 0));
        size_t far = 0, huge = 0;  // a (finite) vertex beyond kMaxCoordinate; edges > kMaxEdge
        double far_max = 0.0, huge_max = 0.0;
        for (size_t t = 0; t < nt; ++t) {
            bool is_far = false;
            for (int k = 0; k < 3; ++k) {
                uint32_t idx = m.indices[3 * t + k];
                if (idx >= nv) {
                    throw std::invalid_argument("mesh '" + m.name + "': vertex index " +
                                                std::to_string(idx) + " out of range");
                }
                const Vec3 p = positions_[base + idx];
                if (is_finite(p) && !within_limit(p)) {
                    is_far = true;
                    far_max = std::max(far_max, double(distance_from_origin(p)));
                }
            }
            if (is_far) {
                ++far;
                continue;
            }
            const double edge = max_edge(positions_[base + m.indices[3 * t]],
                                         positions_[base + m.indices[3 * t + 1]],
                                         positions_[base + m.indices[3 * t + 2]]);
            if (edge > kMaxEdge) {  // kept: where the float tests find it, it renders right
                ++huge;
                huge_max = std::max(huge_max, edge);
            }
            for (int k = 0; k < 3; ++k) indices_.push_back(base + m.indices[3 * t + k]);
            uint32_t mat = m.material_ids[t];
            if (mat >= materials_.size()) {
                throw std::invalid_argument("mesh '" + m.name + "': material id " +
                                            std::to_string(mat) + " out of range");
            }
            tri_material_.push_back(mat);
            const Material& mm = materials_[mat];
            const bool alpha = mm.transparency > 0.0f || (mm.tex_flags & kTexAlpha) ||
                               program_has_target(programs_.data(), mm, kTargetAlpha);
            tri_flags_.push_back(uint8_t(flags | (alpha ? kAlphaTested : 0) |
                                         (mm.holdout ? kHoldout : 0)));
            if (any_rays_hidden) tri_rays_.push_back(uint8_t(m.rays & kRayKindsAll));
            // (a moving mesh's too: its lift is taken where it is at the path's time, D49)
            if (any_terminator)
                tri_terminator_.push_back(m.normals.empty() || m.flat ? 0.0f : m.terminator);
        }
        range.tri_count = int32_t(tri_material_.size()) - range.tri_begin;
        mesh_ranges_.push_back(range);
        if (far) {
            warnings_.push_back("mesh '" + m.name + "': " + std::to_string(far) + " of " +
                                std::to_string(nt) + " triangle(s) reach " +
                                format_metres(far_max) + " m from the origin, beyond the " +
                                format_metres(kMaxCoordinate) +
                                " m the ray queries can take; they were left out");
        }
        if (huge) {
            warnings_.push_back("mesh '" + m.name + "': " + std::to_string(huge) +
                                " triangle(s) with edges up to " + format_metres(huge_max) +
                                " m, beyond the " + format_metres(kMaxEdge) +
                                " m the float ray-triangle tests handle: rays may miss them");
        }
    }
    tri_light_.assign(tri_material_.size(), -1);
}

}  // namespace lantern
