// The GPU backend's BVH (accel/) against Embree (EmbreeAccel) and against brute force: same
// hit or miss, same triangle (or the same distance when several lie there), t within 1e-5
// relative, same occlusion, for every ray kind; plus edges, vertices, tmax at a hit, origins on
// surfaces, skipped degenerate and NaN triangles, a bounded depth and a deterministic build.
// A disagreement is allowed only where the ray passes within rounding of an edge or of the
// segment's end ("borderline"), and those must stay rare. Embree parts skip when it is missing.
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

using namespace lantern;

namespace {

constexpr uint8_t kAll = kVisibleCamera | kCastShadow;

Vec3 uniform_dir(Vec2 u) {
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
Mesh cornell() {
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
Mesh sphere(int level, Vec3 c = {0, 0, 0}, float r = 1.0f) {
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
Mesh soup(int n, float size, uint64_t seed, bool mixed = false) {
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

uint32_t need_of(RayKind k) {
    return k == RayKind::kCamera ? kBvhNeedCamera : (k == RayKind::kShadow ? kBvhNeedShadow : 0u);
}

// How close (in barycentric terms, in double) the ray passes to the edges of triangle `prim`,
// scaled by the distance over the triangle's size: small means within rounding of an edge.
double edge_margin(const Mesh& m, const Ray& r, int prim, double* t_out = nullptr) {
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

bool close_t(float a, float b) {
    return std::abs(a - b) <= 1e-5f * std::max(std::abs(a), std::abs(b)) + 1e-7f;
}

// Tolerance on a hit distance: 1e-5 relative, or what a few ulps of the coordinates move the
// hit along a ray meeting the triangle at a grazing angle, whichever is larger.
float t_tol(const Mesh& m, const Ray& r, int prim, float t) {
    Vec3 a = m.p[m.idx[3 * prim]], b = m.p[m.idx[3 * prim + 1]], c = m.p[m.idx[3 * prim + 2]];
    float cos_t = std::abs(dot(normalize(cross(b - a, c - a)), normalize(r.d)));
    float scale = 1.0f + max_component(vec3(std::abs(r.o.x), std::abs(r.o.y), std::abs(r.o.z))) + t;
    return 1e-5f * t + 2.4e-7f * scale / std::max(cos_t, 1e-6f);
}

bool same_t(const Mesh& m, const Ray& r, int pa, float ta, int pb, float tb) {
    return std::abs(ta - tb) <= std::max(t_tol(m, r, pa, ta), t_tol(m, r, pb, tb));
}

// One ray, every kind: closest hit and occlusion against Embree.
void compare_ray(const Mesh& m, const EmbreeAccel& e, const BvhView& bvh, Ray r, Pcg32& rng,
                 Tally& tl) {
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

void expect_agree(const Tally& t) {
    for (auto& n : t.notes) ADD_FAILURE() << n;
    EXPECT_EQ(t.failures, 0) << "of " << t.rays << " queries";
    EXPECT_LE(t.borderline, std::max(10L, t.rays / 10000)) << "borderline of " << t.rays;
    std::printf("%ld queries, %ld borderline\n", t.rays, t.borderline);
    ::testing::Test::RecordProperty("queries", int(t.rays));
    ::testing::Test::RecordProperty("borderline", int(t.borderline));
}

// Random ray: origin in the box [lo, hi], uniform direction, unbounded.
auto random_rays(Vec3 lo, Vec3 hi) {
    return [=](Pcg32& rng, int) {
        Vec3 u{rng.uniform(), rng.uniform(), rng.uniform()};
        return Ray{lo + (hi - lo) * u, uniform_dir(rng.uniform2()), 0.0f, kInf};
    };
}

// Pinhole rays from `eye` through a square window on the plane z = zw.
auto camera_rays(Vec3 eye, float x0, float x1, float y0, float y1, float zw, int res) {
    return [=](Pcg32&, int i) {
        float x = x0 + (x1 - x0) * ((i % res) + 0.5f) / res,
              y = y0 + (y1 - y0) * ((i / res % res) + 0.5f) / res;
        return Ray{eye, normalize(Vec3{x, y, zw} - eye), 0.0f, kInf};
    };
}

#define NEED_EMBREE() \
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version()

}  // namespace

// ---- Against Embree ----

TEST(Bvh, EmbreeCornellBox) {
    NEED_EMBREE();
    Mesh m = cornell();
    expect_agree(
        compare_many(m, 250000, random_rays({0.01f, 0.01f, 0.01f}, {0.99f, 0.99f, 0.99f}), 1));
    expect_agree(compare_many(
        m, 512 * 512, camera_rays({0.5f, 0.5f, -1.2f}, -0.1f, 1.1f, -0.1f, 1.1f, 0.0f, 512), 2));
}

TEST(Bvh, EmbreeSphere) {
    NEED_EMBREE();
    Mesh m = sphere(5);  // 20480 triangles
    expect_agree(
        compare_many(m, 250000, random_rays({-1.2f, -1.2f, -1.2f}, {1.2f, 1.2f, 1.2f}), 3));
    expect_agree(compare_many(
        m, 512 * 512, camera_rays({0.3f, 0.2f, 3.0f}, -1.1f, 1.1f, -1.1f, 1.1f, 0.0f, 512), 4));
}

TEST(Bvh, EmbreeTriangleSoup) {
    NEED_EMBREE();
    Mesh m = soup(100000, 0.03f, 5, true);
    expect_agree(
        compare_many(m, 150000, random_rays({-0.1f, -0.1f, -0.1f}, {1.1f, 1.1f, 1.1f}), 6));
    expect_agree(
        compare_many(m, 256 * 256, camera_rays({0.5f, 0.5f, -2.0f}, 0, 1, 0, 1, 0.0f, 256), 7));
}

TEST(Bvh, EmbreeDegenerateAndCoincident) {
    NEED_EMBREE();
    Mesh m = soup(20000, 0.05f, 8);
    const float nan = std::nanf(""), inf = std::numeric_limits<float>::infinity();
    for (int i = 0; i < 500; ++i) {  // degenerate and non-finite, mixed in
        Vec3 a = m.p[3 * i], b = m.p[3 * i + 1];
        m.tri(a, a, b);                                          // repeated vertex
        m.tri(a, a + Vec3{0.01f, 0, 0}, a + Vec3{0.02f, 0, 0});  // collinear
        m.tri(a, b, Vec3{nan, 0.5f, 0.5f});                      // NaN
        m.tri(a, Vec3{inf, 0, 0}, b);                            // infinite
    }
    for (int i = 0; i < 2000;
         ++i) {  // coincident: duplicates (rotated order) and coplanar overlaps
        Vec3 a = m.p[3 * i], b = m.p[3 * i + 1], c = m.p[3 * i + 2];
        m.tri(b, c, a);
        m.tri(a, (a + b) * 0.5f, c);
    }
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    EXPECT_EQ(bvh.stats.skipped_nonfinite, 1000);
    EXPECT_EQ(bvh.stats.skipped_degenerate, 1000);
    EXPECT_EQ(bvh.stats.triangles, 20000 + 4000);
    expect_agree(compare_many(m, 200000, random_rays({0, 0, 0}, {1, 1, 1}), 9));
}

// Rays from inside closed meshes through shared edges and vertices: watertight, so never a miss.
TEST(Bvh, EdgesAndVerticesAreWatertight) {
    Mesh m = sphere(4);
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    std::unique_ptr<EmbreeAccel> e;
    if (embree_available()) e = std::make_unique<EmbreeAccel>(m.view(), w);
    Vec3 origins[3] = {{0, 0, 0}, {0.1f, -0.2f, 0.05f}, {-0.3f, 0.3f, 0.3f}};
    int checked = 0, embree_misses = 0;
    for (Vec3 o : origins) {
        for (int t = 0; t < m.count(); ++t) {
            for (int k = 0; k < 3; ++k) {
                Vec3 a = m.p[m.idx[3 * t + k]], b = m.p[m.idx[3 * t + (k + 1) % 3]];
                for (Vec3 target : {a, (a + b) * 0.5f, a * 0.25f + b * 0.75f}) {
                    Ray r{o, normalize(target - o), 0.0f, kInf};
                    BvhHit h = bvh_intersect(bvh.view(), r, 0);
                    ASSERT_GE(h.prim, 0) << "miss through an edge or vertex of triangle " << t;
                    EXPECT_NEAR(h.t, length(target - o), 1e-5f);
                    if (e) {  // Embree (robust mode) is not watertight at vertices: count its
                              // misses
                        HitRecord he = e->intersect(r, RayKind::kIndirect);
                        if (he.prim < 0)
                            ++embree_misses;
                        else
                            EXPECT_TRUE(close_t(he.t, h.t)) << he.t << " vs " << h.t;
                    }
                    ++checked;
                }
            }
        }
    }
    EXPECT_GT(checked, 100000);
    std::printf("%d rays through edges and vertices: BVH 0 misses, Embree %d\n", checked,
                embree_misses);
    ::testing::Test::RecordProperty("embree_misses", embree_misses);
    // axis-aligned walls: rays through the room's corners, edges and quad diagonals
    Mesh c = cornell();
    Bvh cb = build_bvh(c.view(), {}, w);
    for (float x : {0.0f, 0.5f, 1.0f})
        for (float y : {0.0f, 0.25f, 1.0f})
            for (float z : {0.0f, 1.0f}) {
                Vec3 o{0.3f, 0.7f, 0.6f}, target{x, y, z};
                BvhHit h = bvh_intersect(cb.view(), Ray{o, normalize(target - o), 0.0f, kInf}, 0);
                ASSERT_GE(h.prim, 0);
                EXPECT_LE(h.t, length(target - o) * (1 + 1e-5f));
            }
}

// ---- BVH alone ----

// Every ray against brute force over the same triangle test: the same t exactly.
TEST(Bvh, MatchesBruteForce) {
    for (int which = 0; which < 3; ++which) {
        Mesh m = which == 0 ? cornell() : which == 1 ? sphere(3) : soup(20000, 0.05f, 11, true);
        std::vector<std::string> w;
        Bvh bvh = build_bvh(m.view(), {}, w);
        EXPECT_LE(bvh.stats.max_leaf_size, 8);
        Pcg32 rng = Pcg32::for_path(12, which, 0);
        const int n = which == 2 ? 1500 : 20000;
        int inexact = 0;
        for (int i = 0; i < n; ++i) {
            Vec3 o = Vec3{rng.uniform(), rng.uniform(), rng.uniform()} * 2.4f - vec3(1.2f);
            if (which != 1) o = o * 0.5f + vec3(0.5f);
            Ray r{o, uniform_dir(rng.uniform2()), 0.0f,
                  rng.uniform() < 0.5f ? kInf : rng.uniform()};
            for (uint32_t need : {0u, kBvhNeedCamera, kBvhNeedShadow}) {
                BvhRay br = bvh_ray(r);
                float best = r.tmax;
                int prim = -1;
                for (const BvhTri& tri : bvh.tris) {
                    float t, u, v;
                    if ((tri.flags & need) == need && bvh_hit_triangle(br, tri, best, &t, &u, &v))
                        best = t, prim = tri.prim;
                }
                BvhHit h = bvh_intersect(bvh.view(), r, need);
                ASSERT_EQ(h.prim < 0, prim < 0) << "ray " << i << " need " << need;
                if (prim >= 0 && h.t != best) {  // a tie within rounding culled by a box
                    ++inexact;
                    EXPECT_LE(std::abs(h.t - best), 1e-6f * best) << "ray " << i;
                }
                EXPECT_EQ(bvh_occluded(bvh.view(), r, need), prim >= 0);
            }
        }
        std::printf("mesh %d: %d of %d closest hits a rounding error away from brute force\n",
                    which, inexact, 3 * n);
        EXPECT_LE(inexact, 3 * n / 1000);
    }
}

// tmax exactly at a hit still hits; just short of it does not; tmin at the hit excludes it.
TEST(Bvh, SegmentEnds) {
    Mesh m = sphere(4);
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    Pcg32 rng = Pcg32::for_path(13, 0, 0);
    for (int i = 0; i < 20000; ++i) {
        Ray r{Vec3{rng.uniform(), rng.uniform(), rng.uniform()} * 0.8f - vec3(0.4f),
              uniform_dir(rng.uniform2()), 0.0f, kInf};
        BvhHit h = bvh_intersect(bvh.view(), r, 0);
        ASSERT_GE(h.prim, 0);  // inside a closed sphere
        Ray at = r;
        at.tmax = h.t;
        BvhHit h2 = bvh_intersect(bvh.view(), at, 0);
        EXPECT_EQ(h2.t, h.t);
        EXPECT_TRUE(bvh_occluded(bvh.view(), at, 0));
        at.tmax = std::nextafter(h.t, 0.0f);
        EXPECT_FALSE(bvh_occluded(bvh.view(), at, 0));
        Ray past = r;
        past.tmin = h.t;
        BvhHit h3 = bvh_intersect(bvh.view(), past, 0);
        EXPECT_TRUE(h3.prim < 0 || h3.t > h.t);
    }
}

// Origins on a surface: with the shared offset rule the source triangle is never hit again;
// without it (tmin 0) a self-hit can only be at a rounding-sized distance.
TEST(Bvh, OriginOnSurface) {
    Mesh m = cornell();
    Mesh s = sphere(4, {0.5f, 0.5f, 0.5f}, 0.2f);
    for (size_t k = 0; k < s.idx.size(); ++k) s.idx[k] += uint32_t(m.p.size());
    m.p.insert(m.p.end(), s.p.begin(), s.p.end());
    m.idx.insert(m.idx.end(), s.idx.begin(), s.idx.end());
    m.flags.insert(m.flags.end(), s.flags.begin(), s.flags.end());
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    Pcg32 rng = Pcg32::for_path(14, 0, 0);
    for (int i = 0; i < 50000; ++i) {
        int t = int(rng.next() % uint32_t(m.count()));
        Vec3 a = m.p[m.idx[3 * t]], b = m.p[m.idx[3 * t + 1]], c = m.p[m.idx[3 * t + 2]];
        Vec2 u = rng.uniform2();
        if (u.x + u.y > 1) u = {1 - u.x, 1 - u.y};
        Vec3 p = a + (b - a) * u.x + (c - a) * u.y, ng = normalize(cross(b - a, c - a));
        Vec3 d = uniform_dir(rng.uniform2());
        BvhHit raw = bvh_intersect(bvh.view(), Ray{p, d, 0.0f, kInf}, 0);
        if (raw.prim == t) EXPECT_LT(raw.t * std::abs(dot(d, ng)), 1e-6f);  // rounding of p
        Ray off{offset_ray_origin(p, ng, d), d, 0.0f, kInf};
        BvhHit h = bvh_intersect(bvh.view(), off, 0);
        EXPECT_NE(h.prim, t) << "self-hit at t=" << h.t;
    }
}

TEST(Bvh, EmptyAndSingleTriangle) {
    std::vector<std::string> w;
    Mesh empty;
    Bvh e = build_bvh(empty.view(), {}, w);
    EXPECT_EQ(e.view().num_nodes, 0);
    EXPECT_LT(bvh_intersect(e.view(), Ray{{0, 0, 0}, {0, 0, 1}}, 0).prim, 0);
    Mesh one;
    one.tri({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
    Bvh b = build_bvh(one.view(), {}, w);
    BvhHit h = bvh_intersect(b.view(), Ray{{0.25f, 0.5f, 0}, {0, 0, 1}}, 0);
    EXPECT_EQ(h.prim, 0);
    EXPECT_EQ(h.t, 1.0f);
    EXPECT_FLOAT_EQ(h.uv.x, 0.25f);  // weight of vertex 1
    EXPECT_FLOAT_EQ(h.uv.y, 0.5f);   // weight of vertex 2
    EXPECT_LT(bvh_intersect(b.view(), Ray{{0.6f, 0.6f, 0}, {0, 0, 1}}, 0).prim, 0);
    one.flags[0] = kCastShadow;  // hidden from the camera
    Bvh hidden = build_bvh(one.view(), {}, w);
    EXPECT_LT(bvh_intersect(hidden.view(), Ray{{0.25f, 0.5f, 0}, {0, 0, 1}}, kBvhNeedCamera).prim,
              0);
    EXPECT_TRUE(bvh_occluded(hidden.view(), Ray{{0.25f, 0.5f, 0}, {0, 0, 1}}));
}

// Triangles whose positions form a geometric series unbalance SAH; the depth stays within the
// traversal stack, and with object medians (forced early here) every triangle stays reachable.
TEST(Bvh, DepthStaysWithinStack) {
    Mesh m;
    for (int k = 0; k < 3000; ++k) {
        float x = std::exp2(-k / 150.0f), s = x * 1e-3f;  // down to 1e-6: no zero areas
        m.tri({x, 0, 0}, {x + s, 0, 0}, {x, s, 0});
    }
    std::vector<std::string> w;
    Bvh bvh = build_bvh(m.view(), {}, w);
    EXPECT_EQ(bvh.stats.triangles, m.count());
    EXPECT_LE(bvh.stats.max_depth, kBvhStackSize);
    BvhBuildOptions median;  // object medians from the second level on: still exact, still shallow
    median.sah_depth = 1;
    Bvh mb = build_bvh(m.view(), median, w);
    EXPECT_LE(mb.stats.max_depth, 1 + int(std::ceil(std::log2(m.count()))));
    for (int k = 0; k < m.count(); k += 7) {
        Vec3 a = m.p[3 * k], b = m.p[3 * k + 1], c = m.p[3 * k + 2];
        Vec3 target = (a + b + c) * (1.0f / 3.0f);
        for (const Bvh* b : {&bvh, &mb}) {
            BvhHit h = bvh_intersect(b->view(), Ray{target + Vec3{0, 0, 1}, {0, 0, -1}}, 0);
            EXPECT_EQ(h.prim, k);
        }
    }
}

TEST(Bvh, BuildIsDeterministic) {
    Mesh m = soup(60000, 0.02f, 15, true);
    std::vector<std::string> w;
    BvhBuildOptions one, many;
    one.threads = 1;
    many.threads = 4;
    Bvh a = build_bvh(m.view(), one, w), b = build_bvh(m.view(), many, w);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.tris.size(), b.tris.size());
    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)));
    EXPECT_EQ(0, std::memcmp(a.tris.data(), b.tris.data(), a.tris.size() * sizeof(BvhTri)));
    EXPECT_EQ(a.stats.leaves, b.stats.leaves);
}

// Alpha-tested triangles (scene/alpha.h): the BVH with BvhAlphaTest and Embree with its filter
// make the same decisions (one hash of ray and triangle), and a surface of alpha 0.3 stops
// 30% of the rays that reach it.
TEST(Bvh, AlphaTestAgreesWithEmbree) {
    if (!embree_available()) GTEST_SKIP() << embree_version();
    Mesh m = soup(3000, 0.08f, 21);
    std::vector<Material> mats(2);
    mats[1].transparency = 0.7f;  // alpha 0.3
    std::vector<uint32_t> tri_mat(m.count());
    for (int t = 0; t < m.count(); ++t) {
        tri_mat[t] = t % 2;
        if (t % 2) m.flags[t] |= kAlphaTested;
    }
    SceneView s = m.view();
    s.materials = mats.data();
    s.num_materials = 2;
    s.tri_material = tri_mat.data();
    std::vector<std::string> w;
    EmbreeAccel e(s, w);
    Bvh bvh = build_bvh(s, {}, w);
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    int differ = 0, n = 20000, alpha_first = 0, alpha_stopped = 0;
    for (int i = 0; i < n; ++i) {
        Ray r{Vec3{rng.uniform(), rng.uniform(), rng.uniform()}, uniform_dir(rng.uniform2())};
        BvhHit b = bvh_intersect(bvh.view(), r, kBvhNeedIndirect, BvhAlphaTest{s, r});
        HitRecord h = e.intersect(r, RayKind::kIndirect);
        if (b.prim != h.prim) ++differ;
        EXPECT_EQ(bvh_occluded(bvh.view(), r, kBvhNeedShadow, BvhAlphaTest{s, r}),
                  e.occluded(r)) << "ray " << i;
        // the first alpha-tested triangle along the ray, without the test: stopped or passed?
        BvhHit plain = bvh_intersect(bvh.view(), r, kBvhNeedIndirect);
        if (plain.prim >= 0 && plain.prim % 2) {
            ++alpha_first;
            alpha_stopped += b.prim == plain.prim;
        }
    }
    // a closest hit may differ only by rounding at a shared edge
    EXPECT_LE(differ, n / 1000) << differ << " of " << n;
    double p = double(alpha_stopped) / alpha_first;
    double sigma = std::sqrt(0.3 * 0.7 / alpha_first);
    std::printf("alpha 0.3: %d of %d first alpha hits stopped (%.4f, sigma %.4f)\n",
                alpha_stopped, alpha_first, p, sigma);
    EXPECT_GT(alpha_first, 2000);
    EXPECT_LT(std::abs(p - 0.3), 5 * sigma);
}
