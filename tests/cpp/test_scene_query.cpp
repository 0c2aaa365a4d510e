// The built-in ray query the CUDA backend runs (accel/scene_query.h: triangles through the
// one- or two-level BVH, then the strands' query of accel/curve_query.h), over copies of its
// arrays made as the CUDA renderer uploads them (accel/scene_query_build.h's
// scene_query_copied, HostScene::copied_view; here host copies, the originals scribbled over
// after), must give CpuBackend's answer on its built-in BVH (LANTERN_ACCEL=bvh, two levels as
// the session asks where meshes move) bit for bit: t, primitive, uv, occlusion, for every kind
// of ray at random shutter times, in a scene with a still floor, a turning mesh, a deforming
// mesh, still strands, strands hidden from the camera (the kinds' split), a strand set turning
// with its object and strands that deform. Controls: the query without its strands, and at the
// shutter's opening instead of the ray's time, differ on many rays.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "accel/scene_query_build.h"
#include "backend/backend.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;

namespace {

// Row-major 4x4: a turn by a about z, then a move by (tx, ty, tz).
std::vector<float> sq_turn(double a, float tx, float ty, float tz) {
    const float c = float(std::cos(a)), n = float(std::sin(a));
    return {c, -n, 0, tx, n, c, 0, ty, 0, 0, 1, tz, 0, 0, 0, 1};
}

CurveInput sq_fur(const char* name, Vec3 at, int strands, uint32_t seed) {
    CurveInput c;
    c.name = name;
    c.offsets.push_back(0);
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    for (int s = 0; s < strands; ++s) {
        float pdf;
        const Vec3 d = sample_uniform_sphere(rng.uniform2(), &pdf);
        for (int k = 0; k < 4; ++k) {
            const Vec3 p = at + d * (0.15f + 0.12f * float(k));
            c.points.insert(c.points.end(), {p.x, p.y, p.z});
            c.radius.push_back(0.02f * (1.0f - 0.2f * float(k)));
        }
        c.offsets.push_back(int32_t(c.radius.size()));
        c.material_ids.push_back(0);
    }
    return c;
}

SceneInput sq_scene() {
    SceneInput in;
    in.materials.push_back(MaterialInput{});
    in.meshes.push_back(test::box_mesh(vec3(-2.0f, -2.0f, -0.6f), vec3(2.0f, 2.0f, -0.5f), 0, "floor"));
    MeshInput turning = test::box_mesh(vec3(-0.2f, -0.2f, -0.2f), vec3(0.2f, 0.2f, 0.2f), 0, "turning");
    for (int k = 0; k < 3; ++k) {
        const std::vector<float> m = sq_turn(0.6 * k, 0.6f + 0.2f * float(k), 0.0f, 0.0f);
        turning.motion.insert(turning.motion.end(), m.begin(), m.end());
    }
    in.meshes.push_back(turning);
    MeshInput deforming = test::box_mesh(vec3(-0.9f, 0.5f, -0.2f), vec3(-0.5f, 0.9f, 0.2f), 0, "deforming");
    for (int k = 0; k < 2; ++k)
        for (size_t i = 0; i < deforming.positions.size(); ++i)
            deforming.deform.push_back(deforming.positions[i] + (i % 3 == 2 ? 0.3f * float(k) : 0.0f));
    in.meshes.push_back(deforming);
    in.curves.push_back(sq_fur("still", vec3(0.0f, -0.8f, 0.0f), 60, 1));
    CurveInput hidden = sq_fur("hidden", vec3(-0.8f, -0.8f, 0.0f), 40, 2);
    hidden.visible_camera = false;
    in.curves.push_back(hidden);
    CurveInput turned = sq_fur("turning", vec3(0.0f, 0.8f, 0.0f), 60, 3);
    for (int k = 0; k < 3; ++k) {  // about the object's origin, its points exported at identity
        const std::vector<float> m = sq_turn(-0.5 * k, 0.0f, 0.1f * float(k), 0.0f);
        turned.motion.insert(turned.motion.end(), m.begin(), m.end());
    }
    in.curves.push_back(turned);
    CurveInput waving = sq_fur("waving", vec3(0.8f, -0.8f, 0.0f), 40, 4);
    for (int k = 0; k < 2; ++k)
        for (size_t i = 0; i < waving.points.size(); ++i)
            waving.deform.push_back(waving.points[i] + (i % 3 == 0 ? 0.25f * float(k) : 0.0f));
    in.curves.push_back(waving);
    return in;
}

struct SqEnv {  // LANTERN_ACCEL=bvh for one scope
    SqEnv() { setenv("LANTERN_ACCEL", "bvh", 1); }
    ~SqEnv() { unsetenv("LANTERN_ACCEL"); }
};

// Host copies standing in for the device's (each kept until the test ends)
struct SqCopies {
    std::vector<std::unique_ptr<char[]>> blocks;
    const void* operator()(const void* p, size_t bytes) {
        if (!p || bytes == 0) return nullptr;
        blocks.emplace_back(new char[bytes]);
        std::memcpy(blocks.back().get(), p, bytes);
        return blocks.back().get();
    }
};

template <typename T>
void sq_scribble(std::vector<T>& v) {
    if (!v.empty()) std::memset(static_cast<void*>(v.data()), 0xFF, v.size() * sizeof(T));
}

// every array the copy was made from, overwritten (a pointer left to them would now fail)
void sq_scribble(SceneQuery& q) {
    sq_scribble(q.tlas.nodes);
    sq_scribble(q.tlas.leaf_inst);
    sq_scribble(q.tlas.instances);
    for (Bvh& b : q.tlas.blas) {
        sq_scribble(b.nodes);
        sq_scribble(b.tris);
    }
    sq_scribble(q.tlas.blas_views);
    for (CurveBvh& b : q.curves.bvh) {
        sq_scribble(b.nodes);
        sq_scribble(b.segs);
    }
    for (CurveQuery::Moving& m : q.curves.moving)
        for (CurveBvh& b : m.bvh) {
            sq_scribble(b.nodes);
            sq_scribble(b.segs);
        }
    sq_scribble(q.curves.moving_views);
}

RayKind sq_kind(int k) {
    return k == 0 ? RayKind::kCamera : (k == 2 ? RayKind::kShadow : RayKind::kIndirect);
}
uint32_t sq_need(int k) {
    return k == 0 ? kBvhNeedCamera : (k == 2 ? kBvhNeedShadow : kBvhNeedIndirect);
}

struct SqCounts {
    int rays = 0, differ = 0, strands = 0, moving_strands = 0, moving_tris = 0;
};

// x: the copied query (or a control), at_open: rays at time 0 for the query side only
SqCounts sq_compare(const HostScene& scene, const CpuBackend& cpu, const SceneView& copied,
                    const SceneQueryView& x, bool at_open) {
    const SceneView& v = scene.view();
    SqCounts c;
    Pcg32 rng = Pcg32::for_path(11, 0, 0);
    const BvhView none{};
    for (int i = 0; i < 6000; ++i) {
        float pdf;
        const Vec3 o = sample_uniform_sphere(rng.uniform2(), &pdf) * 3.0f + vec3(0.0f, 0.0f, 0.5f);
        const Vec3 aim = vec3(2.4f * rng.uniform() - 1.2f, 2.4f * rng.uniform() - 1.2f,
                              0.8f * rng.uniform() - 0.4f);
        Ray r{o, normalize(aim - o), 1e-4f, rng.uniform() < 0.3f ? 2.5f : kInf};
        r.time = rng.uniform();
        const int kind = int(rng.next() % 3u);
        Ray rq = r;
        if (at_open) rq.time = 0.0f;
        const HitRecord e = cpu.intersect(r, sq_kind(kind));
        const BvhHit h = scene_query_closest(none, &x, rq, kind, sq_need(kind),
                                             BvhAlphaTest{copied, rq});
        const bool eo = kind == 2 ? cpu.occluded(r) : e.prim >= 0;
        const bool ho = scene_query_occluded(none, &x, rq, kind, sq_need(kind),
                                             BvhAlphaTest{copied, rq});
        ++c.rays;
        const bool same = h.prim == e.prim && (e.prim < 0 || (h.t == e.t && h.uv.x == e.uv.x &&
                                                              h.uv.y == e.uv.y));
        if (!same || eo != ho) ++c.differ;
        if (e.prim >= v.num_triangles) {
            ++c.strands;
            if (curve_set_of(v.curves, e.prim - v.num_triangles)) ++c.moving_strands;
        } else if (e.prim >= 0) {
            for (int m = 0; m < v.motion.num_objects; ++m) {
                const ObjectMotion& om = v.motion.objects[m];
                if (e.prim >= om.tri_begin && e.prim < om.tri_begin + om.tri_count) ++c.moving_tris;
            }
        }
    }
    return c;
}

}  // namespace

