// The environment map's importance distribution: cells of at most kMaxCells texels a side,
// each weighted by its mean luminance times the solid angle its (u, v) area covers, so that
// env_sample draws directions close to proportionally to the radiance they carry.
#include "scene/envmap_build.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <list>
#include <mutex>
#include <stdexcept>

namespace lantern {

namespace {

constexpr int kMaxCellsX = 2048, kMaxCellsY = 1024;

double det3(const float* m) {
    return double(m[0]) * (double(m[4]) * m[8] - double(m[5]) * m[7]) -
           double(m[1]) * (double(m[3]) * m[8] - double(m[5]) * m[6]) +
           double(m[2]) * (double(m[3]) * m[7] - double(m[4]) * m[6]);
}

bool invert3(const float* m, float* inv) {
    const double d = det3(m);
    if (!(std::fabs(d) > 1e-12) || !std::isfinite(d)) return false;
    const double c[9] = {
        double(m[4]) * m[8] - double(m[5]) * m[7], double(m[2]) * m[7] - double(m[1]) * m[8],
        double(m[1]) * m[5] - double(m[2]) * m[4], double(m[5]) * m[6] - double(m[3]) * m[8],
        double(m[0]) * m[8] - double(m[2]) * m[6], double(m[2]) * m[3] - double(m[0]) * m[5],
        double(m[3]) * m[7] - double(m[4]) * m[6], double(m[1]) * m[6] - double(m[0]) * m[7],
        double(m[0]) * m[4] - double(m[1]) * m[3]};
    for (int k = 0; k < 9; ++k) {
        inv[k] = float(c[k] / d);
        if (!std::isfinite(inv[k])) return false;
    }
    return true;
}

// Equirectangular solid angle per unit (u, v), averaged over the band v0..v1 (exact, so that
// a coarse map's poles weigh what they cover): 2 pi^2 cos(elevation) integrated.
double band_jacobian(double v0, double v1) {
    return 2.0 * kPi * (std::sin((v1 - 0.5) * kPi) - std::sin((v0 - 0.5) * kPi)) / (v1 - v0);
}

// A CDF over w[0..n-1] written to out (last entry exactly 1); false when the sum is 0.
bool write_cdf(const double* w, int n, float* out) {
    double total = 0.0;
    for (int i = 0; i < n; ++i) total += w[i];
    if (!(total > 0.0)) {  // unused row (its marginal mass is 0): uniform, never sampled
        for (int i = 0; i < n; ++i) out[i] = float(i + 1) / float(n);
        return false;
    }
    double acc = 0.0;
    for (int i = 0; i < n; ++i) {
        acc += w[i];
        out[i] = float(acc / total);
    }
    out[n - 1] = 1.0f;
    return true;
}

}  // namespace

void build_envmap(const EnvMapInput& in, EnvMapStorage& out, std::vector<std::string>& warnings) {
    out = EnvMapStorage{};
    const std::string who = "world map '" + in.name + "'";
    if (in.width <= 0 || in.height <= 0 || (in.channels != 3 && in.channels != 4))
        throw std::invalid_argument(who + ": needs width, height >= 1 and 3 or 4 channels");
    const size_t w = size_t(in.width), h = size_t(in.height), n = w * h;
    if (in.pixels.size() != n * size_t(in.channels))
        throw std::invalid_argument(who + ": " + std::to_string(in.pixels.size()) +
                                    " values for " + std::to_string(in.width) + "x" +
                                    std::to_string(in.height) + "x" +
                                    std::to_string(in.channels));
    EnvMap& e = out.view;
    e.projection = in.projection == "mirror_ball" ? kEnvMirrorBall : kEnvEquirect;
    if (in.projection != "equirectangular" && in.projection != "mirror_ball")
        throw std::invalid_argument(who + ": unknown projection '" + in.projection +
                                    "' (equirectangular, mirror_ball)");
    std::copy(in.to_map, in.to_map + 9, e.to_map);
    if (!invert3(e.to_map, e.from_map)) {
        warnings.push_back(who + ": its mapping is singular or not finite; the map is used "
                           "unrotated and unscaled");
        const float id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        std::copy(id, id + 9, e.to_map);
        std::copy(id, id + 9, e.from_map);
    }
    e.det = float(std::fabs(det3(e.to_map)));

    // ---- Texels: strength applied, bad values to 0 ----
    float s[3];
    for (int c = 0; c < 3; ++c)
        s[c] = std::isfinite(in.strength[c]) ? std::max(in.strength[c], 0.0f) : 0.0f;
    out.texels.resize(3 * n);
    size_t bad = 0, negative = 0;
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            float v = in.pixels[i * size_t(in.channels) + size_t(c)];
            if (!std::isfinite(v)) {
                ++bad;
                v = 0.0f;
            } else if (v < 0.0f) {
                ++negative;
                v = 0.0f;
            }
            v *= s[c];
            out.texels[3 * i + size_t(c)] = std::isfinite(v) ? std::min(v, 1e30f) : 0.0f;
        }
    }
    if (bad)
        warnings.push_back(who + ": " + std::to_string(bad) +
                           " NaN or infinite texel values were set to 0");
    if (negative)
        warnings.push_back(who + ": " + std::to_string(negative) +
                           " negative texel values were set to 0");

    // ---- Cells: mean luminance over the texels whose centres they hold ----
    const int cx_n = std::min(in.width, kMaxCellsX), cy_n = std::min(in.height, kMaxCellsY);
    std::vector<double> lum(size_t(cx_n) * size_t(cy_n), 0.0), count(lum.size(), 0.0);
    for (size_t y = 0; y < h; ++y) {
        const size_t cy = std::min(size_t((double(y) + 0.5) / double(h) * cy_n), size_t(cy_n - 1));
        for (size_t x = 0; x < w; ++x) {
            const size_t cx =
                std::min(size_t((double(x) + 0.5) / double(w) * cx_n), size_t(cx_n - 1));
            const float* t = &out.texels[3 * (y * w + x)];
            lum[cy * cx_n + cx] += luminance(Vec3{t[0], t[1], t[2]});
            count[cy * cx_n + cx] += 1.0;
        }
    }
    for (size_t k = 0; k < lum.size(); ++k) lum[k] = count[k] > 0.0 ? lum[k] / count[k] : 0.0;

    // ---- Weights: luminance x solid angle per (u, v); a dark cell beside a bright one keeps
    // a little weight, since the bilinear lookup carries light half a texel into it ----
    std::vector<double> weight(lum.size(), 0.0);
    double sphere_sum = 0.0;  // integral of luminance over the sphere, by cells
    double color_sum[3] = {0.0, 0.0, 0.0};
    for (int cy = 0; cy < cy_n; ++cy) {
        for (int cx = 0; cx < cx_n; ++cx) {
            double near = 0.0;
            for (int dy = -1; dy <= 1; ++dy) {
                const int yy = cy + dy;
                if (yy < 0 || yy >= cy_n) continue;
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = (cx + dx + cx_n) % cx_n;
                    near = std::max(near, lum[size_t(yy) * cx_n + xx]);
                }
            }
            // the cell's solid angle per unit (u, v): at its centre, or (mirror ball) 16 where
            // any of the cell touches the ball's disk
            const double u0 = double(cx) / cx_n, u1 = double(cx + 1) / cx_n;
            const double v0 = double(cy) / cy_n, v1 = double(cy + 1) / cy_n;
            double jac;
            if (e.projection == kEnvMirrorBall) {
                auto nearest = [](double a, double b) {  // of [a, b] to 0.5, in [-1, 1] units
                    return 2.0 * std::max({a - 0.5, 0.0, 0.5 - b});
                };
                const double nx = nearest(u0, u1), nz = nearest(v0, v1);
                jac = nx * nx + nz * nz <= 1.0 ? 16.0 : 0.0;
            } else {
                jac = band_jacobian(v0, v1);
            }
            const size_t k = size_t(cy) * cx_n + cx;
            weight[k] = std::max(lum[k], 0.01 * near) * jac;
            sphere_sum += lum[k] * jac / (double(cx_n) * cy_n);
        }
    }
    for (size_t y = 0; y < h; ++y) {  // the mean colour, texel by texel over the sphere
        const double row_jac = band_jacobian(double(y) / double(h), double(y + 1) / double(h));
        for (size_t x = 0; x < w; ++x) {
            double jac = row_jac;
            if (e.projection == kEnvMirrorBall) {
                float j;
                env_uv_to_direction(e.projection, Vec2{(float(x) + 0.5f) / float(w),
                                                       (float(y) + 0.5f) / float(h)}, &j);
                jac = j;
            }
            const float* t = &out.texels[3 * (y * w + x)];
            for (int c = 0; c < 3; ++c) color_sum[c] += t[c] * jac;
        }
    }
    const double norm = 1.0 / (double(n) * 4.0 * kPi);
    out.mean = {float(color_sum[0] * norm), float(color_sum[1] * norm), float(color_sum[2] * norm)};
    if (!(sphere_sum > 0.0) || !std::isfinite(sphere_sum)) {
        out.texels.clear();
        out.view = EnvMap{};
        return;  // all black: no light
    }

    // ---- CDFs: rows by their total weight, then the cells of each row ----
    out.conditional.resize(weight.size());
    out.marginal.resize(size_t(cy_n));
    std::vector<double> row_sum(size_t(cy_n), 0.0);
    for (int cy = 0; cy < cy_n; ++cy) {
        const double* row = &weight[size_t(cy) * cx_n];
        for (int cx = 0; cx < cx_n; ++cx) row_sum[cy] += row[cx];
        write_cdf(row, cx_n, &out.conditional[size_t(cy) * cx_n]);
    }
    write_cdf(row_sum.data(), cy_n, out.marginal.data());
    e.texels = out.texels.data();
    e.marginal = out.marginal.data();
    e.conditional = out.conditional.data();
    e.width = in.width;
    e.height = in.height;
    e.cells_x = cx_n;
    e.cells_y = cy_n;
}

