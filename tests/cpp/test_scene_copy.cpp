// HostScene::copied_view, which the CUDA backend uploads the scene with: every array the view
// points into must pass through the copy function (a pointer it misses would be a host address
// on the GPU), and the copies must hold the same bytes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <map>
#include <new>
#include <vector>

#include "scene/scene.h"

using namespace lantern;

namespace {

// A scene that fills every array: normals, uvs, tangents, a texture, a mix, an emissive
// triangle, area and point lights, a world colour.
SceneInput full_scene() {
    SceneInput in;
    in.width = 8;
    in.height = 6;
    in.world_color = vec3(0.1f);
    TextureInput t;
    t.name = "checker";
    t.width = t.height = 2;
    t.bytes = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    in.textures.push_back(t);
    MaterialInput a;
    a.name = "textured";
    a.tex_base_color = 0;
    MaterialInput b;
    b.name = "metal";
    b.type = "conductor";
    MaterialInput m;
    m.name = "mix";
    m.type = "mix";
    m.mix_children = {0, 1};
    m.mix_weights = {0.5f, 0.5f};
    MaterialInput e;
    e.name = "lamp";
    e.emission = vec3(3.0f);
    in.materials = {a, b, m, e};
    MeshInput mesh;
    mesh.name = "quad";
    mesh.positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    mesh.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    mesh.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
    mesh.tangents = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    mesh.material_ids = {2, 3};
    in.meshes.push_back(mesh);
    LightInput area;
    area.type = "area";
    area.power = {10, 10, 10};
    area.to_world[11] = 2.0f;
    LightInput point;
    point.type = "point";
    point.power = {5, 5, 5};
    point.radius = 0.1f;
    point.position = {0, 0, 3};
    in.lights = {area, point};
    float cam[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 5, 0, 0, 0, 1};
    std::memcpy(in.camera_to_world, cam, sizeof(cam));
    return in;
}

// Whether p is the start of one of the copies.
bool copied_at(const std::vector<std::vector<uint8_t>>& storage, const void* p) {
    for (const auto& c : storage)
        if (c.data() == p) return true;
    return false;
}

// A HostScene in zeroed memory, so that padding inside its view is zero in both copies and only
// pointers differ between two scenes built from the same input.
struct ZeroedScene {
    void* mem;
    HostScene* scene;
    explicit ZeroedScene(const SceneInput& in)
        : mem(std::calloc(1, sizeof(HostScene))), scene(new (mem) HostScene(in)) {}
    ~ZeroedScene() {
        scene->~HostScene();
        std::free(mem);
    }
};

}  // namespace

TEST(SceneCopy, EveryPointerOfTheViewIsCopied) {
    const SceneInput in = full_scene();
    ZeroedScene a(in), b(in);
    std::map<const void*, std::vector<uint8_t>> copies;  // host array -> its copy
    std::vector<std::vector<uint8_t>> storage;
    const SceneView v = a.scene->copied_view([&](const void* host, size_t bytes) -> const void* {
        storage.emplace_back(static_cast<const uint8_t*>(host),
                             static_cast<const uint8_t*>(host) + bytes);
        copies[host] = storage.back();
        return storage.back().data();
    });
    // words of the view that differ between two scenes of the same input are pointers
    const SceneView& va = a.scene->view();
    const SceneView& vb = b.scene->view();
    constexpr size_t kWords = sizeof(SceneView) / sizeof(uintptr_t);
    uintptr_t wa[kWords], wb[kWords], wc[kWords];
    std::memcpy(wa, &va, sizeof(wa));
    std::memcpy(wb, &vb, sizeof(wb));
    std::memcpy(wc, &v, sizeof(wc));
    int pointers = 0;
    for (size_t k = 0; k < kWords; ++k) {
        if (wa[k] == wb[k]) continue;
        ++pointers;
        const void* host = reinterpret_cast<const void*>(wa[k]);
        // the materials go as a copy of their own, pointing at the copied tables (below)
        const bool copied = host == va.materials ? copied_at(storage, v.materials)
                                                 : copies.count(host) > 0;
        EXPECT_TRUE(copied) << "SceneView word " << k << " (byte offset "
                                        << k * sizeof(uintptr_t)
                                        << ") points into the scene but was not copied";
        EXPECT_NE(wc[k], wa[k]) << "SceneView word " << k << " still points at host memory";
    }
    // positions, normals, uvs, tangents, textures, texels, sRGB table, indices, triangle
    // materials, flags and lights, materials, lights, the three CDFs (lt's, next-event
    // estimation's, light paths'), hittable and miss lists (the world colour is a miss light),
    // the camera's filter table, the light tree's nodes and its distant lights
    // (scene/light_tree.h: the scene has four lights), the materials' albedo tables: 22 arrays
    EXPECT_EQ(pointers, 22);
    // the copies hold the arrays' bytes, and the view's scalars are unchanged
    EXPECT_EQ(std::memcmp(v.positions, va.positions, 4 * sizeof(Vec3)), 0);
    EXPECT_EQ(std::memcmp(v.material_tables, va.material_tables, 4 * sizeof(MaterialTables)), 0);
    for (int i = 0; i < 4; ++i) {  // each material as it is, but at the copy of its tables
        EXPECT_EQ(va.materials[i].tables, va.material_tables + i);
        EXPECT_EQ(v.materials[i].tables, v.material_tables + i);
        Material m = v.materials[i];
        m.tables = va.materials[i].tables;
        EXPECT_EQ(std::memcmp(&m, &va.materials[i], sizeof(Material)), 0) << "material " << i;
    }
    EXPECT_EQ(v.num_triangles, va.num_triangles);
    EXPECT_EQ(v.num_lights, va.num_lights);
    EXPECT_EQ(v.camera.filter_table_size, va.camera.filter_table_size);
    EXPECT_EQ(std::memcmp(v.camera.filter_cdf, va.camera.filter_cdf,
                          sizeof(float) * va.camera.filter_table_size), 0);
}

