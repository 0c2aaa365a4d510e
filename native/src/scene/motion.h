// Transform motion blur (host+device; docs/motion_blur.md). A moving object keeps its triangles
// where they were exported (the scene's world arrays, the bottom-level BVH) and carries its
// object-to-world matrices at the shutter's steps, decomposed as Cycles interpolates them:
// a rotation quaternion (slerped), a translation and an upper-triangular scale-and-shear
// matrix (both lerped), the steps evenly spread over the shutter, time 0 its opening and 1 its
// close. Each camera path draws one time; its rays carry it (Ray::time): the two-level BVH
// places a moving instance at that time, shading moves the exported hit there, and the camera
// moves with its own steps. Scenes without motion draw nothing and run none of this.
#pragma once

#include "core/math.h"
#include "core/rng.h"

namespace lantern {

// One step: M = [R(q) U | t], U = [[u0 u1 u2] [0 u3 u4] [0 0 u5]], q = (x, y, z, w).
struct MotionStep {
    float q[4];
    float t[3];
    float u[6];
};

// A moving mesh: triangles [tri_begin, tri_begin + tri_count) of the scene, its steps
// [first_step, first_step + num_steps) of MotionView::steps, and `base_inv`, the inverse of the
// object-to-world matrix its positions were exported with (exported world -> object space).
struct ObjectMotion {
    int32_t tri_begin, tri_count;
    int32_t first_step, num_steps;
    int32_t mesh;  // its index among the scene's meshes (the two-level BVH's instance)
    int32_t deform;  // its index in MotionView::deforms (deformation blur), -1: rigid (or none
                     // when MotionView::deforms is null)
    Transform base_inv;
    Transform base;  // the exported object-to-world matrix itself
};

// A deforming mesh (deformation blur): its triangles' corners at each of num_steps steps,
// placed as the exported positions are, from MotionView::deform_corners[first]: step k,
// triangle tri_begin + i, corner j at first + 3 * (k * tri_count + i) + j. A deforming mesh is
// also an ObjectMotion (identity steps where only its vertices move), so every path that places
// a moving mesh places it; the corners are lerped at the ray's time in its exported frame.
struct DeformMesh {
    int32_t tri_begin, tri_count;
    int32_t first, num_steps;
};

struct MotionView {
    const MotionStep* steps = nullptr;
    const ObjectMotion* objects = nullptr;  // ordered by tri_begin, ranges disjoint
    const DeformMesh* deforms = nullptr;
    const Vec3* deform_corners = nullptr;
    int32_t num_objects = 0;
    int32_t camera_first = 0, camera_steps = 0;  // camera: steps of its to_world (< 2: still)
    int32_t curves = 0;  // 1: strands move (CurveView::keys; docs/motion_blur.md "Strands")
    // test only (LANTERN_TEST_UNTIMED_MEDIA=1, the negative control of tests/python/
    // test_motion_media_bidir.py): the medium rays of lt, bdpt, lvc and cis at time 0
    int32_t media_untimed = 0;
    // per medium: the index in `objects` of the moving mesh that bounds it where it is
    // heterogeneous and moves (its density in that mesh's exported frame: medium_ray_exported),
    // else -1; null where no such volume moves
    const int32_t* medium_objects = nullptr;
    LANTERN_HD bool any() const { return num_objects > 0 || camera_steps > 1 || curves; }
    // the paths' rays must carry their time: a mesh or a strand moves (a moving camera alone
    // needs only its camera rays')
    LANTERN_HD bool rays_timed() const { return num_objects > 0 || curves; }
};

// ---- Time: one number per camera path, outside the path's own dimensions (sample_dims.h,
// "motion blur"): the 1D Owen-scrambled Sobol' sequence of the path's sample index under its own
// scramble, so that a pixel's times are stratified and no existing draw changes ----
constexpr uint32_t kMotionTimeSalt = 0x54494D45u;  // "TIME"
// The PCG stream's (-DLANTERN_RNG_PCG, bench/qmc_noise.py's Rng): a hash of its starting state,
// which no draw changes (its `state` does: stages that recompute the time after drawing would
// each see another time)
LANTERN_HD inline float motion_time(const Pcg32& rng) {
    return bits_to_unit(uint32_t(mix64(rng.key ^ kMotionTimeSalt)));
}
#ifndef LANTERN_RNG_PCG
LANTERN_HD inline float motion_time(const Rng& rng) {
    const uint32_t seed = rng.seed ^ kMotionTimeSalt;
    return bits_to_unit(sobol_owen(sobol_shuffled(rng.rindex, seed, 0), seed, 0));
}
#endif

// lvc, cis (their light-vertex cache is shared by every path of a pass): one time per pass, the
// same 1D sequence over the pass's index (BdptSettings::iteration) under a scramble of the
// session's seed, so that the passes' times are stratified (docs/motion_blur.md)
constexpr uint64_t kMotionPassSalt = 0x5041535354494D45ull;  // "PASSTIME"
LANTERN_HD inline float motion_pass_time(uint64_t seed, uint64_t pass) {
#ifdef LANTERN_RNG_PCG
    return bits_to_unit(uint32_t(mix64(mix64(seed ^ kMotionPassSalt) ^ pass)));
#else
    const uint32_t sd = uint32_t(mix64(seed ^ kMotionPassSalt));
    return bits_to_unit(sobol_owen(sobol_shuffled(reverse_bits32(uint32_t(pass)), sd, 0), sd, 0));
#endif
}

// ---- Interpolation ----
LANTERN_HD inline Transform motion_compose(const float q[4], const float t[3], const float u[6]) {
    const float x = q[0], y = q[1], z = q[2], w = q[3];
    const float r[3][3] = {{1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y - w * z),
                            2.0f * (x * z + w * y)},
                           {2.0f * (x * y + w * z), 1.0f - 2.0f * (x * x + z * z),
                            2.0f * (y * z - w * x)},
                           {2.0f * (x * z - w * y), 2.0f * (y * z + w * x),
                            1.0f - 2.0f * (x * x + y * y)}};
    const float um[3][3] = {{u[0], u[1], u[2]}, {0.0f, u[3], u[4]}, {0.0f, 0.0f, u[5]}};
    Transform m;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            m.m[i][j] = r[i][0] * um[0][j] + r[i][1] * um[1][j] + r[i][2] * um[2][j];
        m.m[i][3] = t[i];
    }
    return m;
}

