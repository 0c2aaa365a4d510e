// The world's environment map as stages see it: radiance by direction (Blender's Environment
// Texture, equirectangular or mirror ball, behind a linear Mapping), and its importance
// sampling by a piecewise-constant 2D distribution over cells of the image, with the exact
// solid-angle pdf of every direction (what next-event estimation and BDPT's MIS read).
#pragma once

#include "core/math.h"
#include "core/sampling.h"

namespace lantern {

enum EnvProjection : int32_t { kEnvEquirect = 0, kEnvMirrorBall = 1 };

struct EnvMap {
    const float* texels = nullptr;   // width x height x 3 radiance (strength applied), rows
                                     // bottom (v = 0) to top, as Blender's pixels
    const float* marginal = nullptr; // cells_y entries: CDF over cell rows (last entry 1)
    const float* conditional = nullptr;  // cells_y x cells_x: CDF over the cells of each row
    int32_t width = 0, height = 0;   // 0: no map (the world is a constant colour)
    int32_t cells_x = 0, cells_y = 0;  // the distribution's grid (texel blocks)
    int32_t projection = kEnvEquirect;
    float to_map[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};    // world direction -> the texture's vector
    float from_map[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // its inverse
    float det = 1.0f;                // |det to_map|
};

LANTERN_HD inline Vec3 mat3_mul(const float* m, Vec3 v) {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
            m[6] * v.x + m[7] * v.y + m[8] * v.z};
}

// ---- Projections: a unit vector in map space <-> (u, v) in [0, 1]^2 ----
// Equirectangular as Blender's: u = 0.5 - atan2(y, x) / 2 pi, v = 0.5 + asin(z) / pi.
// Mirror ball: the ball seen from -Y; its normal at the image point reflects +Y into m.
LANTERN_HD inline Vec2 env_direction_to_uv(int32_t projection, Vec3 m) {
    if (projection == kEnvMirrorBall) {
        Vec3 h = m - vec3(0.0f, 1.0f, 0.0f);
        float len = length(h);
        if (!(len > 0.0f)) return {0.5f, 0.5f};  // straight behind the ball: its rim
        return {0.5f * (h.x / len + 1.0f), 0.5f * (h.z / len + 1.0f)};
    }
    float u = 0.5f - atan2f(m.y, m.x) * (0.5f * kInvPi);
    float v = 0.5f + asinf(clampf(m.z, -1.0f, 1.0f)) * kInvPi;
    return {u - floorf(u), v};
}

// The unit map-space direction of (u, v) and the Jacobian d(omega)/d(u v); 0 where (u, v) maps
// to no direction (outside the mirror ball's disk).
LANTERN_HD inline Vec3 env_uv_to_direction(int32_t projection, Vec2 uv, float* jacobian) {
    if (projection == kEnvMirrorBall) {
        float nx = 2.0f * uv.x - 1.0f, nz = 2.0f * uv.y - 1.0f;
        float r2 = nx * nx + nz * nz;
        if (r2 > 1.0f) {
            *jacobian = 0.0f;
            return vec3(0.0f, 0.0f, 1.0f);
        }
        Vec3 n = {nx, -sqrtf(1.0f - r2), nz};
        // reflection doubles the polar angle: d(omega) = 4 dA(disk) = 16 du dv
        *jacobian = 16.0f;
        return normalize(vec3(0.0f, 1.0f, 0.0f) - n * (2.0f * n.y));
    }
    float phi = (0.5f - uv.x) * 2.0f * kPi;
    float elev = (uv.y - 0.5f) * kPi;
    float c = cosf(elev);
    *jacobian = 2.0f * kPi * kPi * c;
    return {c * cosf(phi), c * sinf(phi), sinf(elev)};
}

// ---- Radiance: bilinear between texel centres, wrapping in u (equirectangular) ----
LANTERN_HD inline Vec3 env_texel(const EnvMap& e, int x, int y) {
    const float* t = e.texels + 3 * (size_t(y) * size_t(e.width) + size_t(x));
    return {t[0], t[1], t[2]};
}

LANTERN_HD inline Vec3 env_lookup(const EnvMap& e, Vec2 uv) {
    float fx = uv.x * float(e.width) - 0.5f, fy = uv.y * float(e.height) - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float tx = fx - x0f, ty = fy - y0f;
    int x0 = int(x0f), y0 = int(y0f), x1 = x0 + 1, y1 = y0 + 1;
    if (e.projection == kEnvEquirect) {
        x0 = (x0 % e.width + e.width) % e.width;
        x1 = (x1 % e.width + e.width) % e.width;
    } else {
        x0 = min_int(max_int(x0, 0), e.width - 1);
        x1 = min_int(max_int(x1, 0), e.width - 1);
    }
    if (e.projection == kEnvEquirect) {  // rows wrap too: Cycles reads environment images
        y0 = (y0 % e.height + e.height) % e.height;  // with EXTENSION_REPEAT, so within half a
        y1 = (y1 % e.height + e.height) % e.height;  // texel of a pole the far row blends in (D24)
    } else {
        y0 = min_int(max_int(y0, 0), e.height - 1);
        y1 = min_int(max_int(y1, 0), e.height - 1);
    }
    Vec3 a = env_texel(e, x0, y0) * (1.0f - tx) + env_texel(e, x1, y0) * tx;
    Vec3 b = env_texel(e, x0, y1) * (1.0f - tx) + env_texel(e, x1, y1) * tx;
    return a * (1.0f - ty) + b * ty;
}

// Radiance arriving from world direction d (unit, pointing away from the scene).
LANTERN_HD inline Vec3 env_radiance(const EnvMap& e, Vec3 d) {
    Vec3 m = mat3_mul(e.to_map, d);
    if (!(length_sq(m) > 0.0f)) return vec3(0.0f);
    return env_lookup(e, env_direction_to_uv(e.projection, normalize(m)));
}

// ---- Importance sampling ----
// Probability of cell i of a CDF (entries cdf[0..n-1], the last 1).
LANTERN_HD inline float env_cdf_mass(const float* cdf, int i) {
    return cdf[i] - (i > 0 ? cdf[i - 1] : 0.0f);
}

// |d omega_map / d omega_world| of m = normalize(to_map d) for a unit d.
LANTERN_HD inline float env_map_jacobian(const EnvMap& e, Vec3 d) {
    float len = length(mat3_mul(e.to_map, d));
    return len > 0.0f ? e.det / (len * len * len) : 0.0f;
}

// Radiance from world direction d and the solid-angle pdf with which env_sample produces it.
// env_eval, env_pdf_w and env_sample are out of line on the device (LANTERN_DEVICE_NOINLINE: their
// trigonometry was copied at every world light site of a shade kernel).
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline Vec3 env_eval(const EnvMap& e, Vec3 d, float* pdf_w) {
    *pdf_w = 0.0f;
    Vec3 m = mat3_mul(e.to_map, d);
    if (!(length_sq(m) > 0.0f)) return vec3(0.0f);
    m = normalize(m);
    Vec2 uv = env_direction_to_uv(e.projection, m);
    Vec3 le = env_lookup(e, uv);
    int cx = min_int(int(uv.x * float(e.cells_x)), e.cells_x - 1);
    int cy = min_int(max_int(int(uv.y * float(e.cells_y)), 0), e.cells_y - 1);
    float p_cell = env_cdf_mass(e.marginal, cy) *
                   env_cdf_mass(e.conditional + size_t(cy) * size_t(e.cells_x), cx);
    float jac;
    env_uv_to_direction(e.projection, uv, &jac);
    if (!(p_cell > 0.0f) || !(jac > 0.0f)) return le;
    float pdf = p_cell * float(e.cells_x) * float(e.cells_y) / jac * env_map_jacobian(e, d);
    *pdf_w = is_finite(pdf) ? pdf : 0.0f;
    return le;
}

// Solid-angle pdf with which env_sample produces world direction d.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline float env_pdf_w(const EnvMap& e, Vec3 d) {
    float pdf;
    env_eval(e, d, &pdf);
    return pdf;
}

