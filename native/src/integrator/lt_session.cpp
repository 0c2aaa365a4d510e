// The light tracer's schedule (integrator "lt"): generate light paths, then per bounce trace,
// shade, test the camera segments and splat the survivors through the pixel filter in slot
// order, so the image has the same bits whatever the thread count (no float atomics).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "backend/backend.h"
#include "integrator/lt.h"
#include "integrator/session.h"

namespace lantern {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

void check_light_tracing(const SceneInput& in) {
    for (size_t k = 0; k < in.lights.size(); ++k) {
        const LightInput& l = in.lights[k];
        if ((l.type == "point" || l.type == "spot") && l.soft_falloff && std::isfinite(l.radius) &&
            l.radius > 0.0f) {
            throw std::invalid_argument(
                "integrator 'lt' cannot trace light from scene.lights[" + std::to_string(k) +
                "] (" + l.type + ", radius " + std::to_string(l.radius) +
                " m, soft_falloff on): its disk faces each shaded point, so it has no emission "
                "distribution; set soft_falloff off (a sphere light) or radius 0");
        }
    }
}

int64_t Session::test_camera_segments(int active) {
    auto t = Clock::now();
    const PathState ps = state_;
    int64_t tested = 0;
    for (int k = 0; k < active; ++k) tested += ps.shadow_valid[queue_[k]];
    backend_->for_all(active, [&](int k) {
        int i = queue_[k];
        if (!ps.shadow_valid[i]) return;
        // the camera sees only camera-visible triangles: test with its structure
        Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
        occluded_[i] = backend_->intersect(r, RayKind::kCamera).prim >= 0 ? 1 : 0;
    });
    stats_.time_shadow += seconds_since(t);
    return tested;
}

// Adds this bounce's unoccluded splats to the iteration's pixels, in queue (slot) order.
void Session::splat(const std::vector<int32_t>& slots, int count) {
    const CameraView& c = scene_->view().camera;
    // L = width * height * spp_per_iteration light paths; the image divides by spp
    const double scale = 1.0 / (double(width_) * double(height_));
    for (int k = 0; k < count; ++k) {
        int i = slots[k];
        if (!shadow_valid_[i] || occluded_[i]) continue;
        const Vec3 v = shadow_c_[i];
        splat_pixels(c, splat_xy_[i], scale, [&](int pixel, double f) {
            double* dst = &iteration_sum_[size_t(pixel) * 3];
            dst[0] += f * v.x;
            dst[1] += f * v.y;
            dst[2] += f * v.z;
        });
    }
}

void Session::run_lt_chunk(int64_t first_path, int n) {
    resize_state(n);
    if (int(power_.size()) < n) {
        power_.resize(n);
        splat_xy_.resize(n);
    }
    const SceneView& sv = scene_->view();
    const PtSettings st{settings_.max_depth, settings_.rr_depth, settings_.spp_per_iteration,
                        settings_.seed, iteration_};
    const PathState ps = state_;
    const LightPathState lp{power_.data(), splat_xy_.data()};
    auto t = Clock::now();
    backend_->for_all(n, [&](int i) {
        lt_generate(sv, ps, lp, st, i, first_path + i);
        queue_[i] = i;
    });
    stats_.time_generate += seconds_since(t);
    int active = n;
    while (!cancel_.load()) {
        // ---- camera segments of this bounce, then splats in slot order ----
        stats_.rays_shadow += test_camera_segments(active);
        t = Clock::now();
        splat(queue_, active);
        stats_.time_film += seconds_since(t);
        // compaction, in order: the next queue keeps the paths that continue
        active = backend_->compact(queue_.data(), active, ps.alive, next_queue_.data());
        std::swap(queue_, next_queue_);
        if (active == 0) break;
        stats_.rays_indirect += active;  // light rays
        // ---- trace and shade ----
        trace_queue(active, false);
        t = Clock::now();
        backend_->for_all(active, [&](int k) { lt_shade(sv, ps, lp, st, queue_[k]); });
        stats_.time_shade += seconds_since(t);
    }
    count_dropped(n);
}

}  // namespace lantern