// ---- The cache: by a 64-bit hash of everything build_envmap reads ----
namespace {

struct EnvCacheEntry {
    uint64_t key;
    std::shared_ptr<const EnvMapStorage> storage;
    std::vector<std::string> warnings;
};

uint64_t mix64(uint64_t h, uint64_t v) {  // splitmix64's finaliser over a running state
    h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= h >> 30;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 27;
    h *= 0x94d049bb133111ebull;
    return h ^ (h >> 31);
}

uint64_t envmap_key(const EnvMapInput& in) {
    uint64_t h = mix64(0, uint64_t(uint32_t(in.width)) << 32 | uint32_t(in.height));
    h = mix64(h, uint64_t(in.channels));
    for (char c : in.projection) h = mix64(h, uint64_t(uint8_t(c)));
    auto floats = [&h](const float* f, size_t n) {
        size_t i = 0;
        for (; i + 2 <= n; i += 2) {
            uint64_t v;
            std::memcpy(&v, f + i, 8);
            h = mix64(h, v);
        }
        if (i < n) {
            uint32_t v;
            std::memcpy(&v, f + i, 4);
            h = mix64(h, v);
        }
    };
    floats(in.to_map, 9);
    const float s[3] = {in.strength.x, in.strength.y, in.strength.z};
    floats(s, 3);
    floats(in.pixels.data(), in.pixels.size());
    return mix64(h, in.pixels.size());
}

std::mutex g_env_mutex;
std::list<EnvCacheEntry> g_env_cache;  // most recent first
int64_t g_env_builds = 0;

}  // namespace

