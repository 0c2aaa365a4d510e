// Strands into the scene (docs/curves.md): each CurveInput's strands as round linear segments
// (accel/curve_bvh_build.h's curve_segments drops those without a surface), primitive ids after
// the triangles'. Bad input gets a message and no segments: offsets that do not index the
// points, a material out of range (the first material then), non-finite points or radii.
#include <stdexcept>
#include <string>

#include "accel/curve_bvh_build.h"
#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace lantern {

namespace {

// The strands' layout is consistent: offsets from 0, non-decreasing, ending at the point count,
// one radius per point, one material per strand (or none: material 0).
bool curve_layout_ok(const CurveInput& c, std::string* why) {
    const size_t np = c.points.size() / 3;
    if (c.points.size() % 3 != 0) return *why = "points are not 3 floats each", false;
    if (c.radius.size() != np) return *why = "needs one radius per point", false;
    if (c.offsets.empty() || c.offsets.front() != 0 || size_t(c.offsets.back()) != np)
        return *why = "offsets must run from 0 to the number of points", false;
    for (size_t k = 1; k < c.offsets.size(); ++k)
        if (c.offsets[k] < c.offsets[k - 1]) return *why = "offsets must not decrease", false;
    const size_t ns = c.offsets.size() - 1;
    if (!c.material_ids.empty() && c.material_ids.size() != ns)
        return *why = "needs one material id per strand", false;
    return true;
}

}  // namespace

// Bytes the strands take once built, per segment: the scene's CurveSeg and per-primitive
// entries (material, flags, light and sets), a ray-query structure's copy of the segments and its
// nodes or Embree's vertices, and per kind of ray where the kinds differ (curve_accel.cpp): a
// generous 4 x 40 + 16 B.
constexpr double kCurveBytesPerSegment = 176.0;

void HostScene::add_curves(const SceneInput& in) {
    // memory first, from the counts (docs/curves.md "Bad input"): millions of strands are fine,
    // more than half the machine's memory is refused before anything is built
    double segments = 0.0;
    for (const CurveInput& c : in.curves)
        segments += double(c.points.size() / 3) -
                    double(c.offsets.empty() ? 0 : c.offsets.size() - 1);
    if (segments * kCurveBytesPerSegment > 0.5 * memory_limit_bytes())
        throw std::invalid_argument("the scene's strands (" + std::to_string(int64_t(segments)) +
                                    " segments) need " +
                                    format_bytes(segments * kCurveBytesPerSegment) +
                                    ", more than half of the " +
                                    format_bytes(memory_limit_bytes()) +
                                    " this render may use; reduce the hair's count or steps");
    for (size_t k = 0; k < in.curves.size(); ++k) {
        const CurveInput& c = in.curves[k];
        const std::string who = "curves " + std::to_string(k) + " ('" + c.name + "')";
        std::string why;
        if (!curve_layout_ok(c, &why)) throw std::invalid_argument(who + ": " + why);
        const int ns = int(c.offsets.size()) - 1;
        std::vector<CurveSeg> segs = curve_segments(c.points.data(), c.radius.data(),
                                                    c.offsets.data(), ns);
        size_t expected = 0;
        for (int s = 0; s < ns; ++s)
            expected += size_t(std::max(c.offsets[s + 1] - c.offsets[s] - 1, 0));
        if (segs.size() < expected) {
            // radii 0 at both ends are no surface (as in Cycles): say so only for bad values
            size_t bad = 0;
            for (size_t p = 0; p < c.radius.size(); ++p) {
                const float* x = &c.points[3 * p];
                if (!(c.radius[p] >= 0.0f) || !std::isfinite(c.radius[p]) ||
                    !std::isfinite(x[0] + x[1] + x[2]))
                    ++bad;
            }
            if (bad)
                warnings_.push_back(who + ": " + std::to_string(bad) +
                                    " points with a NaN, infinite or negative radius or position;"
                                    " their segments are left out");
        }
        // segments far beyond the ray queries' range cannot be traced (scene/scene_limits.h)
        size_t far = 0;
        const uint8_t flags = uint8_t((c.visible_camera ? kVisibleCamera : 0) |
                                      (c.cast_shadow ? kCastShadow : 0));
        int strand = 0;  // segments come in strand order
        for (CurveSeg& g : segs) {
            if (!within_limit(g.p0) || !within_limit(g.p1) || !(g.r0 < kMaxCoordinate) ||
                !(g.r1 < kMaxCoordinate)) {
                ++far;
                continue;
            }
            // CurveSeg::index: the strand's material comes from the segment's first point
            while (c.offsets[strand + 1] <= g.index) ++strand;
            uint32_t mat = c.material_ids.empty() ? 0u : c.material_ids[size_t(strand)];
            if (mat >= materials_.size()) {
                warnings_.push_back(who + ": material " + std::to_string(mat) +
                                    " does not exist; strand " + std::to_string(strand) +
                                    " uses material 0");
                mat = 0;
            }
            g.index = int32_t(curve_segs_.size());
            curve_segs_.push_back(g);
            curve_material_.push_back(mat);
            curve_flags_.push_back(flags);
        }
        if (far)
            warnings_.push_back(who + ": " + std::to_string(far) + " segments lie beyond the " +
                                format_metres(kMaxCoordinate) + " m the ray queries can take;"
                                " they are left out");
    }
    if (size_t(num_triangles()) + curve_segs_.size() > size_t(INT32_MAX))
        throw std::invalid_argument("the scene has more triangles and strand segments than "
                                    "primitive ids (2^31)");
}

// After the lights and linking: every per-triangle array gets the segments' entries (not
// emitters; the first light and shadow set; every kind of ray sees them).
void HostScene::add_curve_prims() {
    if (curve_segs_.empty()) return;
    tri_material_.insert(tri_material_.end(), curve_material_.begin(), curve_material_.end());
    tri_flags_.insert(tri_flags_.end(), curve_flags_.begin(), curve_flags_.end());
    tri_light_.resize(tri_material_.size(), -1);
    if (!tri_rays_.empty()) tri_rays_.resize(tri_material_.size(), uint8_t(kRayKindsAll));
    if (!tri_light_set_.empty()) tri_light_set_.resize(tri_material_.size(), 0);
    if (!tri_shadow_set_.empty()) tri_shadow_set_.resize(tri_material_.size(), 0);
}

}  // namespace lantern