TEST(SceneQuery, CopiedQueryIsCpuBackendsBuiltinAnswer) {
    SqEnv env;
    HostScene scene(sq_scene());
    const SceneView& v = scene.view();
    ASSERT_EQ(v.motion.num_objects, 2);  // the turning mesh, the deforming one
    ASSERT_EQ(v.curves.num_sets, 1);     // the turning strands
    ASSERT_GT(v.curves.keys.num_steps, 1);  // the waving strands
    std::vector<std::string> w;
    CpuBackend cpu(v, 1, w, &scene.mesh_ranges());
    ASSERT_TRUE(scene_query_needed(v));
    SceneQuery q;
    scene_query_build(q, v, &scene.mesh_ranges(), 1, w);
    EXPECT_EQ(q.curves.distinct, 3);  // the hidden strands split the kinds
    SqCopies copies;
    const CurveQueryCopy copy = [&](const void* p, size_t n) { return copies(p, n); };
    const SceneView copied = scene.copied_view(copy);
    const SceneQueryView x = scene_query_copied(q, copy, copied);
    sq_scribble(q);
    const SqCounts c = sq_compare(scene, cpu, copied, x, false);
    printf("%d rays: %d strand hits (%d on the turning set), %d on moving meshes; %d differ\n",
           c.rays, c.strands, c.moving_strands, c.moving_tris, c.differ);
    EXPECT_EQ(c.differ, 0);
    EXPECT_GT(c.strands, 300);
    EXPECT_GT(c.moving_strands, 50);
    EXPECT_GT(c.moving_tris, 100);
    // controls: without the strands, and at the shutter's opening
    SceneQueryView bare = x;
    bare.curves.num_segs = 0;
    const SqCounts nc = sq_compare(scene, cpu, copied, bare, false);
    const SqCounts tc = sq_compare(scene, cpu, copied, x, true);
    printf("controls: %d differ without strands, %d at the opening\n", nc.differ, tc.differ);
    EXPECT_GT(nc.differ, c.strands / 2);
    EXPECT_GT(tc.differ, 100);
}

TEST(SceneQuery, OnlyScenesWithMovingMeshesOrStrandsNeedIt) {
    SceneInput in;
    in.materials.push_back(MaterialInput{});
    in.meshes.push_back(test::box_mesh(vec3(-1.0f), vec3(1.0f), 0));
    HostScene still(in);
    EXPECT_FALSE(scene_query_needed(still.view()));
    HostScene full(sq_scene());
    EXPECT_TRUE(scene_query_needed(full.view()));
}