std::shared_ptr<const EnvMapStorage> build_envmap_cached(const EnvMapInput& in,
                                                         std::vector<std::string>& warnings) {
    const uint64_t key = envmap_key(in);
    {
        std::lock_guard<std::mutex> lock(g_env_mutex);
        for (auto it = g_env_cache.begin(); it != g_env_cache.end(); ++it) {
            if (it->key != key) continue;
            g_env_cache.splice(g_env_cache.begin(), g_env_cache, it);
            const EnvCacheEntry& e = g_env_cache.front();
            warnings.insert(warnings.end(), e.warnings.begin(), e.warnings.end());
            return e.storage;
        }
    }
    auto storage = std::make_shared<EnvMapStorage>();
    std::vector<std::string> w;
    build_envmap(in, *storage, w);  // outside the lock: builds of different maps overlap
    warnings.insert(warnings.end(), w.begin(), w.end());
    std::lock_guard<std::mutex> lock(g_env_mutex);
    ++g_env_builds;
    g_env_cache.push_front(EnvCacheEntry{key, storage, std::move(w)});
    while (int(g_env_cache.size()) > kEnvMapCacheSize) g_env_cache.pop_back();
    return storage;
}

int64_t envmap_builds() {
    std::lock_guard<std::mutex> lock(g_env_mutex);
    return g_env_builds;
}

}  // namespace lantern
