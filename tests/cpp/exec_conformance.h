// Executor conformance: every primitive of an executor (backend/cpu/cpu_exec.h,
// backend/cuda/cuda_exec.cuh) against a plain host reference on random inputs: sizes 0, 1,
// odd and 2^20 + 3, keys on 1 to 32 bits, all-false / all-true / random flags. Written once as
// templates; tests/cpp/test_exec_conformance.cpp runs them on CpuExec under GoogleTest and
// tests/cuda/exec_conformance.cu on CudaExec as a plain program (tools/gpu_check.sh runs it
// first). Each check returns an empty string when it passes, else what differed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "backend/cpu/embree_accel.h"  // RayKind
#include "core/math.h"
#include "integrator/lt.h"
#include "scene/scene.h"

namespace lantern {
namespace conformance {

struct Result {
    std::string primitive;
    std::string failure;  // empty: passed
};

inline const std::vector<int>& sizes() {
    static const std::vector<int> s = {0, 1, 2, 7, 1001, 65537, (1 << 20) + 3};
    return s;
}

inline std::string where(const char* what, int n, const std::string& detail) {
    return std::string(what) + " (n = " + std::to_string(n) + "): " + detail;
}

template <typename T>
std::string first_difference(const std::vector<T>& got, const std::vector<T>& want) {
    if (got.size() != want.size())
        return "size " + std::to_string(got.size()) + ", want " + std::to_string(want.size());
    for (size_t k = 0; k < got.size(); ++k)
        if (!(got[k] == want[k]))
            return "item " + std::to_string(k) + ": " + std::to_string(got[k]) + ", want " +
                   std::to_string(want[k]);
    return "";
}

template <typename Exec, typename T>
std::vector<T> readback(Exec&, const typename Exec::template Array<T>& a, size_t n) {
    std::vector<T> out(n);
    a.download(out.data(), n);
    return out;
}

template <typename Exec, typename T>
typename Exec::template Array<T> uploaded(Exec& ex, const std::vector<T>& v) {
    auto a = ex.template array<T>();
    a.grow(std::max<size_t>(v.size(), 1));
    a.upload(v.data(), v.size());
    return a;
}

// ---- arrays: grow, grow keeping a prefix, swap, release, the meter's transient peak ----
template <typename Exec>
std::string check_arrays(Exec& ex) {
    const MemoryMeter& m = ex.meter();
    const int64_t base = m.current;
    std::vector<int32_t> v(1000);
    std::iota(v.begin(), v.end(), 7);
    auto a = ex.template array<int32_t>();
    a.grow(1000);
    a.upload(v.data(), v.size());
    if (m.current - base != 4000) return "meter after grow: " + std::to_string(m.current - base);
    const int64_t peak0 = m.peak;
    a.grow_keep(5000, 600);
    if (a.capacity() < 5000) return "grow_keep did not grow";
    if (m.current - base != 20000) return "meter after grow_keep: " + std::to_string(m.current - base);
    if (m.peak < std::max<int64_t>(peak0, base + 24000))
        return "the meter missed grow_keep's transient (old + new): peak " + std::to_string(m.peak);
    std::vector<int32_t> got = readback<Exec, int32_t>(ex, a, 600);
    std::string d = first_difference(got, std::vector<int32_t>(v.begin(), v.begin() + 600));
    if (!d.empty()) return "grow_keep lost the prefix: " + d;
    auto b = ex.template array<int32_t>();
    b.grow(10);
    a.swap(b);
    if (a.capacity() != 10 || b.capacity() < 5000) return "swap";
    got = readback<Exec, int32_t>(ex, b, 600);
    if (!first_difference(got, std::vector<int32_t>(v.begin(), v.begin() + 600)).empty())
        return "swap lost the contents";
    a.release();
    b.release();
    if (m.current != base) return "meter after release: " + std::to_string(m.current - base);
    return "";
}

// ---- each ----
template <typename Exec>
std::string check_each(Exec& ex, int n) {
    auto a = ex.template array<uint32_t>();
    a.grow(std::max(n, 1));
    uint32_t* p = a.data();
    ex.each(n, [=] LANTERN_HD(int k) { p[k] = uint32_t(k) * 2654435761u + 1u; });
    ex.sync();
    std::vector<uint32_t> want(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) want[size_t(k)] = uint32_t(k) * 2654435761u + 1u;
    const std::string d = first_difference(readback<Exec, uint32_t>(ex, a, size_t(n)), want);
    return d.empty() ? d : where("each", n, d);
}

// ---- stable flagged select; flags per item, or per slot through a queue ----
template <typename Exec>
std::string check_select(Exec& ex, int n, int pattern, std::mt19937& rng) {
    std::vector<int32_t> in(static_cast<size_t>(n));
    std::iota(in.begin(), in.end(), 0);
    std::shuffle(in.begin(), in.end(), rng);  // a queue of slots in any order
    std::vector<uint8_t> flags(static_cast<size_t>(n));
    for (auto& f : flags)
        f = pattern == 0 ? 0 : pattern == 1 ? 1 : pattern == 2 ? uint8_t(rng() & 1)
                                                              : uint8_t(rng() % 97 == 0);
    for (int by_slot = 0; by_slot < 2; ++by_slot) {
        std::vector<int32_t> want;
        for (int k = 0; k < n; ++k)
            if (flags[size_t(by_slot ? in[size_t(k)] : k)]) want.push_back(in[size_t(k)]);
        auto di = uploaded(ex, in);
        auto df = uploaded(ex, flags);
        auto out = ex.template array<int32_t>();
        out.grow(std::max(n, 1));
        const int m = ex.select_flagged(di.data(), df.data(), n, out.data(), by_slot == 0);
        if (m != int(want.size()))
            return where("select_flagged", n, "count " + std::to_string(m) + ", want " +
                                                   std::to_string(want.size()) + " (pattern " +
                                                   std::to_string(pattern) + ")");
        const std::string d = first_difference(readback<Exec, int32_t>(ex, out, size_t(m)), want);
        if (!d.empty()) return where("select_flagged", n, d);
    }
    return "";
}

// ---- exclusive scan ----
template <typename Exec>
std::string check_scan(Exec& ex, int n, std::mt19937& rng) {
    std::vector<int32_t> in(static_cast<size_t>(n)), want(static_cast<size_t>(n));
    for (auto& v : in) v = int32_t(rng() % 8);
    int64_t s = 0;
    for (int k = 0; k < n; ++k) {
        want[size_t(k)] = int32_t(s);
        s += in[size_t(k)];
    }
    auto di = uploaded(ex, in);
    auto out = ex.template array<int32_t>();
    out.grow(std::max(n, 1));
    const int64_t total = ex.exclusive_scan(di.data(), n, out.data());
    if (total != s) return where("exclusive_scan", n, "total " + std::to_string(total));
    const std::string d = first_difference(readback<Exec, int32_t>(ex, out, size_t(n)), want);
    return d.empty() ? d : where("exclusive_scan", n, d);
}

// ---- stable radix sort of pairs on bits [begin, end) ----
template <typename Exec>
std::string check_sort(Exec& ex, int n, int begin_bit, int end_bit, int key_bits,
                       std::mt19937& rng) {
    std::vector<uint32_t> keys(static_cast<size_t>(n));
    for (auto& k : keys) k = key_bits >= 32 ? uint32_t(rng()) : uint32_t(rng()) & ((1u << key_bits) - 1u);
    std::vector<int32_t> idx(static_cast<size_t>(n));
    std::iota(idx.begin(), idx.end(), 0);
    const uint32_t mask = end_bit - begin_bit >= 32 ? ~0u : ((1u << (end_bit - begin_bit)) - 1u);
    auto digit = [&](int32_t i) { return (keys[size_t(i)] >> begin_bit) & mask; };
    std::vector<int32_t> want = idx;
    std::stable_sort(want.begin(), want.end(), [&](int32_t a, int32_t b) { return digit(a) < digit(b); });
    std::vector<uint32_t> want_keys(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) want_keys[size_t(k)] = keys[size_t(want[size_t(k)])];
    auto dk = uploaded(ex, keys);
    auto dv = uploaded(ex, idx);
    ex.sort_pairs(dk.data(), dv.data(), n, begin_bit, end_bit);
    const std::string what = "sort_pairs bits [" + std::to_string(begin_bit) + ", " +
                             std::to_string(end_bit) + ")";
    std::string d = first_difference(readback<Exec, int32_t>(ex, dv, size_t(n)), want);
    if (!d.empty()) return where(what.c_str(), n, "values: " + d);
    d = first_difference(readback<Exec, uint32_t>(ex, dk, size_t(n)), want_keys);
    return d.empty() ? d : where(what.c_str(), n, "keys: " + d);
}

// ---- reductions: count, sum, bits_or ----
template <typename Exec>
std::string check_reductions(Exec& ex, int n, std::mt19937& rng) {
    std::vector<uint8_t> f(static_cast<size_t>(n));
    std::vector<int32_t> v(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
        f[size_t(k)] = uint8_t(rng() % 3 == 0);
        v[size_t(k)] = int32_t(rng() % 1000);
    }
    int64_t want_count = 0, want_sum = 0;
    uint32_t want_or = 0;
    for (int k = 0; k < n; ++k) {
        want_count += f[size_t(k)];
        want_sum += v[size_t(k)];
        if (f[size_t(k)]) want_or |= 1u << (v[size_t(k)] % 9);
    }
    auto df = uploaded(ex, f);
    auto dv = uploaded(ex, v);
    const uint8_t* pf = df.data();
    const int32_t* pv = dv.data();
    const int64_t c = ex.count(n, [=] LANTERN_HD(int k) { return pf[k] != 0; });
    if (c != want_count) return where("count", n, std::to_string(c) + ", want " + std::to_string(want_count));
    const int64_t s8 = ex.sum(pf, n);
    if (s8 != want_count) return where("sum (uint8)", n, std::to_string(s8));
    const int64_t s = ex.sum(pv, n);
    if (s != want_sum) return where("sum (int32)", n, std::to_string(s) + ", want " + std::to_string(want_sum));
    const uint32_t o = ex.bits_or(n, [=] LANTERN_HD(int k) {
        return pf[k] ? 1u << (uint32_t(pv[k]) % 9u) : 0u;
    });
    if (o != want_or) return where("bits_or", n, std::to_string(o) + ", want " + std::to_string(want_or));
    return "";
}

// ---- light-tracing splats against a serial splat_pixels; exact where the executor adds in
// queue order, else within the rounding of a different order of double additions ----
// The serial reference's adder, host+device as splat_pixels is (a host lambda there: nvcc's
// warning #20013-D, a host function called from a __host__ __device__ one).
struct SplatWant {
    double* want;
    Vec3 v;
    LANTERN_HD void operator()(int pixel, double f) const {
        want[size_t(pixel) * 3 + 0] += f * v.x;
        want[size_t(pixel) * 3 + 1] += f * v.y;
        want[size_t(pixel) * 3 + 2] += f * v.z;
    }
};
template <typename Exec>
std::string check_splat(Exec& ex, int n, std::mt19937& rng) {
    CameraView cam{};
    cam.width = 37;
    cam.height = 23;
    cam.filter_width = 1.5f;
    std::uniform_real_distribution<float> ux(-2.0f, 39.0f), uy(-2.0f, 25.0f), uv(0.0f, 3.0f);
    std::vector<uint8_t> valid(static_cast<size_t>(n));
    std::vector<Vec2> xy(static_cast<size_t>(n));
    std::vector<Vec3> value(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
        valid[size_t(k)] = uint8_t(rng() % 10 < 7);
        xy[size_t(k)] = Vec2{ux(rng), uy(rng)};
        value[size_t(k)] = Vec3{uv(rng), uv(rng), uv(rng)};
    }
    const size_t px3 = size_t(cam.width) * cam.height * 3;
    std::vector<double> want(px3, 0.25);  // splats add to what is there
    const double scale = 1.0 / 851.0;
    for (int k = 0; k < n; ++k) {
        if (!valid[size_t(k)]) continue;
        splat_pixels(cam, xy[size_t(k)], scale, SplatWant{want.data(), value[size_t(k)]});
    }
    auto dv = uploaded(ex, valid);
    auto dxy = uploaded(ex, xy);
    auto dval = uploaded(ex, value);
    auto img = uploaded(ex, std::vector<double>(px3, 0.25));
    ex.splat(n, dv.data(), dxy.data(), dval.data(), cam, scale, img.data());
    ex.sync();
    const std::vector<double> got = readback<Exec, double>(ex, img, px3);
    for (size_t k = 0; k < px3; ++k) {
        const double tol = Exec::kDeterministicSplats ? 0.0 : 1e-12 * (1.0 + std::fabs(want[k]));
        if (!(std::fabs(got[k] - want[k]) <= tol))
            return where("splat", n, "pixel value " + std::to_string(k) + ": " +
                                         std::to_string(got[k]) + ", want " + std::to_string(want[k]));
    }
    return "";
}

// ---- ray queries: a random triangle soup (ray_scene) against a brute-force double-precision
// Moeller-Trumbore reference. Rays whose reference has a second hit within 1e-4 of the first
// (or of the segment's end) are ties any structure may break either way and are not compared.
struct RayCase {
    std::vector<Vec3> o, d;
    std::vector<float> tmax;  // occlusion segments
};

inline SceneInput ray_scene(uint32_t seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), s(-0.25f, 0.25f);
    SceneInput in;
    in.materials.push_back(MaterialInput{});
    MeshInput m;
    m.name = "soup";
    for (int t = 0; t < 400; ++t) {
        const Vec3 c{u(rng), u(rng), u(rng)};
        for (int v = 0; v < 3; ++v) {
            m.positions.insert(m.positions.end(), {c.x + s(rng), c.y + s(rng), c.z + s(rng)});
            m.indices.push_back(uint32_t(3 * t + v));
        }
        m.material_ids.push_back(0);
    }
    in.meshes.push_back(m);
    return in;
}

inline void brute_hits(const SceneView& s, int tris, Vec3 o, Vec3 d, double tmax, double* t1,
                       double* t2, int* prim) {
    *t1 = *t2 = tmax;
    *prim = -1;
    for (int t = 0; t < tris; ++t) {
        const Vec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
                   c = s.positions[s.indices[3 * t + 2]];
        const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
        const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
        const double dd[3] = {d.x, d.y, d.z}, w[3] = {double(o.x) - a.x, double(o.y) - a.y,
                                                      double(o.z) - a.z};
        const double p[3] = {dd[1] * e2[2] - dd[2] * e2[1], dd[2] * e2[0] - dd[0] * e2[2],
                             dd[0] * e2[1] - dd[1] * e2[0]};
        const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
        if (std::fabs(det) < 1e-14) continue;
        const double bu = (w[0] * p[0] + w[1] * p[1] + w[2] * p[2]) / det;
        const double q[3] = {w[1] * e1[2] - w[2] * e1[1], w[2] * e1[0] - w[0] * e1[2],
                             w[0] * e1[1] - w[1] * e1[0]};
        const double bv = (dd[0] * q[0] + dd[1] * q[1] + dd[2] * q[2]) / det;
        const double th = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        if (bu < 0 || bv < 0 || bu + bv > 1 || !(th > 1e-6) || !(th < tmax)) continue;
        if (th < *t1) {
            *t2 = *t1;
            *t1 = th;
            *prim = t;
        } else if (th < *t2) {
            *t2 = th;
        }
    }
}

// ex must answer ray queries for `s` (the scene of ray_scene()): CpuExec over a CpuBackend of
// it, CudaExec with set_rays() on its device copy.
template <typename Exec>
std::string check_rays(Exec& ex, const SceneView& s, int tris, int n, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1.5f, 1.5f), g(-1.0f, 1.0f);
    std::vector<Vec3> o(static_cast<size_t>(n)), d(static_cast<size_t>(n));
    std::vector<float> seg(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
        o[size_t(k)] = Vec3{u(rng), u(rng), u(rng)};
        Vec3 v{g(rng), g(rng), g(rng)};
        const float len = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
        d[size_t(k)] = len > 1e-3f ? Vec3{v.x / len, v.y / len, v.z / len} : Vec3{0, 0, 1};
        seg[size_t(k)] = 0.05f + 1.5f * float(rng() % 1000) / 1000.0f;
    }
    auto dO = uploaded(ex, o);
    auto dD = uploaded(ex, d);
    auto dS = uploaded(ex, seg);
    auto ht = ex.template array<float>();
    auto hp = ex.template array<int32_t>();
    auto bl = ex.template array<uint8_t>();
    ht.grow(std::max(n, 1));
    hp.grow(std::max(n, 1));
    bl.grow(std::max(n, 1));
    const Vec3* po = dO.data();
    const Vec3* pd = dD.data();
    const float* ps = dS.data();
    float* pt = ht.data();
    int32_t* pp = hp.data();
    uint8_t* pb = bl.data();
    ex.closest(n, RayKind::kIndirect, [=] LANTERN_HD(int k) { return Ray{po[k], pd[k], 0.0f, kInf}; },
               [=] LANTERN_HD(int k, float t, int32_t prim, Vec2) {
                   pt[k] = prim >= 0 ? t : -1.0f;
                   pp[k] = prim;
               });
    ex.occluded(n, [=] LANTERN_HD(int k) { return Ray{po[k], pd[k], 0.0f, ps[k]}; },
                [=] LANTERN_HD(int k, bool b) { pb[k] = b ? 1 : 0; });
    ex.sync();
    const std::vector<float> t = readback<Exec, float>(ex, ht, size_t(n));
    const std::vector<int32_t> prim = readback<Exec, int32_t>(ex, hp, size_t(n));
    const std::vector<uint8_t> blocked = readback<Exec, uint8_t>(ex, bl, size_t(n));
    int compared = 0, wrong = 0;
    std::string first;
    for (int k = 0; k < n; ++k) {
        double t1, t2, s1, s2;
        int p, sp;
        brute_hits(s, tris, o[size_t(k)], d[size_t(k)], 1e30, &t1, &t2, &p);
        brute_hits(s, tris, o[size_t(k)], d[size_t(k)], seg[size_t(k)], &s1, &s2, &sp);
        const bool tie = (p >= 0 && t2 - t1 < 1e-4) ||
                         (p >= 0 && std::fabs(t1 - seg[size_t(k)]) < 1e-4);
        if (tie) continue;
        ++compared;
        const bool ok = prim[size_t(k)] == p &&
                        (p < 0 || std::fabs(t[size_t(k)] - t1) <= 1e-4 * (1.0 + t1)) &&
                        (blocked[size_t(k)] != 0) == (sp >= 0);
        if (!ok && wrong++ == 0)
            first = "ray " + std::to_string(k) + ": prim " + std::to_string(prim[size_t(k)]) +
                    " t " + std::to_string(t[size_t(k)]) + " blocked " +
                    std::to_string(blocked[size_t(k)]) + ", want prim " + std::to_string(p) +
                    " t " + std::to_string(t1) + " blocked " + std::to_string(sp >= 0);
    }
    if (compared < n * 9 / 10) return where("closest / occluded", n, "too many ties to compare");
    // grazing rays along an edge may go either way in a watertight test: one in a thousand
    if (wrong > compared / 1000) return where("closest / occluded", n, std::to_string(wrong) +
                                              " of " + std::to_string(compared) + " wrong; " + first);
    return "";
}