// Steps a, b mixed at f in [0, 1]: slerp of the rotations (b's quaternion is on a's side: the
// builder flips signs), lerp of the rest.
LANTERN_HD inline Transform motion_mix(const MotionStep& a, const MotionStep& b, float f) {
    float q[4], t[3], u[6];
    const float c = a.q[0] * b.q[0] + a.q[1] * b.q[1] + a.q[2] * b.q[2] + a.q[3] * b.q[3];
    float wa = 1.0f - f, wb = f;
    if (c < 0.9995f) {  // slerp; nearly parallel: the normalised lerp
        const float th = acosf(fmaxf(c, -1.0f));
        const float st = sinf(th);
        wa = sinf((1.0f - f) * th) / st;
        wb = sinf(f * th) / st;
    }
    float l = 0.0f;
    for (int k = 0; k < 4; ++k) {
        q[k] = wa * a.q[k] + wb * b.q[k];
        l += q[k] * q[k];
    }
    l = l > 0.0f ? 1.0f / sqrtf(l) : 0.0f;
    for (int k = 0; k < 4; ++k) q[k] *= l;
    for (int k = 0; k < 3; ++k) t[k] = (1.0f - f) * a.t[k] + f * b.t[k];
    for (int k = 0; k < 6; ++k) u[k] = (1.0f - f) * a.u[k] + f * b.u[k];
    return motion_compose(q, t, u);
}

// The object-to-world matrix of steps [first, first + n) at time in [0, 1].
LANTERN_HD inline Transform motion_at(const MotionStep* steps, int first, int n, float time) {
    if (n < 2) return motion_compose(steps[first].q, steps[first].t, steps[first].u);
    const float x = fminf(fmaxf(time, 0.0f), 1.0f) * float(n - 1);
    const int k = x >= float(n - 1) ? n - 2 : int(x);
    return motion_mix(steps[first + k], steps[first + k + 1], x - float(k));
}

LANTERN_HD inline Transform transform_mul(const Transform& a, const Transform& b) {
    Transform m;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
            float v = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
            m.m[i][j] = j == 3 ? v + a.m[i][3] : v;
        }
    }
    return m;
}

// Inverse of an affine transform; false (m untouched) when it is singular or not finite.
LANTERN_HD inline bool transform_inverse(const Transform& a, Transform* out) {
    const float(*m)[4] = a.m;
    const float c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    const float c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    const float c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    const float det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    if (!(fabsf(det) > 1e-30f) || !(fabsf(det) < 1e30f)) return false;
    const float id = 1.0f / det;
    Transform r;
    r.m[0][0] = c00 * id;
    r.m[1][0] = c01 * id;
    r.m[2][0] = c02 * id;
    r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
    r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
    r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
    r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
    r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
    r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
    for (int i = 0; i < 3; ++i)
        r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j)
            if (!(fabsf(r.m[i][j]) <= 3.0e38f)) return false;  // NaN or inf
    *out = r;
    return true;
}

