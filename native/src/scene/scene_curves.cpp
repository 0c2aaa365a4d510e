// Strands into the scene (docs/curves.md): each CurveInput's strands as round linear segments
// (accel/curve_bvh_build.h's curve_segments drops those without a surface), primitive ids after
// the triangles'. Bad input gets a message and no segments: offsets that do not index the
// points, a material out of range (the first material then), non-finite points or radii.
#include <algorithm>
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
    curve_ranges_.clear();
    // memory first, from the counts (docs/curves.md "Bad input"): millions of strands are fine,
    // more than half the machine's memory is refused before anything is built
    double segments = 0.0;
    for (const CurveInput& c : in.curves)
        segments += double(c.points.size() / 3) -
                    double(c.offsets.empty() ? 0 : c.offsets.size() - 1);
    // motion blur's steps (scene/curve_motion.cpp): every moving set shares the largest count,
    // a CurveSeg per segment and step (and as much again while they are laid out)
    std::vector<int> steps(in.curves.size(), 0);
    int shared = 0;
    for (size_t k = 0; k < in.curves.size(); ++k) {
        steps[k] = curve_input_steps(in.curves[k], "curves " + std::to_string(k) + " ('" +
                                                       in.curves[k].name + "')");
        shared = std::max(shared, steps[k]);
    }
    const double per_segment = kCurveBytesPerSegment + 2.0 * sizeof(CurveSeg) * shared;
    if (segments * per_segment > 0.5 * memory_limit_bytes())
        throw std::invalid_argument("the scene's strands (" + std::to_string(int64_t(segments)) +
                                    " segments) need " +
                                    format_bytes(segments * per_segment) +
                                    ", more than half of the " +
                                    format_bytes(memory_limit_bytes()) +
                                    " this render may use; reduce the hair's count or steps");
    std::vector<CurveSeg> keys;  // per segment, its `shared` steps (laid out step-major below)
    bool moves = false;
    for (size_t k = 0; k < in.curves.size(); ++k) {
        const CurveInput& c = in.curves[k];
        const std::string who = "curves " + std::to_string(k) + " ('" + c.name + "')";
        std::string why;
        if (!curve_layout_ok(c, &why)) throw std::invalid_argument(who + ": " + why);
        const int ns = int(c.offsets.size()) - 1;
        curve_ranges_.emplace_back(int32_t(curve_segs_.size()), 0);
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
            if (shared > 1) {  // motion blur: its keys (the frame's where the set is still)
                const size_t first = keys.size();
                bool its = false;
                for (int st = 0; st < shared; ++st) {
                    CurveSeg key = steps[k] > 1 ? curve_key(c, steps[k], g.index, st, shared) : g;
                    its |= key.p0.x != g.p0.x || key.p0.y != g.p0.y || key.p0.z != g.p0.z ||
                           key.p1.x != g.p1.x || key.p1.y != g.p1.y || key.p1.z != g.p1.z ||
                           key.r0 != g.r0 || key.r1 != g.r1;
                    keys.push_back(key);
                }
                if (its) g.flags |= kCurveMoves;  // else it renders as still, bit for bit
                moves |= its;
                for (size_t j = first; j < keys.size(); ++j) {
                    keys[j].index = int32_t(curve_segs_.size());
                    keys[j].flags = g.flags;
                }
            }
            g.index = int32_t(curve_segs_.size());
            curve_segs_.push_back(g);
            curve_material_.push_back(mat);
            curve_flags_.push_back(flags);
        }
        curve_ranges_.back().second = int32_t(curve_segs_.size()) - curve_ranges_.back().first;
        if (far)
            warnings_.push_back(who + ": " + std::to_string(far) + " segments lie beyond the " +
                                format_metres(kMaxCoordinate) + " m the ray queries can take;"
                                " they are left out");
    }
    if (moves) {  // step-major: step k of segment i at k * segments + i (CurveKeys)
        const size_t n = curve_segs_.size();
        curve_keys_.resize(size_t(shared) * n);
        for (size_t i = 0; i < n; ++i)
            for (int st = 0; st < shared; ++st)
                curve_keys_[size_t(st) * n + i] = keys[i * size_t(shared) + size_t(st)];
        curve_steps_ = shared;
    }
    if (size_t(num_triangles()) + curve_segs_.size() > size_t(INT32_MAX))
        throw std::invalid_argument("the scene has more triangles and strand segments than "
                                    "primitive ids (2^31)");
}

// After the lights and linking: every per-triangle array gets the segments' entries (not
// emitters; the kinds of ray that see their object, tri_rays, made here where only strands hide
// from some kind; their CurveInput's light and shadow sets, where some emitter is linked:
// build_light_linking made the arrays).
void HostScene::add_curve_prims(const SceneInput& in) {
    if (curve_segs_.empty()) return;
    const size_t first = tri_material_.size();
    tri_material_.insert(tri_material_.end(), curve_material_.begin(), curve_material_.end());
    tri_flags_.insert(tri_flags_.end(), curve_flags_.begin(), curve_flags_.end());
    tri_light_.resize(tri_material_.size(), -1);
    bool rays_hidden = !tri_rays_.empty();
    for (size_t k = 0; k < curve_ranges_.size() && k < in.curves.size(); ++k)
        rays_hidden |= (in.curves[k].rays & kRayKindsAll) != kRayKindsAll;
    if (rays_hidden) {
        tri_rays_.resize(first, uint8_t(kRayKindsAll));
        tri_rays_.resize(tri_material_.size(), uint8_t(kRayKindsAll));
        for (size_t k = 0; k < curve_ranges_.size() && k < in.curves.size(); ++k) {
            const auto [begin, count] = curve_ranges_[k];
            std::fill_n(tri_rays_.begin() + ptrdiff_t(first + size_t(begin)), size_t(count),
                        uint8_t(in.curves[k].rays & kRayKindsAll));
        }
    }
    for (std::vector<uint8_t>* sets : {&tri_light_set_, &tri_shadow_set_}) {
        if (sets->empty()) continue;
        sets->resize(tri_material_.size(), 0);
        for (size_t k = 0; k < curve_ranges_.size() && k < in.curves.size(); ++k) {
            const CurveInput& c = in.curves[k];
            const int32_t set = (sets == &tri_light_set_ ? c.light_set : c.shadow_set) & 63;
            const auto [begin, count] = curve_ranges_[k];
            std::fill_n(sets->begin() + ptrdiff_t(first + size_t(begin)), size_t(count),
                        uint8_t(set));
        }
    }
}

}  // namespace lantern