// Every check on every size; one Result per primitive (the first failure it met).
template <typename Exec>
std::vector<Result> run_all(Exec& ex, uint32_t seed = 12345) {
    std::mt19937 rng(seed);
    std::vector<Result> out;
    auto record = [&](const char* name, const std::string& failure) {
        for (Result& r : out)
            if (r.primitive == name) {
                if (r.failure.empty()) r.failure = failure;
                return;
            }
        out.push_back({name, failure});
    };
    record("arrays", check_arrays(ex));
    for (int n : sizes()) {
        record("each", check_each(ex, n));
        for (int pattern = 0; pattern < 4; ++pattern)
            record("select_flagged", check_select(ex, n, pattern, rng));
        record("exclusive_scan", check_scan(ex, n, rng));
        record("reductions", check_reductions(ex, n, rng));
        if (n <= 65537) record("splat", check_splat(ex, n, rng));
        const bool big = n > 100000;
        for (int bits : {1, 2, 3, 5, 8, 9, 16, 24, 31, 32}) {
            if (big && bits != 3 && bits != 32 && bits != 9) continue;
            record("sort_pairs", check_sort(ex, n, 0, bits, bits, rng));
        }
        record("sort_pairs", check_sort(ex, n, 4, 12, 32, rng));  // bits outside do not order
        record("sort_pairs", check_sort(ex, n, 24, 27, 32, rng));
    }
    return out;
}

}  // namespace conformance
}  // namespace lantern
