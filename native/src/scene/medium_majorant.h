// Majorants along a ray through a heterogeneous medium (docs/volumes.md): a Volume object's
// medium has a grid of bricks (kMajorantBrick^3 voxels of its density grid each) holding a bound
// on the extinction over every point whose trilinear lookup reads a voxel of the brick; other
// heterogeneous media one constant majorant. majorant_next() walks the ray brick by brick (3D DDA,
// Amanatides & Woo) and hands out pieces of constant majorant: the one function the trackings
// (scene/medium_hetero.h) call. Host+device, no state beyond the walk.
#pragma once

#include <cstdint>

#include "core/math.h"

namespace lantern {

constexpr int kMajorantBrick = 8;  // voxels per brick side

// A medium's bricks as stages see them (SceneView::majorant_grids): brick (i, j, k) is the unit
// cube [i, i+1) x [j, j+1) x [k, k+1) of brick space and holds majorant_values[offset + (k * ny +
// j) * nx + i]; outside the bricks the majorant is `outside` (the world volume's part there).
struct MajorantGrid {
    Transform world_to_brick;
    int32_t nx, ny, nz;
    int32_t pad;
    uint64_t offset;
    float outside;
    float pad2;
};

// A piece [t0, t1) of the ray over which the majorant is mu (1/m).
struct MajorantSeg {
    float t0, t1, mu;
};

// The state of a walk along o + d t, t in [0, t_end].
struct MajorantWalk {
    const MajorantGrid* g;  // null: one piece of majorant mu_const
    const float* values;
    float t, t_end;
    float t_in, t_out;       // where the ray is inside the bricks (t_in >= t_out: never)
    float t_next[3], t_delta[3];
    int32_t idx[3], step[3];
    int32_t phase;           // 0 before the bricks, 1 inside, 2 after, 3 done
    float mu_const;
};

LANTERN_HD inline MajorantWalk majorant_walk_constant(float mu, float t_end) {
    MajorantWalk w{};
    w.g = nullptr;
    w.t = 0.0f;
    w.t_end = t_end;
    w.mu_const = mu;
    w.phase = 0;
    return w;
}

LANTERN_HD inline MajorantWalk majorant_walk_grid(const MajorantGrid& g, const float* values,
                                                  Vec3 o, Vec3 d, float t_end) {
    MajorantWalk w{};
    w.g = &g;
    w.values = values;
    w.t = 0.0f;
    w.t_end = t_end;
    w.mu_const = g.outside;
    w.phase = 0;
    const Vec3 a = g.world_to_brick.point(o), b = g.world_to_brick.vector(d);
    const float av[3] = {a.x, a.y, a.z}, bv[3] = {b.x, b.y, b.z};
    const int32_t n[3] = {g.nx, g.ny, g.nz};
    float t0 = 0.0f, t1 = t_end;
    for (int k = 0; k < 3; ++k) {  // the slabs [0, n_k]
        if (bv[k] == 0.0f) {
            if (!(av[k] >= 0.0f && av[k] < float(n[k]))) t1 = -1.0f;  // parallel, outside
            continue;
        }
        const float inv = 1.0f / bv[k];
        float ta = (0.0f - av[k]) * inv, tb = (float(n[k]) - av[k]) * inv;
        if (ta > tb) {
            const float x = ta;
            ta = tb;
            tb = x;
        }
        t0 = fmaxf(t0, ta);
        t1 = fminf(t1, tb);
    }
    w.t_in = t0;
    w.t_out = t1;
    if (!(t0 < t1)) {  // never inside: one piece of the outside majorant
        w.t_in = w.t_out = t_end;
        return w;
    }
    for (int k = 0; k < 3; ++k) {
        const float p = av[k] + bv[k] * t0;
        int32_t i = int32_t(floorf(p));
        i = i < 0 ? 0 : (i >= n[k] ? n[k] - 1 : i);
        w.idx[k] = i;
        if (bv[k] > 0.0f) {
            w.step[k] = 1;
            w.t_delta[k] = 1.0f / bv[k];
            w.t_next[k] = (float(i + 1) - av[k]) / bv[k];
        } else if (bv[k] < 0.0f) {
            w.step[k] = -1;
            w.t_delta[k] = -1.0f / bv[k];
            w.t_next[k] = (float(i) - av[k]) / bv[k];
        } else {
            w.step[k] = 0;
            w.t_delta[k] = kInf;
            w.t_next[k] = kInf;
        }
    }
    return w;
}

// The next piece of the walk; false when the ray's end was reached (the walk is done).
LANTERN_HD inline bool majorant_next(MajorantWalk& w, MajorantSeg* seg) {
    if (w.phase == 3 || !(w.t < w.t_end)) {
        w.phase = 3;
        return false;
    }
    if (!w.g) {  // constant: one piece
        *seg = MajorantSeg{w.t, w.t_end, w.mu_const};
        w.t = w.t_end;
        w.phase = 3;
        return true;
    }
    if (w.phase == 0) {
        w.phase = 1;
        if (w.t_in > w.t) {
            const float t1 = fminf(w.t_in, w.t_end);
            *seg = MajorantSeg{w.t, t1, w.mu_const};
            w.t = t1;
            if (!(w.t_in < w.t_out)) w.phase = 2;
            return true;
        }
        if (!(w.t_in < w.t_out)) w.phase = 2;
    }
    if (w.phase == 1) {
        const int k = w.t_next[0] < w.t_next[1] ? (w.t_next[0] < w.t_next[2] ? 0 : 2)
                                                : (w.t_next[1] < w.t_next[2] ? 1 : 2);
        const float t1 = fminf(fmaxf(w.t_next[k], w.t), fminf(w.t_out, w.t_end));
        const MajorantGrid& g = *w.g;
        const float mu = w.values[g.offset + (uint64_t(w.idx[2]) * uint64_t(g.ny) +
                                              uint64_t(w.idx[1])) * uint64_t(g.nx) +
                                  uint64_t(w.idx[0])];
        *seg = MajorantSeg{w.t, t1, mu};
        w.t = t1;
        w.idx[k] += w.step[k];
        w.t_next[k] += w.t_delta[k];
        const int32_t n = k == 0 ? g.nx : (k == 1 ? g.ny : g.nz);
        if (w.idx[k] < 0 || w.idx[k] >= n || !(w.t < w.t_out)) w.phase = 2;
        return true;
    }
    // after the bricks: the outside majorant to the end
    *seg = MajorantSeg{w.t, w.t_end, w.mu_const};
    w.t = w.t_end;
    w.phase = 3;
    return true;
}

}  // namespace lantern
