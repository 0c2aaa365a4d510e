#include "accel/scene_query_build.h"

namespace lantern {

SceneQueryView SceneQuery::view() const {
    SceneQueryView v;
    v.two_level = two_level ? 1 : 0;
    if (two_level) v.tlas = tlas.view();
    v.curves = curves.view();
    return v;
}

bool scene_query_needed(const SceneView& s) {
    return s.motion.num_objects > 0 || s.curves.num_segs > 0;
}

void scene_query_build(SceneQuery& q, const SceneView& s, const std::vector<MeshRange>* meshes,
                       int threads, std::vector<std::string>& warnings) {
    q.two_level = meshes != nullptr;
    if (meshes) build_tlas_scene(q.tlas, s, *meshes, threads, warnings);
    if (s.curves.num_segs > 0) curve_query_build(q.curves, s);
}

namespace {
template <typename T>
const T* copy_of(const std::vector<T>& v, const CurveQueryCopy& copy) {
    return v.empty() ? nullptr : static_cast<const T*>(copy(v.data(), v.size() * sizeof(T)));
}
}  // namespace

SceneQueryView scene_query_copied(const SceneQuery& q, const CurveQueryCopy& copy,
                                  const SceneView& copied) {
    SceneQueryView v = q.view();
    if (q.two_level) {
        // every bottom level's nodes and triangles in one array each: the views point into them
        std::vector<BvhNode> nodes;
        std::vector<BvhTri> tris;
        std::vector<size_t> at(q.tlas.blas.size() * 2);
        for (size_t k = 0; k < q.tlas.blas.size(); ++k) {
            const Bvh& b = q.tlas.blas[k];
            at[2 * k] = nodes.size();
            at[2 * k + 1] = tris.size();
            nodes.insert(nodes.end(), b.nodes.begin(), b.nodes.end());
            tris.insert(tris.end(), b.tris.begin(), b.tris.end());
        }
        const BvhNode* dn = copy_of(nodes, copy);
        const BvhTri* dt = copy_of(tris, copy);
        std::vector<BvhView> blas(q.tlas.blas_views);
        for (size_t k = 0; k < blas.size(); ++k) {
            blas[k].nodes = blas[k].num_nodes > 0 ? dn + at[2 * k] : nullptr;
            blas[k].tris = blas[k].num_tris > 0 ? dt + at[2 * k + 1] : nullptr;
        }
        v.tlas.nodes = copy_of(q.tlas.nodes, copy);
        v.tlas.leaf_inst = copy_of(q.tlas.leaf_inst, copy);
        v.tlas.instances = copy_of(q.tlas.instances, copy);
        v.tlas.blas = copy_of(blas, copy);
        v.tlas.motion = copied.motion;
    }
    if (q.curves.num_segs > 0) v.curves = curve_query_copied(q.curves, copy, copied);
    return v;
}

}  // namespace lantern
