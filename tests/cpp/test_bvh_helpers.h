// The shared part of the BVH tests (test_bvh.cpp: the BVH alone and against brute force;
// test_bvh_embree.cpp: against Embree): test meshes (a Cornell-like room, an icosphere, a
// triangle soup) and the harness comparing the BVH with Embree ray by ray.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "accel/bvh_builder.h"
#include "backend/cpu/embree_accel.h"
#include "backend/cpu/embree_loader.h"
#include "core/offset.h"
#include "core/rng.h"
#include "core/sampling.h"

namespace lantern::bvh_test {

constexpr uint8_t kAll = kVisibleCamera | kCastShadow;

inline Vec3 uniform_dir(Vec2 u) {
    float pdf;
    return sample_uniform_sphere(u, &pdf);
}

struct Mesh {
    std::vector<Vec3> p;
    std::vector<uint32_t> idx;
    std::vector<uint8_t> flags;
    void tri(Vec3 a, Vec3 b, Vec3 c, uint8_t f = kAll) {
        uint32_t k = uint32_t(p.size());
        p.insert(p.end(), {a, b, c});
        idx.insert(idx.end(), {k, k + 1, k + 2});
        flags.push_back(f);
    }
    void quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint8_t f = kAll) {
        tri(a, b, c, f), tri(a, c, d, f);
    }
    void box(Vec3 lo, Vec3 hi, uint8_t f = kAll) {  // closed, shared corners
        uint32_t k = uint32_t(p.size());
        for (int i = 0; i < 8; ++i)
            p.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
        const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (auto& f4 : q) {
            idx.insert(idx.end(),
                       {k + f4[0], k + f4[1], k + f4[2], k + f4[0], k + f4[2], k + f4[3]});
            flags.insert(flags.end(), {f, f});
        }
    }
    int count() const { return int(idx.size() / 3); }
    SceneView view() const {
        SceneView s;
        s.positions = p.data(), s.indices = idx.data(), s.tri_flags = flags.data();
        s.num_triangles = count();
        return s;
    }
};

// Cornell-like room: closed unit box, two blocks, a light hidden from the camera, a blocker
// that casts no shadow.
inline Mesh cornell() {
    Mesh m;
    m.box({0, 0, 0}, {1, 1, 1});
    m.box({0.15f, 0, 0.2f}, {0.45f, 0.6f, 0.5f});
    m.box({0.55f, 0, 0.55f}, {0.85f, 0.3f, 0.85f});
    m.quad({0.4f, 0.99f, 0.4f}, {0.6f, 0.99f, 0.4f}, {0.6f, 0.99f, 0.6f}, {0.4f, 0.99f, 0.6f},
           kCastShadow);
    m.quad({0.6f, 0.5f, 0.1f}, {0.9f, 0.5f, 0.1f}, {0.9f, 0.8f, 0.1f}, {0.6f, 0.8f, 0.1f},
           kVisibleCamera);
    return m;
}