// Exported world -> world at `time` (the mesh's arrays are placed there).
LANTERN_HD inline Transform object_motion_to_world(const MotionView& mv, const ObjectMotion& o,
                                                   float time) {
    return transform_mul(motion_at(mv.steps, o.first_step, o.num_steps, time), o.base_inv);
}

// World at `time` -> exported world (a ray's frame for the bottom level); false where the
// object's matrix is singular at that time (a scale through zero: nothing to hit).
LANTERN_HD inline bool object_motion_to_exported(const MotionView& mv, const ObjectMotion& o,
                                                 float time, Transform* out) {
    Transform inv;
    if (!transform_inverse(motion_at(mv.steps, o.first_step, o.num_steps, time), &inv))
        return false;
    *out = transform_mul(o.base, inv);
    return true;
}

// A moving heterogeneous volume (MotionView::medium_objects): a ray (o, d) in world at `time`
// brought to its mesh's exported frame, where the density program, its attribute fits and its
// majorant are; the ray's parameter stays the world distance (an affine map: d need not stay
// unit). Unchanged where medium med does not move. Out of line: still media never call it.
#ifndef __CUDA_ARCH__
__attribute__((noinline))
#endif
LANTERN_DEVICE_NOINLINE
LANTERN_HD inline void medium_ray_exported(const MotionView& mv, int32_t med, float time, Vec3* o,
                                           Vec3* d) {
    const int32_t k = mv.medium_objects && med >= 0 ? mv.medium_objects[med] : -1;
    Transform a;
    if (k < 0 || !object_motion_to_exported(mv, mv.objects[k], time, &a)) return;
    *o = a.point(*o);
    *d = a.vector(*d);
}

// The moving object that holds triangle tri, or null (a binary search over the few movers).
LANTERN_HD inline const ObjectMotion* object_motion_of(const MotionView& mv, int tri) {
    int lo = 0, hi = mv.num_objects - 1;
    while (lo <= hi) {
        const int mid = (lo + hi) >> 1;
        const ObjectMotion& o = mv.objects[mid];
        if (tri < o.tri_begin) {
            hi = mid - 1;
        } else if (tri >= o.tri_begin + o.tri_count) {
            lo = mid + 1;
        } else {
            return &o;
        }
    }
    return nullptr;
}

// Triangle tri of deforming mesh dm at `time` (its exported frame): corners lerped between steps.
LANTERN_HD inline void deform_triangle(const MotionView& mv, const DeformMesh& dm, int tri,
                                       float time, Vec3 p[3]) {
    const int n = dm.num_steps;
    const float x = fminf(fmaxf(time, 0.0f), 1.0f) * float(n - 1);
    const int k = x >= float(n - 1) ? n - 2 : int(x);
    const float f = x - float(k);
    const Vec3* a = mv.deform_corners + dm.first + 3 * (k * dm.tri_count + (tri - dm.tri_begin));
    const Vec3* b = a + 3 * dm.tri_count;
    for (int j = 0; j < 3; ++j) p[j] = a[j] * (1.0f - f) + b[j] * f;
}

// A rotation taking unit vector a to unit vector b, applied to v (Rodrigues; a = -b: v as is).
LANTERN_HD inline Vec3 rotate_between(Vec3 a, Vec3 b, Vec3 v) {
    const Vec3 k = cross(a, b);
    const float c = dot(a, b);
    if (!(c > -0.9999f)) return v;
    return v * c + cross(k, v) + k * (dot(k, v) / (1.0f + c));
}

// The hit h on exported triangle tri (barycentrics uv: weights of corners 1 and 2; corners
// e[3] as exported), moved onto the deformed triangle at `time`, all in the exported frame: the
// point from the deformed corners, both normals turned as the triangle's normal turns, then
// made to face the ray d (the deformed triangle's side decides).
template <class Hit>
LANTERN_HD inline void deform_hit(const MotionView& mv, const DeformMesh& dm, int tri, Vec2 uv,
                                  const Vec3 e[3], Vec3 d, float time, Hit* h) {
    Vec3 p[3];
    deform_triangle(mv, dm, tri, time, p);
    const Vec3 ne = cross(e[1] - e[0], e[2] - e[0]), nd = cross(p[1] - p[0], p[2] - p[0]);
    const float le = length(ne), ld = length(nd);
    h->p = p[0] * (1.0f - uv.x - uv.y) + p[1] * uv.x + p[2] * uv.y;
    if (!(le > 0.0f) || !(ld > 0.0f)) return;
    const Vec3 a = ne * (1.0f / le), b = nd * (1.0f / ld);
    h->ng = normalize(rotate_between(a, b, h->ng));
    h->ns = normalize(rotate_between(a, b, h->ns));
    if (dot(h->ng, d) > 0.0f) {  // the deformed triangle turned its other side to the ray
        h->ng = -h->ng;
        h->ns = -h->ns;
        h->front = !h->front;
    }
}

