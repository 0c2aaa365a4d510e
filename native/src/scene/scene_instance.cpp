// HostScene::move_mesh: the viewport's transform edit. The mesh's arrays as given are kept on
// its first move; each move writes positions = M p, normals = normalise(M^-T n) and tangents =
// normalise(M t) from them (as the add-on places an object's local arrays, export/mesh.py), so
// shading sees the moved mesh in world space exactly as a fresh export of it.
#include <cmath>

#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace lantern {

namespace {

Vec3 normalised_or_zero(Vec3 v) {
    const float l = length(v);
    return l > 0.0f && std::isfinite(l) ? v * (1.0f / l) : Vec3{0.0f, 0.0f, 0.0f};
}

}  // namespace

bool HostScene::move_mesh(int k, const Transform& m) {
    if (k < 0 || size_t(k) >= mesh_ranges_.size()) return false;
    const MeshRange& r = mesh_ranges_[k];
    for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
        if (tri_light_[t] >= 0) return false;  // an emitter: the light tree would change
        // a Volume object's box: its grid's world-to-index map would stay behind
        const uint32_t mat = tri_material_[size_t(t)];
        if (mat < material_medium_.size() && material_medium_[mat] >= 0 &&
            media_[size_t(material_medium_[mat])].density_grid >= 0)
            return false;
    }
    Transform inv;
    if (!invert_affine(m, &inv)) return false;
    auto e = [&](int r, int c) { return double(m.m[r][c]); };
    const double det = e(0, 0) * (e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1)) -
                       e(0, 1) * (e(1, 0) * e(2, 2) - e(1, 2) * e(2, 0)) +
                       e(0, 2) * (e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0));
    if (!(det > 0.0)) return false;  // mirrored: the add-on flips the winding, export again
    if (mesh_given_.size() < mesh_ranges_.size()) mesh_given_.resize(mesh_ranges_.size());
    std::unique_ptr<MeshCopy> fresh;
    const MeshCopy* given = mesh_given_[k].get();
    const size_t vb = size_t(r.vert_begin), nv = size_t(r.vert_count);
    if (!given) {  // never moved: the arrays hold what was given
        fresh = std::make_unique<MeshCopy>();
        fresh->positions.assign(positions_.begin() + vb, positions_.begin() + vb + nv);
        if (!normals_.empty())
            fresh->normals.assign(normals_.begin() + vb, normals_.begin() + vb + nv);
        if (!tangents_.empty())
            fresh->tangents.assign(tangents_.begin() + 4 * vb, tangents_.begin() + 4 * (vb + nv));
        given = fresh.get();
    }
    // every vertex its triangles use must stay within the ray queries' range and the sphere
    // that distant lights' paths cover (HostScene::add_lights)
    const float reach = view_.scene_radius * (1.0f + 1e-4f);
    std::vector<Vec3> moved(nv);
    for (size_t v = 0; v < nv; ++v) moved[v] = m.point(given->positions[v]);
    for (int t = r.tri_begin; t < r.tri_begin + r.tri_count; ++t) {
        for (int j = 0; j < 3; ++j) {
            const Vec3 p = moved[indices_[3 * size_t(t) + j] - vb];
            if (!is_finite(p) || !within_limit(p) || length(p - view_.scene_center) > reach)
                return false;
        }
    }
    std::copy(moved.begin(), moved.end(), positions_.begin() + vb);
    // the pure light tracer's disk grows to cover the moved mesh (never past scene_radius,
    // which bounds it above): its sun and world paths keep reaching every vertex
    float far = view_.emit_radius;
    for (const Vec3& p : moved) {
        if (within_limit(p)) far = std::max(far, length(p - view_.scene_center) * (1.0f + 1e-5f));
    }
    view_.emit_radius = std::min(far, view_.scene_radius);
    bool identity = true;  // back where it was given: the given arrays, bit for bit
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) identity &= m.m[i][j] == (i == j ? 1.0f : 0.0f);
    if (identity) {
        std::copy(given->normals.begin(), given->normals.end(), normals_.begin() + vb);
        std::copy(given->tangents.begin(), given->tangents.end(), tangents_.begin() + 4 * vb);
    } else if (!given->normals.empty()) {
        for (size_t v = 0; v < nv; ++v) {  // n M^-1, i.e. M^-T n
            const Vec3 n = given->normals[v];
            const Vec3 w{inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
                         inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
                         inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z};
            normals_[vb + v] = normalised_or_zero(w);
        }
    }
    if (!identity && !given->tangents.empty()) {
        for (size_t v = 0; v < nv; ++v) {
            const float* g = &given->tangents[4 * v];
            const Vec3 t = normalised_or_zero(m.vector(Vec3{g[0], g[1], g[2]}));
            float* out = &tangents_[4 * (vb + v)];
            out[0] = t.x, out[1] = t.y, out[2] = t.z, out[3] = g[3];
        }
    }
    if (fresh) mesh_given_[k] = std::move(fresh);
    return true;
}

}  // namespace lantern