// Icosphere: shared vertices, subdivided `level` times, radius r around c.
inline Mesh sphere(int level, Vec3 c = {0, 0, 0}, float r = 1.0f) {
    const float g = 1.6180339887f;
    std::vector<Vec3> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                           {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                           {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    std::vector<uint32_t> f = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                               4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                               6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (Vec3& x : v) x = normalize(x);
    for (int l = 0; l < level; ++l) {
        std::vector<uint32_t> nf;
        std::vector<std::vector<std::pair<uint32_t, uint32_t>>> edge(v.size());  // lo -> (hi, mid)
        auto mid2 = [&](uint32_t a, uint32_t b) {
            uint32_t lo = std::min(a, b), hi = std::max(a, b);
            for (auto& e : edge[lo])
                if (e.first == hi) return e.second;
            v.push_back(normalize(v[a] + v[b]));
            edge[lo].push_back({hi, uint32_t(v.size() - 1)});
            return uint32_t(v.size() - 1);
        };
        for (size_t t = 0; t < f.size(); t += 3) {
            uint32_t a = f[t], b = f[t + 1], c = f[t + 2];
            uint32_t ab = mid2(a, b), bc = mid2(b, c), ca = mid2(c, a);
            nf.insert(nf.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        f.swap(nf);
    }
    Mesh m;
    for (Vec3 x : v) m.p.push_back(c + x * r);
    m.idx = f;
    m.flags.assign(f.size() / 3, kAll);
    return m;
}

// n random triangles of edge about `size` in the unit cube, random flags when `mixed`.
inline Mesh soup(int n, float size, uint64_t seed, bool mixed = false) {
    Mesh m;
    Pcg32 rng = Pcg32::for_path(seed, 0, 0);
    auto u3 = [&] { return vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
    for (int i = 0; i < n; ++i) {
        Vec3 c = u3();
        uint8_t f = mixed ? uint8_t(rng.next() % 4) : kAll;
        m.tri(c + (u3() - vec3(0.5f)) * size, c + (u3() - vec3(0.5f)) * size,
              c + (u3() - vec3(0.5f)) * size, f);
    }
    return m;
}

// ---- Comparison harness ----

inline uint32_t need_of(RayKind k) {
    return k == RayKind::kCamera ? kBvhNeedCamera : (k == RayKind::kShadow ? kBvhNeedShadow : 0u);
}

// How close (in barycentric terms, in double) the ray passes to the edges of triangle `prim`,
// scaled by the distance over the triangle's size: small means within rounding of an edge.
inline double edge_margin(const Mesh& m, const Ray& r, int prim, double* t_out = nullptr) {
    auto P = [&](int k) {
        Vec3 v = m.p[m.idx[3 * prim + k]];
        return std::array<double, 3>{v.x, v.y, v.z};
    };
    auto a = P(0), b = P(1), c = P(2);
    double o[3] = {r.o.x, r.o.y, r.o.z}, d[3] = {r.d.x, r.d.y, r.d.z}, e1[3], e2[3], s[3];
    for (int i = 0; i < 3; ++i) e1[i] = b[i] - a[i], e2[i] = c[i] - a[i], s[i] = o[i] - a[i];
    auto cr = [](const double* x, const double* y, double* z) {
        z[0] = x[1] * y[2] - x[2] * y[1], z[1] = x[2] * y[0] - x[0] * y[2],
        z[2] = x[0] * y[1] - x[1] * y[0];
    };
    auto dt = [](const double* x, const double* y) {
        return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    };
    double pv[3], qv[3], n[3];
    cr(d, e2, pv);
    cr(s, e1, qv);
    cr(e1, e2, n);
    double det = dt(e1, pv);
    if (det == 0.0) return 0.0;
    double u = dt(s, pv) / det, v = dt(d, qv) / det, t = dt(e2, qv) / det;
    if (t_out) *t_out = t;
    double size = std::sqrt(std::sqrt(dt(n, n))) + 1e-30;
    double dist = std::abs(t) * std::sqrt(dt(d, d)) + std::sqrt(dt(s, s));
    return std::min({u, v, 1.0 - u - v}) / (1.0 + dist / size);
}

struct Tally {
    long rays = 0, borderline = 0, failures = 0;
    std::vector<std::string> notes;
};

inline bool close_t(float a, float b) {
    return std::abs(a - b) <= 1e-5f * std::max(std::abs(a), std::abs(b)) + 1e-7f;
}

// Tolerance on a hit distance: 1e-5 relative, or what a few ulps of the coordinates move the
// hit along a ray meeting the triangle at a grazing angle, whichever is larger.
inline float t_tol(const Mesh& m, const Ray& r, int prim, float t) {
    Vec3 a = m.p[m.idx[3 * prim]], b = m.p[m.idx[3 * prim + 1]], c = m.p[m.idx[3 * prim + 2]];
    float cos_t = std::abs(dot(normalize(cross(b - a, c - a)), normalize(r.d)));
    float scale = 1.0f + max_component(vec3(std::abs(r.o.x), std::abs(r.o.y), std::abs(r.o.z))) + t;
    return 1e-5f * t + 2.4e-7f * scale / std::max(cos_t, 1e-6f);
}

inline bool same_t(const Mesh& m, const Ray& r, int pa, float ta, int pb, float tb) {
    return std::abs(ta - tb) <= std::max(t_tol(m, r, pa, ta), t_tol(m, r, pb, tb));
}

// One ray, every kind: closest hit and occlusion against Embree.
inline void compare_ray(const Mesh& m, const EmbreeAccel& e, const BvhView& bvh, Ray r,
                        Pcg32& rng, Tally& tl) {
    for (RayKind kind : {RayKind::kCamera, RayKind::kIndirect, RayKind::kShadow}) {
        HitRecord he = e.intersect(r, kind);
        BvhHit hb = bvh_intersect(bvh, r, need_of(kind));
        ++tl.rays;
        bool ok = (he.prim < 0 && hb.prim < 0) ||
                  (he.prim >= 0 && hb.prim >= 0 && same_t(m, r, he.prim, he.t, hb.prim, hb.t));
        if (ok && he.prim >= 0 && he.prim == hb.prim) {
            ok = std::abs(he.uv.x - hb.uv.x) < 1e-3f && std::abs(he.uv.y - hb.uv.y) < 1e-3f;
        }
        if (!ok) {
            // the nearer reported hit is the one the other engine missed
            bool e_near = hb.prim < 0 || (he.prim >= 0 && he.t < hb.t);
            int prim = e_near ? he.prim : hb.prim;
            float t = e_near ? he.t : hb.t;
            bool border = edge_margin(m, r, prim) < 1e-5 ||
                          std::abs(t - r.tmin) < t_tol(m, r, prim, t) ||
                          std::abs(t - r.tmax) < t_tol(m, r, prim, t);
            if (border) {
                ++tl.borderline;
            } else {
                ++tl.failures;
                if (tl.notes.size() < 8) {
                    char buf[512];
                    double te = 0, tb = 0, me = he.prim >= 0 ? edge_margin(m, r, he.prim, &te) : 0,
                           mb = hb.prim >= 0 ? edge_margin(m, r, hb.prim, &tb) : 0;
                    snprintf(buf, sizeof buf,
                             "kind %d o (%.9g %.9g %.9g) d (%.9g %.9g %.9g): embree %d t=%.9g "
                             "(exact %.9g, margin %.3g), bvh %d t=%.9g (exact %.9g, margin %.3g)",
                             int(kind), r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, he.prim, he.t, te,
                             me, hb.prim, hb.t, tb, mb);
                    tl.notes.push_back(buf);
                }
            }
        }
    }
    // occlusion on a segment that ends somewhere around the first shadow caster
    HitRecord hs = e.intersect(r, RayKind::kShadow);
    Ray s = r;
    s.tmax = (hs.prim >= 0 ? hs.t : 4.0f) * (0.5f + rng.uniform());
    bool oe = e.occluded(s), ob = bvh_occluded(bvh, s);
    ++tl.rays;
    if (oe != ob) {
        // the occluder of the engine that saw one: its first hit on the unbounded ray
        BvhHit h = bvh_intersect(bvh, Ray{s.o, s.d, s.tmin, kInf}, kBvhNeedShadow);
        if (oe) {
            HitRecord x = e.intersect(Ray{s.o, s.d, s.tmin, kInf}, RayKind::kShadow);
            h = {x.t, x.prim, x.uv};
        }
        bool border = h.prim >= 0 && (std::abs(h.t - s.tmax) < t_tol(m, s, h.prim, h.t) ||
                                      edge_margin(m, s, h.prim) < 1e-5);
        (border ? tl.borderline : tl.failures)++;
        if (!border && tl.notes.size() < 8) {
            char buf[256];
            snprintf(buf, sizeof buf,
                     "occlusion: embree %d bvh %d, tmax %.9g, first shadow hit %d at %.9g", int(oe),
                     int(ob), s.tmax, h.prim, h.t);
            tl.notes.push_back(buf);
        }
    }
}

// n rays from make(rng, i) compared on all hardware threads.
template <typename Make>
Tally compare_many(const Mesh& m, int n, Make make, uint64_t seed) {
    std::vector<std::string> warnings;
    SceneView s = m.view();
    EmbreeAccel e(s, warnings);
    Bvh bvh = build_bvh(s, {}, warnings);
    int threads = int(std::max(1u, std::min(8u, std::thread::hardware_concurrency())));
    std::vector<Tally> parts(threads);
    std::vector<std::thread> pool;
    for (int k = 0; k < threads; ++k) {
        pool.emplace_back([&, k] {
            Pcg32 rng = Pcg32::for_path(seed, 1, k);
            for (int i = k; i < n; i += threads)
                compare_ray(m, e, bvh.view(), make(rng, i), rng, parts[k]);
        });
    }
    for (auto& t : pool) t.join();
    Tally all;
    for (auto& p : parts) {
        all.rays += p.rays, all.borderline += p.borderline, all.failures += p.failures;
        all.notes.insert(all.notes.end(), p.notes.begin(), p.notes.end());
    }
    return all;
}

inline void expect_agree(const Tally& t) {
    for (auto& n : t.notes) ADD_FAILURE() << n;
    EXPECT_EQ(t.failures, 0) << "of " << t.rays << " queries";
    EXPECT_LE(t.borderline, std::max(10L, t.rays / 10000)) << "borderline of " << t.rays;
    std::printf("%ld queries, %ld borderline\n", t.rays, t.borderline);
    ::testing::Test::RecordProperty("queries", int(t.rays));
    ::testing::Test::RecordProperty("borderline", int(t.borderline));
}

// Random ray: origin in the box [lo, hi], uniform direction, unbounded.
inline auto random_rays(Vec3 lo, Vec3 hi) {
    return [=](Pcg32& rng, int) {
        Vec3 u{rng.uniform(), rng.uniform(), rng.uniform()};
        return Ray{lo + (hi - lo) * u, uniform_dir(rng.uniform2()), 0.0f, kInf};
    };
}

// Pinhole rays from `eye` through a square window on the plane z = zw.
inline auto camera_rays(Vec3 eye, float x0, float x1, float y0, float y1, float zw, int res) {
    return [=](Pcg32&, int i) {
        float x = x0 + (x1 - x0) * ((i % res) + 0.5f) / res,
              y = y0 + (y1 - y0) * ((i / res % res) + 0.5f) / res;
        return Ray{eye, normalize(Vec3{x, y, zw} - eye), 0.0f, kInf};
    };
}

#define NEED_EMBREE() \
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version()

}  // namespace lantern::bvh_test
