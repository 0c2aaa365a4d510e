// A triangle soup the ray-query tests build by hand (test_cpu_accel.cpp, test_instances.cpp,
// test_shadow_collect.cpp): positions, indices, per-triangle flags and materials, and the
// SceneView over them that the accelerators read. Named outside an anonymous namespace, so
// the unity batches (several test files in one unit) see one definition.
#pragma once

#include <cstdint>
#include <vector>

#include "accel/tlas_build.h"
#include "scene/scene.h"

namespace lantern::soup_test {

struct TriangleSoup {
    std::vector<Vec3> p;
    std::vector<uint32_t> idx, tri_mat;
    std::vector<uint8_t> flags;
    std::vector<Material> mats;
    std::vector<MeshRange> meshes;  // (test_instances.cpp: the meshes' triangle ranges)
    SceneView view() const {
        SceneView s;
        s.positions = p.data(), s.indices = idx.data(), s.tri_flags = flags.data();
        s.num_triangles = int(flags.size());
        s.materials = mats.data(), s.num_materials = int(mats.size());
        s.tri_material = tri_mat.data();
        return s;
    }
};

}  // namespace lantern::soup_test
