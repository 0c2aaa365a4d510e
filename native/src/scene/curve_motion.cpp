// Strands under motion blur, the host side (docs/motion_blur.md "Strands"; accel/curve_bvh.h's
// CurveKeys): a strand set's points (and radii) at the shutter's steps checked, and the steps'
// segments laid out for the ray queries. Every moving set shares the scene's step count (the
// largest of them): a set of fewer steps is sampled piecewise linearly at the shared steps,
// exact where its steps are among them (the add-on's 3, 5, 9, ... nest). Bad steps (not finite,
// a negative radius, beyond the ray queries' range, a size that does not match the points):
// a message naming the set and the step, and the set renders still, where it was exported.
#include <cmath>
#include <string>

#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace lantern {

int HostScene::curve_input_steps(const CurveInput& c, const std::string& who) {
    if (c.deform.empty() && c.deform_radius.empty()) return 0;
    const size_t per = c.points.size(), np = per / 3;
    auto still = [&](const std::string& why) {
        warnings_.push_back(who + ": " + why + "; rendered without motion blur (where it is at "
                            "the frame)");
        return 0;
    };
    if (per == 0 || c.deform.size() % per != 0 || c.deform.size() / per < 2)
        return still("its motion steps do not match its " + std::to_string(np) +
                     " points (got " + std::to_string(c.deform.size() / 3) +
                     " positions; a hair system whose strand or key count changes over the "
                     "shutter cannot be blurred)");
    const size_t steps = c.deform.size() / per;
    if (!c.deform_radius.empty() && c.deform_radius.size() != steps * np)
        return still("its radii at the motion steps do not match its " + std::to_string(np) +
                     " points at " + std::to_string(steps) + " steps");
    for (size_t k = 0; k < c.deform.size(); k += 3) {
        const Vec3 p = vec3(c.deform[k], c.deform[k + 1], c.deform[k + 2]);
        if (!within_limit(p))
            return still("a point at motion step " + std::to_string(k / per) +
                         " is not finite or lies beyond the " + format_metres(kMaxCoordinate) +
                         " m the ray queries can take");
    }
    for (size_t k = 0; k < c.deform_radius.size(); ++k)
        if (!(c.deform_radius[k] >= 0.0f) || !(c.deform_radius[k] < kMaxCoordinate))
            return still("a radius at motion step " + std::to_string(k / np) +
                         " is negative or not finite");
    return int(steps);
}

CurveSeg curve_key(const CurveInput& c, int steps, int32_t i, int k, int shared) {
    // the shared step k's time on c's own steps
    const float x = shared > 1 ? float(k) * float(steps - 1) / float(shared - 1) : 0.0f;
    const int a = x >= float(steps - 1) ? steps - 2 : int(x);
    const float f = (steps - 1) * k == a * (shared - 1) ? 0.0f : x - float(a);
    const size_t per = c.points.size(), np = per / 3;
    auto point = [&](int s, int32_t p) {
        const float* v = c.deform.data() + size_t(s) * per + 3 * size_t(p);
        return vec3(v[0], v[1], v[2]);
    };
    auto radius = [&](int s, int32_t p) {
        return c.deform_radius.empty() ? c.radius[size_t(p)]
                                       : c.deform_radius[size_t(s) * np + size_t(p)];
    };
    CurveSeg g;
    if (f == 0.0f) {  // on one of c's own steps: its values exactly
        g.p0 = point(a, i), g.p1 = point(a, i + 1);
        g.r0 = radius(a, i), g.r1 = radius(a, i + 1);
    } else {
        const float e = 1.0f - f;
        g.p0 = point(a, i) * e + point(a + 1, i) * f;
        g.p1 = point(a, i + 1) * e + point(a + 1, i + 1) * f;
        g.r0 = radius(a, i) * e + radius(a + 1, i) * f;
        g.r1 = radius(a, i + 1) * e + radius(a + 1, i + 1) * f;
    }
    g.index = i;
    return g;
}

}  // namespace lantern