// The deforming mesh of moving object o, or null.
LANTERN_HD inline const DeformMesh* deform_of(const MotionView& mv, const ObjectMotion& o) {
    return mv.deforms && o.deform >= 0 ? &mv.deforms[o.deform] : nullptr;
}

// A normal under m: (m^-1)^T n through the cofactors (scale does not matter: normalised later).
LANTERN_HD inline Vec3 motion_normal(const Transform& a, Vec3 n) {
    const float(*m)[4] = a.m;
    const Vec3 c0{m[1][1] * m[2][2] - m[1][2] * m[2][1], m[1][2] * m[2][0] - m[1][0] * m[2][2],
                  m[1][0] * m[2][1] - m[1][1] * m[2][0]};
    const Vec3 c1{m[0][2] * m[2][1] - m[0][1] * m[2][2], m[0][0] * m[2][2] - m[0][2] * m[2][0],
                  m[0][1] * m[2][0] - m[0][0] * m[2][1]};
    const Vec3 c2{m[0][1] * m[1][2] - m[0][2] * m[1][1], m[0][2] * m[1][0] - m[0][0] * m[1][2],
                  m[0][0] * m[1][1] - m[0][1] * m[1][0]};
    // cofactor matrix C with C[i][j] = rows above: c0 = (C00, C01, C02) ... n' = C n
    return Vec3{c0.x * n.x + c0.y * n.y + c0.z * n.z, c1.x * n.x + c1.y * n.y + c1.z * n.z,
                c2.x * n.x + c2.y * n.y + c2.z * n.z};
}

// A hit on a moving mesh at `time`: surface(dx) shades the exported triangle for the ray's
// direction dx brought there; its point and normals are then moved to `time` (normals by the
// cofactors, as the moved triangle's own; a mirroring step keeps them facing the ray).
// A deforming mesh's hit is first moved onto its triangle at `time` (deform_hit; corners: the
// exported triangle's, for its normal's turn).
template <class Hit, class Surface, class Corners>
LANTERN_HD inline Hit motion_surface(const MotionView& mv, int tri, Vec2 uv, Vec3 d, float time,
                                     const Surface& surface, const Corners& corners) {
    const ObjectMotion* o = object_motion_of(mv, tri);
    if (!o) return surface(d);
    const Transform m = object_motion_to_world(mv, *o, time);
    Transform inv;
    if (!transform_inverse(m, &inv)) return surface(d);
    const Vec3 dx = inv.vector(d);
    Hit h = surface(dx);
    if (const DeformMesh* dm = deform_of(mv, *o)) {
        Vec3 e[3];
        corners(e);
        deform_hit(mv, *dm, tri, uv, e, dx, time, &h);
    }
    const float det = m.m[0][0] * (m.m[1][1] * m.m[2][2] - m.m[1][2] * m.m[2][1]) -
                      m.m[0][1] * (m.m[1][0] * m.m[2][2] - m.m[1][2] * m.m[2][0]) +
                      m.m[0][2] * (m.m[1][0] * m.m[2][1] - m.m[1][1] * m.m[2][0]);
    const float sign = det < 0.0f ? -1.0f : 1.0f;
    h.p = m.point(h.p);
    h.ng = normalize(motion_normal(m, h.ng)) * sign;
    h.ns = normalize(motion_normal(m, h.ns)) * sign;
    return h;
}

// The camera at `time` (its steps: rigid, CameraView::to_world).
template <class Camera>  // CameraView (scene_view.h, which includes this file)
LANTERN_HD inline Camera motion_camera(Camera c, const MotionView& mv, float time) {
    c.to_world = motion_at(mv.steps, mv.camera_first, mv.camera_steps, time);
    return c;
}

// A ray of the camera path whose stream is rng, at the path's time where the scene moves.
LANTERN_HD inline Ray timed_ray(Ray r, const MotionView& mv, const Rng& rng) {
    if (mv.any()) r.time = motion_time(rng);
    return r;
}

}  // namespace lantern
