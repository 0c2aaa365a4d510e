// Camera rays with Cycles' sample placement: the pixel filter is importance-sampled (each
// sample lands in its own pixel with weight one) through an inverted CDF of the 1D
// Blackman-Harris filter, applied separably in x and y; with depth of field, a thin lens.
#pragma once

#include "core/rng.h"
#include "core/sampling.h"
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

// ---- Thin lens: a point on the aperture (camera-local x, y in metres), uniform in area ----
// Uniform density over the aperture is all the lens's importance needs: a camera ray's
// direction density about its lens point is that of the pinhole (1 / (a_pix cos^3)), so
// light tracing's splat weight keeps its form with distances taken from the lens point.
LANTERN_HD inline Vec2 sample_aperture(const CameraView& c, Vec2 u) {
    Vec2 q;
    if (c.blades >= 3) {  // a regular polygon: one of its triangles, then a point in it
        float n = float(c.blades);
        float k = floorf(u.x * n);
        float ux = u.x * n - k;
        float a0 = c.blade_rotation + 2.0f * kPi * k / n, a1 = a0 + 2.0f * kPi / n;
        float su = sqrtf(ux);
        float b0 = su * (1.0f - u.y), b1 = su * u.y;  // barycentrics of the two outer corners
        q = {b0 * cosf(a0) + b1 * cosf(a1), b0 * sinf(a0) + b1 * sinf(a1)};
    } else {
        q = sample_concentric_disk(u);
    }
    return {q.x * c.inv_aperture_ratio * c.lens_radius, q.y * c.lens_radius};
}

// ---- Panoramic equirectangular (Blender's): x runs from longitude max (left) to min, y from
// latitude max (top) to min; longitude 0 latitude 0 is the view axis (-Z), +Y up ----
LANTERN_HD inline Vec3 pano_direction(const CameraView& c, float x, float y) {
    float lon = c.pano_range[1] - (x / float(c.width)) * (c.pano_range[1] - c.pano_range[0]);
    float lat = c.pano_range[3] - (y / float(c.height)) * (c.pano_range[3] - c.pano_range[2]);
    float cl = cosf(lat);
    return {-cl * sinf(lon), sinf(lat), -cl * cosf(lon)};
}

// Raster position of camera-local direction d, and the solid angle of one pixel there.
LANTERN_HD inline Vec2 pano_raster(const CameraView& c, Vec3 d, float* pixel_w) {
    float lat = asinf(clampf(d.y, -1.0f, 1.0f));
    float lon = atan2f(-d.x, -d.z);
    float dlon = c.pano_range[1] - c.pano_range[0], dlat = c.pano_range[3] - c.pano_range[2];
    *pixel_w = cosf(lat) * (dlon / float(c.width)) * (dlat / float(c.height));
    return {(c.pano_range[1] - lon) / dlon * float(c.width),
            (c.pano_range[3] - lat) / dlat * float(c.height)};
}

// Ray through raster position (x, y), y down from the top row; tmin/tmax carry the clip range.
// A lens point (camera-local, from sample_aperture) moves the origin onto the lens and aims
// the ray at the same point of the focal plane.
LANTERN_HD inline Ray camera_ray(const CameraView& c, float x, float y, Vec2 lens = Vec2{}) {
    float sx = c.screen[0] + (x / float(c.width)) * (c.screen[1] - c.screen[0]);
    float sy = c.screen[3] - (y / float(c.height)) * (c.screen[3] - c.screen[2]);
    Ray r;
    if (c.panoramic) {  // clipping by distance along the ray, as Cycles' panoramas
        r.o = c.to_world.origin();
        r.d = normalize(c.to_world.vector(pano_direction(c, x, y)));
        r.tmin = c.clip_start;
        r.tmax = c.clip_end;
        return r;
    }
    if (c.orthographic) {
        r.o = c.to_world.point(vec3(sx, sy, 0.0f));
        r.d = normalize(c.to_world.vector(vec3(0.0f, 0.0f, -1.0f)));
        r.tmin = c.clip_start;
        r.tmax = c.clip_end;
    } else {
        Vec3 dl = normalize(vec3(sx, sy, -1.0f));
        r.o = c.to_world.origin();
        if (c.lens_radius > 0.0f) {
            Vec3 focus = vec3(sx, sy, -1.0f) * c.focus_distance;
            Vec3 lp = vec3(lens.x, lens.y, 0.0f);
            dl = normalize(focus - lp);
            r.o = c.to_world.point(lp);
        }
        float inv_z = 1.0f / fmaxf(-dl.z, 1e-8f);
        r.d = normalize(c.to_world.vector(dl));
        r.tmin = c.clip_start * inv_z;
        r.tmax = c.clip_end * inv_z;
    }
    return r;
}

// A camera sample's raster position: the pixel's centre and its filter offset (u: the sample's
// first two numbers; integrator/pixel_conn.h reads it again).
LANTERN_HD inline Vec2 camera_raster_sample(const CameraView& c, int pixel, Vec2 u) {
    int px = pixel % c.width, py = pixel / c.width;
    return Vec2{float(px) + 0.5f + filter_offset(c, u.x), float(py) + 0.5f + filter_offset(c, u.y)};
}

LANTERN_HD inline Ray generate_camera_ray(const CameraView& c, int pixel, Rng& rng) {
    const Vec2 r = camera_raster_sample(c, pixel, rng.uniform2());
    const float x = r.x, y = r.y;
    Vec2 lens = c.lens_radius > 0.0f ? sample_aperture(c, rng.uniform2()) : Vec2{};  // (pinhole
                                                                                    // when panoramic)
    return camera_ray(c, x, y, lens);
}

}  // namespace lantern
