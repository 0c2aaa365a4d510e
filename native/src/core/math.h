// Host+device basics: vectors, frames and small helpers. Everything here is plain data and
// inline functions marked LANTERN_HD, so that CPU stages and CUDA kernels share one definition.
#pragma once

#include <cmath>
#include <cstdint>

#if defined(__CUDACC__)
#define LANTERN_HD __host__ __device__
#else
#define LANTERN_HD
#endif

// Forced inline on the host for the smallest helpers of the hottest stages: GCC stops inlining
// into a stage once the stage passes its growth limits (bdpt_connect_in, material_eval), and a
// call there costs more than the helper's few multiply-adds (Frame::to_local: 5.9 % of a cis
// step's instructions as calls, bench/results/2026-12-03-cpu-inline). The same arithmetic, so
// the same bits. The device keeps nvcc's own inlining (its stack frames are measured with it).
#if defined(__GNUC__) && !defined(__CUDA_ARCH__)
#define LANTERN_HOST_INLINE __attribute__((always_inline))
#else
#define LANTERN_HOST_INLINE
#endif

// Out of line on the device only: ptxas then compiles a large function once per kernel instead
// of once per call site inlined into the shade kernels (their time and memory in ptxas grow
// faster than their size: docs/cuda_backend.md, "Build time"). The host's code and bits are
// unchanged (the macro is empty there).
#ifdef __CUDA_ARCH__
#define LANTERN_DEVICE_NOINLINE __noinline__
#else
#define LANTERN_DEVICE_NOINLINE
#endif