// A world direction from u: a cell by the distribution, a uniform point in it; its pdf_w and
// radiance. Returns false (pdf 0) when the sample maps to no direction.
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline bool env_sample(const EnvMap& e, Vec2 u, Vec3* d_out, float* pdf_w,
                                  Vec3* le) {
    *pdf_w = 0.0f;
    int cy = sample_cdf(e.marginal, e.cells_y, u.y);
    const float* row = e.conditional + size_t(cy) * size_t(e.cells_x);
    int cx = sample_cdf(row, e.cells_x, u.x);
    float py = env_cdf_mass(e.marginal, cy), px = env_cdf_mass(row, cx);
    if (!(py > 0.0f) || !(px > 0.0f)) return false;
    // the position inside the cell: the remainder of u, rescaled
    float ry = clampf((u.y - (cy > 0 ? e.marginal[cy - 1] : 0.0f)) / py, 0.0f, 0.99999994f);
    float rx = clampf((u.x - (cx > 0 ? row[cx - 1] : 0.0f)) / px, 0.0f, 0.99999994f);
    Vec2 uv = {(float(cx) + rx) / float(e.cells_x), (float(cy) + ry) / float(e.cells_y)};
    float jac;
    Vec3 m = env_uv_to_direction(e.projection, uv, &jac);
    if (!(jac > 0.0f)) return false;
    Vec3 d = mat3_mul(e.from_map, m);
    if (!(length_sq(d) > 0.0f)) return false;
    d = normalize(d);
    // radiance and pdf from the direction itself, exactly as a ray that finds the world reads
    // them (MIS needs the same pdf both ways)
    *le = env_eval(e, d, pdf_w);
    if (!(*pdf_w > 0.0f)) return false;
    *d_out = d;
    return true;
}

}  // namespace lantern
