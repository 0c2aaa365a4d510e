// Build time and rays per second of the GPU backend's BVH (accel/, run here on the CPU) against
// Embree (EmbreeAccel, single-ray API) on a procedural ~1M-triangle scene: a noisy terrain and
// a bumpy icosphere. Coherent = pinhole camera rays, incoherent = rays leaving random surface
// points in uniform directions, shadow = segments from those points to a point above the scene.
// Build: cmake --build build/py --target lantern_bvh_bench; run: build/py/lantern_bvh_bench
// [threads...]. Prints a markdown table; docs/bvh.md records the results.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "accel/bvh_builder.h"
#include "backend/cpu/embree_accel.h"
#include "backend/cpu/embree_loader.h"
#include "core/offset.h"
#include "core/rng.h"
#include "core/sampling.h"

using namespace lantern;

namespace {

struct Scene {
    std::vector<Vec3> p;
    std::vector<uint32_t> idx;
    std::vector<uint8_t> flags;
    SceneView view() const {
        SceneView s;
        s.positions = p.data(), s.indices = idx.data(), s.tri_flags = flags.data();
        s.num_triangles = int(idx.size() / 3);
        return s;
    }
};

float bumps(float x, float y) {
    return 0.08f * std::sin(7.1f * x) * std::cos(5.3f * y) +
           0.03f * std::sin(23.0f * x + 11.0f * y) + 0.01f * std::sin(61.0f * y - 37.0f * x);
}

Scene make_scene() {
    Scene s;
    const int g = 580;  // terrain: 2 g^2 triangles over [-2, 2]^2
    for (int j = 0; j <= g; ++j)
        for (int i = 0; i <= g; ++i) {
            float x = -2.0f + 4.0f * i / g, z = -2.0f + 4.0f * j / g;
            s.p.push_back({x, bumps(x, z), z});
        }
    for (int j = 0; j < g; ++j)
        for (int i = 0; i < g; ++i) {
            uint32_t a = j * (g + 1) + i, b = a + 1, c = a + g + 1, d = c + 1;
            s.idx.insert(s.idx.end(), {a, c, b, b, c, d});
        }
    // a bumpy UV sphere of 2 * 405 * 405 triangles above the terrain
    const int n = 405;
    uint32_t base = uint32_t(s.p.size());
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            float th = kPi * j / n, ph = 2 * kPi * i / n;
            Vec3 d{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
            float r = 0.6f * (1.0f + 0.5f * bumps(3 * th, 3 * ph));
            s.p.push_back(Vec3{0.2f, 0.75f, 0.1f} + d * r);
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            s.idx.insert(s.idx.end(), {a, b, c, b, d, c});
        }
    s.flags.assign(s.idx.size() / 3, kVisibleCamera | kCastShadow);
    return s;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Runs fn(i) for i in [0, n) on `threads` threads (interleaved blocks of 64); returns seconds.
double run(int n, int threads, const std::function<void(int)>& fn) {
    auto t0 = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int k = 0; k < threads; ++k) {
        pool.emplace_back([&, k] {
            for (int b = k * 64; b < n; b += threads * 64)
                for (int i = b; i < std::min(n, b + 64); ++i) fn(i);
        });
    }
    for (auto& t : pool) t.join();
    return seconds_since(t0);
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<int> thread_counts;
    for (int a = 1; a < argc; ++a) thread_counts.push_back(std::atoi(argv[a]));
    if (thread_counts.empty())
        thread_counts = {1, int(std::max(1u, std::thread::hardware_concurrency()))};
    Scene sc = make_scene();
    SceneView view = sc.view();
    std::printf("scene: %d triangles; %u hardware threads\n\n", view.num_triangles,
                std::thread::hardware_concurrency());

    // ---- Build ----
    std::vector<std::string> warnings;
    std::printf("| build | threads | ms |\n|---|---|---|\n");
    Bvh bvh;
    for (int t : thread_counts) {
        BvhBuildOptions o;
        o.threads = t;
        bvh = build_bvh(view, o, warnings);
        std::printf("| BVH (binned SAH, 32 bins) | %d | %.0f |\n", t, bvh.stats.build_ms);
    }
    const bool have_embree = embree_available();
    std::unique_ptr<EmbreeAccel> embree;
    if (have_embree) {
        auto t0 = std::chrono::steady_clock::now();
        embree = std::make_unique<EmbreeAccel>(view, warnings);
        std::printf("| Embree %s (high quality, robust; its own threads) | all | %.0f |\n",
                    embree_version().c_str(), 1e3 * seconds_since(t0));
    }
    const BvhStats& st = bvh.stats;
    std::printf(
        "\nBVH: %d nodes (%.1f MB) + %d triangles (%.1f MB), %d leaves, depth %d, max leaf %d, "
        "SAH cost %.1f\n\n",
        st.nodes, st.nodes * 64e-6, st.triangles, st.triangles * 48e-6, st.leaves, st.max_depth,
        st.max_leaf_size, st.sah_cost);

    // ---- Rays ----
    const int res = 1024;
    std::vector<Ray> camera(size_t(res) * res), bounce(1 << 20), shadow(1 << 20);
    Vec3 eye{0.0f, 1.6f, -3.8f}, look{0.1f, 0.4f, 0.0f};
    Frame f = Frame::from_normal(normalize(look - eye));
    for (int j = 0; j < res; ++j)
        for (int i = 0; i < res; ++i) {
            float x = (i + 0.5f) / res * 2 - 1, y = (j + 0.5f) / res * 2 - 1;
            camera[size_t(j) * res + i] =
                Ray{eye, normalize(f.to_world({x * 0.6f, y * 0.6f, 1.0f})), 0, kInf};
        }
    Rng rng = Rng::for_path(1, 0, 0);
    Vec3 light{0.5f, 3.0f, -0.5f};
    for (size_t k = 0; k < bounce.size(); ++k) {
        int t = int(rng.next() % uint32_t(view.num_triangles));
        Vec3 a = sc.p[sc.idx[3 * t]], b = sc.p[sc.idx[3 * t + 1]], c = sc.p[sc.idx[3 * t + 2]];
        Vec2 u = rng.uniform2();
        if (u.x + u.y > 1) u = {1 - u.x, 1 - u.y};
        Vec3 p = a + (b - a) * u.x + (c - a) * u.y, ng = normalize(cross(b - a, c - a));
        float pdf;
        Vec3 d = sample_uniform_sphere(rng.uniform2(), &pdf);
        bounce[k] = Ray{offset_ray_origin(p, ng, d), d, 0, kInf};
        Vec3 o = offset_ray_origin(p, ng, light - p);
        shadow[k] = Ray{o, normalize(light - o), 0, length(light - o) * (1 - 1e-4f)};
    }

    struct Set {
        const char* name;
        const std::vector<Ray>* rays;
        bool occlusion;
    };
    Set sets[] = {{"coherent (camera) closest hit", &camera, false},
                  {"incoherent (bounce) closest hit", &bounce, false},
                  {"incoherent shadow segments, any hit", &shadow, true}};
    std::printf(
        "| rays | threads | BVH Mrays/s | Embree Mrays/s | BVH / Embree | hits BVH / Embree |\n"
        "|---|---|---|---|---|---|\n");
    BvhView bv = bvh.view();
    for (const Set& s : sets) {
        const int n = int(s.rays->size());
        std::vector<uint8_t> hb(n), he(n);
        for (int t : thread_counts) {
            double tb = run(n, t, [&](int i) {
                const Ray& r = (*s.rays)[i];
                hb[i] = s.occlusion ? bvh_occluded(bv, r)
                                    : bvh_intersect(bv, r, kBvhNeedCamera).prim >= 0;
            });
            double te = 0.0;
            if (embree) {
                te = run(n, t, [&](int i) {
                    const Ray& r = (*s.rays)[i];
                    he[i] = s.occlusion ? embree->occluded(r)
                                        : embree->intersect(r, RayKind::kCamera).prim >= 0;
                });
            }
            long cb = 0, ce = 0;
            for (int i = 0; i < n; ++i) cb += hb[i], ce += he[i];
            std::printf("| %s | %d | %.2f | %.2f | %.2f | %ld / %ld |\n", s.name, t, n / tb * 1e-6,
                        te > 0 ? n / te * 1e-6 : 0.0, te > 0 ? te / tb : 0.0, cb, ce);
        }
    }
    return 0;
}
