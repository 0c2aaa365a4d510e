#include "scene/scene_limits.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#if defined(__unix__)
#include <sys/resource.h>
#include <unistd.h>
#endif

#include "scene/scene.h"

namespace lantern {

double triangle_area2(Vec3 a, Vec3 b, Vec3 c) {
    const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
    const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

double max_edge(Vec3 a, Vec3 b, Vec3 c) {
    auto len = [](Vec3 p, Vec3 q) {
        const double x = double(p.x) - q.x, y = double(p.y) - q.y, z = double(p.z) - q.z;
        return std::sqrt(x * x + y * y + z * z);
    };
    return std::max(len(a, b), std::max(len(b, c), len(c, a)));
}

std::string light_label(const LightInput& li, size_t index) {
    if (!li.name.empty()) return "light '" + li.name + "'";
    return "light " + std::to_string(index) + " (" + li.type + ")";
}

bool light_within_limit(const LightInput& li, size_t index, std::vector<std::string>& warnings) {
    if (li.type == "sun") return true;  // a direction only
    const Vec3 p = li.type == "point" ? li.position
                                      : Vec3{li.to_world[3], li.to_world[7], li.to_world[11]};
    if (within_limit(p) || !is_finite(p)) return true;  // non-finite: as before, not ours
    warnings.push_back(light_label(li, index) + " is " + format_metres(distance_from_origin(p)) +
                       " m from the origin, beyond the " + format_metres(kMaxCoordinate) +
                       " m the ray queries can take; it was left out");
    return false;
}

std::string format_metres(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

double memory_limit_bytes() {
    double limit = 1e300;
#if defined(__unix__)
    const double phys = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
    if (phys > 0) limit = phys;
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
        limit = std::min(limit, double(rl.rlim_cur));
#endif
    return limit;
}

std::string format_bytes(double bytes) {
    char buf[32];
    if (bytes >= double(1ull << 30)) {
        std::snprintf(buf, sizeof buf, "%.1f GiB", bytes / double(1ull << 30));
    } else {
        std::snprintf(buf, sizeof buf, "%.0f MiB", bytes / double(1ull << 20));
    }
    return buf;
}

void check_film_memory(int width, int height) {
    const double need = double(width) * double(height) * kFilmBytesPerPixel;
    // half for the film: the rest is the scene, the wavefront and the light vertex cache
    const double have = 0.5 * memory_limit_bytes();
    if (need > have) {
        throw std::invalid_argument(
            "a " + std::to_string(width) + "x" + std::to_string(height) + " film needs " +
            format_bytes(need) + " for its buffers (" +
            std::to_string(int(kFilmBytesPerPixel)) + " bytes per pixel), more than the " +
            format_bytes(have) + " a film may take (half the memory this process may use); "
            "lower the resolution");
    }
}

}  // namespace lantern