// The world's environment map adds its texels and both CDFs (scene/envmap.h): 23 arrays.
TEST(SceneCopy, TheEnvironmentMapIsCopied) {
    SceneInput in = full_scene();
    in.world_map.width = 4;
    in.world_map.height = 2;
    in.world_map.pixels.assign(4 * 2 * 3, 0.5f);
    in.world_map.pixels[5] = 7.0f;
    ZeroedScene a(in), b(in);
    std::map<const void*, size_t> copied;
    std::vector<std::vector<uint8_t>> storage;
    const SceneView v = a.scene->copied_view([&](const void* host, size_t bytes) -> const void* {
        storage.emplace_back(static_cast<const uint8_t*>(host),
                             static_cast<const uint8_t*>(host) + bytes);
        copied[host] = bytes;
        return storage.back().data();
    });
    const SceneView& va = a.scene->view();
    const SceneView& vb = b.scene->view();
    constexpr size_t kWords = sizeof(SceneView) / sizeof(uintptr_t);
    uintptr_t wa[kWords], wb[kWords], wc[kWords];
    std::memcpy(wa, &va, sizeof(wa));
    std::memcpy(wb, &vb, sizeof(wb));
    std::memcpy(wc, &v, sizeof(wc));
    int pointers = 0;
    for (size_t k = 0; k < kWords; ++k) {
        if (wa[k] == wb[k]) continue;
        ++pointers;
        EXPECT_TRUE(copied.count(reinterpret_cast<const void*>(wa[k])) ||
                    (wa[k] == reinterpret_cast<uintptr_t>(va.materials) &&
                     copied_at(storage, v.materials)))  // rebased: see the test above
            << "word " << k;
        EXPECT_NE(wc[k], wa[k]) << "word " << k;
    }
    // 22 arrays differ (the light tree's two and the albedo tables among them) between the two
    // scenes; the map's three (texels, marginal, conditional) are shared, built once per
    // content (build_envmap_cached), and copied all the same
    EXPECT_EQ(pointers, 22);
    ASSERT_EQ(va.env.width, 4);
    EXPECT_EQ(va.env.texels, vb.env.texels);
    for (const void* p : {static_cast<const void*>(va.env.texels),
                          static_cast<const void*>(va.env.marginal),
                          static_cast<const void*>(va.env.conditional)})
        EXPECT_TRUE(copied.count(p));
    EXPECT_NE(v.env.texels, va.env.texels);
    EXPECT_NE(v.env.marginal, va.env.marginal);
    EXPECT_NE(v.env.conditional, va.env.conditional);
    EXPECT_EQ(copied[va.env.texels], 4u * 2u * 3u * sizeof(float));
    EXPECT_EQ(std::memcmp(v.env.texels, va.env.texels, 24 * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(v.env.conditional, va.env.conditional, 8 * sizeof(float)), 0);
    EXPECT_EQ(v.env.marginal[1], 1.0f);
}
