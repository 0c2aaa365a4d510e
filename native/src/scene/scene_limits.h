// What a scene may hold so that every ray query and buffer works: coordinates the accelerators
// can take, triangle areas without float overflow, a film that fits in memory. HostScene applies
// these checks (left-out objects named in warnings); the CPU accelerators guard each ray.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/math.h"

namespace lantern {

struct LightInput;

// ---- Coordinates ----
// Embree 3 asserts (SIGABRT, kernels/bvh/bvh_intersector1.cpp: `ray.valid()`) on a ray whose
// origin or direction has a component beyond FLT_LARGE = 1.844e18 or whose tnear / tfar is NaN
// (measured with 3.13.5: a camera 1.8e18 away renders, 1.85e18 aborts), and silently leaves out
// triangles with vertices beyond it. Scenes keep triangles and lights within kMaxCoordinate of
// the origin (the rest is left out, named in a warning); a ray that starts farther out (a far
// camera) is moved to where it enters that cube before Embree sees it. At this bound the edge
// vectors' cross products (< 8e36) stay finite in float.
constexpr float kMaxCoordinate = 1e18f;

inline bool within_limit(Vec3 p) {  // false for NaN too
    return std::fabs(p.x) <= kMaxCoordinate && std::fabs(p.y) <= kMaxCoordinate &&
           std::fabs(p.z) <= kMaxCoordinate;
}

// The largest |coordinate| of p (the distance measure of the limit).
inline float distance_from_origin(Vec3 p) {
    return std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z)));
}

// False, with a warning naming the light, when a point, spot or area light sits beyond
// kMaxCoordinate (it would light the scene by less than 1e-36 of its power per m^2 anyway).
bool light_within_limit(const LightInput& li, size_t index, std::vector<std::string>& warnings);

// Float ray-triangle tests (Embree's and the built-in BVH's) form products of an edge's square
// and a distance; past ~1e38 they overflow and the ray misses. Measured on a lone triangle seen
// from half its size away: edges of 1e13 m are hit, 2e13 m missed by both accelerators. Larger
// triangles are kept (they render where they are found) and named in a warning.
constexpr double kMaxEdge = 1e12;

// The longest edge of triangle abc, in double.
double max_edge(Vec3 a, Vec3 b, Vec3 c);

// Twice the area of triangle abc, in double (the float cross product's squared length
// overflows for edges over ~4e9 m); 0 for a degenerate one, NaN when a vertex is not finite.
double triangle_area2(Vec3 a, Vec3 b, Vec3 c);

// "light 'Lamp'", or "light 3 (point)" when it has no name.
std::string light_label(const LightInput& li, size_t index);

// "2e+19": a distance for a message.
std::string format_metres(double v);

// ---- Memory ----
// Bytes the film's buffers take per pixel: the running sum and the iteration's sum (3 doubles
// each) and image()'s float snapshot (3 floats, the array handed to Python).
constexpr double kFilmBytesPerPixel = 2 * 3 * 8 + 3 * 4;

// Memory a render may use: the physical memory, or the address-space limit when lower.
double memory_limit_bytes();

// "4.0 GiB"
std::string format_bytes(double bytes);

// Throws std::invalid_argument saying how much a width x height film needs when that is more
// than half of memory_limit_bytes() (the rest is the scene, the wavefront and the light vertex
// cache), before anything is allocated.
void check_film_memory(int width, int height);

}  // namespace lantern