namespace lantern {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInf = 3.402823466e+38f;

// fmaxf and fminf inline on the host: without -ffinite-math-only GCC calls libm's (about a
// thousand call sites in pt's unit; each call also makes the caller keep its SSE registers in
// memory across it: bench/results/2026-12-06-ptcost). The same bits as glibc's x86-64 fmaxf /
// fminf: ordered arguments as its maxss / minss (x > y ? x : y, so fmaxf(-0, +0) is +0 there
// too), a NaN argument gives the other one. The device keeps CUDA's. Code outside namespace
// lantern with `using namespace lantern` must name ::fmaxf (the two would be ambiguous).
LANTERN_HD inline float fmaxf(float a, float b) {
#ifdef __CUDA_ARCH__
    return ::fmaxf(a, b);
#else
    return b != b ? a : (a > b ? a : b);
#endif
}
LANTERN_HD inline float fminf(float a, float b) {
#ifdef __CUDA_ARCH__
    return ::fminf(a, b);
#else
    return b != b ? a : (a < b ? a : b);
#endif
}

struct Vec2 {
    float x = 0, y = 0;
};

struct Vec3 {
    float x = 0, y = 0, z = 0;
    LANTERN_HD float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

LANTERN_HD inline Vec3 vec3(float x, float y, float z) { return Vec3{x, y, z}; }
LANTERN_HD inline Vec3 vec3(float s) { return Vec3{s, s, s}; }
LANTERN_HD inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
LANTERN_HD inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
LANTERN_HD inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
LANTERN_HD inline Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
LANTERN_HD inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
LANTERN_HD inline Vec3 operator*(float s, Vec3 a) { return a * s; }
LANTERN_HD inline Vec3 operator/(Vec3 a, float s) { return a * (1.0f / s); }
LANTERN_HD inline Vec3& operator+=(Vec3& a, Vec3 b) { a = a + b; return a; }
LANTERN_HD inline Vec3& operator*=(Vec3& a, Vec3 b) { a = a * b; return a; }
LANTERN_HD inline Vec3& operator*=(Vec3& a, float s) { a = a * s; return a; }
LANTERN_HD inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
LANTERN_HD inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
LANTERN_HD inline float length_sq(Vec3 a) { return dot(a, a); }
LANTERN_HD inline float length(Vec3 a) { return sqrtf(dot(a, a)); }
LANTERN_HD inline float max_component(Vec3 a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
// When the squared length overflows (components over ~1.8e19: the normal of a triangle with
// edges over ~4e9 m) or underflows, the vector is rescaled by its largest component first.
LANTERN_HD inline Vec3 normalize(Vec3 a) {
    float l = length(a);
    if (l > 0.0f && l <= kInf) return a * (1.0f / l);
    if (!(l >= 0.0f)) return Vec3{0, 0, 1};  // NaN
    const float m = fmaxf(fabsf(a.x), fmaxf(fabsf(a.y), fabsf(a.z)));
    if (!(m > 0.0f) || !(m <= kInf)) return Vec3{0, 0, 1};  // zero or infinite
    a = a * (1.0f / m);
    return a * (1.0f / length(a));
}
LANTERN_HD inline float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
LANTERN_HD inline bool is_finite(float v) {
#if defined(__CUDA_ARCH__)
    return isfinite(v);
#else
    return std::isfinite(v);
#endif
}
LANTERN_HD inline bool is_finite(Vec3 a) { return is_finite(a.x) && is_finite(a.y) && is_finite(a.z); }
LANTERN_HD inline bool is_black(Vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
LANTERN_HD inline float clampf(float v, float lo, float hi) { return fminf(fmaxf(v, lo), hi); }
LANTERN_HD inline float sqr(float v) { return v * v; }
LANTERN_HD inline int min_int(int a, int b) { return a < b ? a : b; }
LANTERN_HD inline int max_int(int a, int b) { return a > b ? a : b; }
LANTERN_HD inline float safe_sqrt(float v) { return sqrtf(fmaxf(v, 0.0f)); }

// Orthonormal frame around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
// revisited").
struct Frame {
    Vec3 s, t, n;
    LANTERN_HD static Frame from_normal(Vec3 n) {
        float sign = copysignf(1.0f, n.z);
        float a = -1.0f / (sign + n.z);
        float b = n.x * n.y * a;
        Frame f;
        f.s = {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
        f.t = {b, sign + n.y * n.y * a, -n.y};
        f.n = n;
        return f;
    }
    // from_normal(n) turned about n by `angle` (radians): anisotropic lobes' local X follows
    // a surface tangent stored as that angle
    // (the turn is its own function, so that the common angle 0 stays inlined and small; out of
    // line on the device, where its sincos was inlined at every frame of a shade kernel)
    LANTERN_HD static Frame from_normal_angle(Vec3 n, float angle) {
        const Frame f = from_normal(n);
        return angle == 0.0f ? f : f.turned(angle);
    }
    LANTERN_DEVICE_NOINLINE LANTERN_HD Frame turned(float angle) const {
        const float c = cosf(angle), sn = sinf(angle);
        Frame f = *this;
        f.s = s * c + t * sn;
        f.t = t * c - s * sn;
        return f;
    }
    LANTERN_HOST_INLINE LANTERN_HD Vec3 to_local(Vec3 v) const {
        return {dot(v, s), dot(v, t), dot(v, n)};
    }
    LANTERN_HOST_INLINE LANTERN_HD Vec3 to_world(Vec3 v) const {
        return s * v.x + t * v.y + n * v.z;
    }
};

// Row-major affine transform (the upper 3x4 of a 4x4 matrix).
struct Transform {
    float m[3][4];
    LANTERN_HD Vec3 point(Vec3 p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    LANTERN_HD Vec3 vector(Vec3 v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    LANTERN_HD Vec3 axis(int i) const { return {m[0][i], m[1][i], m[2][i]}; }
    LANTERN_HD Vec3 origin() const { return {m[0][3], m[1][3], m[2][3]}; }
};

struct Ray {
    Vec3 o;
    Vec3 d;
    float tmin = 0.0f;
    float tmax = kInf;
    float time = 0.0f;  // shutter time in [0, 1] (motion blur, scene/motion.h); else unread
};

// A unit vector in 2 x 16 bits (octahedral map, signed-normalised: +Z is exact).
LANTERN_HD inline uint32_t oct_encode(Vec3 v) {
    const float l1 = fabsf(v.x) + fabsf(v.y) + fabsf(v.z);
    if (!(l1 > 0.0f) || !is_finite(v)) return 0u;
    float x = v.x / l1, y = v.y / l1;
    if (v.z < 0.0f) {
        const float ox = (1.0f - fabsf(y)) * (x >= 0.0f ? 1.0f : -1.0f);
        y = (1.0f - fabsf(x)) * (y >= 0.0f ? 1.0f : -1.0f);
        x = ox;
    }
    const int32_t qx = int32_t(rintf(clampf(x, -1.0f, 1.0f) * 32767.0f));
    const int32_t qy = int32_t(rintf(clampf(y, -1.0f, 1.0f) * 32767.0f));
    return (uint32_t(qx & 0xFFFF) << 16) | uint32_t(qy & 0xFFFF);
}
LANTERN_HD inline Vec3 oct_decode(uint32_t c) {
    float x = float(int16_t(uint16_t(c >> 16))) / 32767.0f;
    float y = float(int16_t(uint16_t(c & 0xFFFFu))) / 32767.0f;
    const float z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f) {
        const float ox = (1.0f - fabsf(y)) * (x >= 0.0f ? 1.0f : -1.0f);
        y = (1.0f - fabsf(x)) * (y >= 0.0f ? 1.0f : -1.0f);
        x = ox;
    }
    return normalize(vec3(x, y, z));
}

}  // namespace lantern
