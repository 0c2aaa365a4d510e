// Camera rays with Cycles' sample placement: the pixel filter is importance-sampled (each
// sample lands in its own pixel with weight one) through an inverted CDF of the 1D
// Blackman-Harris filter, applied separably in x and y.
#pragma once

#include "core/rng.h"
#include "scene/scene_view.h"

namespace lantern {

// Blackman-Harris window over [-width/2, width/2]; Cycles uses width = 2 x Blender's filter size.
LANTERN_HD inline float blackman_harris(float x, float width) {
    float v = 2.0f * kPi * (x / width + 0.5f);
    return 0.35875f - 0.48829f * cosf(v) + 0.14128f * cosf(2.0f * v) - 0.01168f * cosf(3.0f * v);
}

LANTERN_HD inline float filter_offset(const CameraView& c, float u) {
    float x = u * float(c.filter_table_size - 1);
    int i = int(x);
    if (i >= c.filter_table_size - 1) return c.filter_cdf[c.filter_table_size - 1];
    float f = x - float(i);
    return c.filter_cdf[i] * (1.0f - f) + c.filter_cdf[i + 1] * f;
}

// Ray through raster position (x, y), y down from the top row; tmin/tmax carry the clip range.
LANTERN_HD inline Ray camera_ray(const CameraView& c, float x, float y) {
    float sx = c.screen[0] + (x / float(c.width)) * (c.screen[1] - c.screen[0]);
    float sy = c.screen[3] - (y / float(c.height)) * (c.screen[3] - c.screen[2]);
    Ray r;
    if (c.orthographic) {
        r.o = c.to_world.point(vec3(sx, sy, 0.0f));
        r.d = normalize(c.to_world.vector(vec3(0.0f, 0.0f, -1.0f)));
        r.tmin = c.clip_start;
        r.tmax = c.clip_end;
    } else {
        Vec3 dl = normalize(vec3(sx, sy, -1.0f));
        float inv_z = 1.0f / fmaxf(-dl.z, 1e-8f);
        r.o = c.to_world.origin();
        r.d = normalize(c.to_world.vector(dl));
        r.tmin = c.clip_start * inv_z;
        r.tmax = c.clip_end * inv_z;
    }
    return r;
}

LANTERN_HD inline Ray generate_camera_ray(const CameraView& c, int pixel, Rng& rng) {
    int px = pixel % c.width, py = pixel / c.width;
    Vec2 u = rng.uniform2();
    float x = float(px) + 0.5f + filter_offset(c, u.x);
    float y = float(py) + 0.5f + filter_offset(c, u.y);
    return camera_ray(c, x, y);
}

}  // namespace lantern
