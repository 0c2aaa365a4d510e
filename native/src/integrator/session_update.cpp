// Updates of a running session that keep its scene and acceleration structure: the viewport's
// camera and view moves, material edits, instance moves (the top level only). Sampling restarts as in a new session (iteration 0,
// the same random streams), so the image after an update is the image a new session of the
// updated scene gives.
#include <algorithm>
#include <mutex>
#include <stdexcept>

#include "integrator/session.h"

#include "backend/backend.h"
#include "backend/cpu/cpu_exec.h"
#include "integrator/wavefront.h"

namespace lantern {

void Session::restart() {
    {
        std::lock_guard<std::mutex> lock(result_mutex_);
        width_ = scene_->view().camera.width;
        height_ = scene_->view().camera.height;
        accum_.assign(size_t(width_) * height_ * 3, 0.0);
        spp_ = 0;
    }
    iteration_ = 0;
    auto_iteration_[0] = auto_iteration_[1] = 0;
    // "auto" keeps its choice for the new view; a pilot under way starts again at its size
    if (alloc_ && alloc_->choice() == 0)
        alloc_ = std::make_unique<Allocation>(int64_t(width_) * height_, false,
                                              settings_.candidates, !gpu_);
    if (wave_) wave_->vertices_per_path = -1.0;  // the light vertex cache estimate is per view
    if (conn_alloc_)  // a new pilot for the new view
        conn_alloc_ = std::make_unique<ConnectionAllocation>(
            width_, height_, settings_.connections, settings_.candidates,
            ConnectionAllocation::zero_allowed(scene_->view()));
    cancel_.store(false);       // a cancel of the old view's step is served
    publish();
}

bool Session::update_camera(const SceneInput& in) {
    std::lock_guard<std::mutex> serial(step_mutex_);  // after a running step returns
    if (gpu_) return false;
    scene_->set_camera(in);
    settings_.connection_map.clear();  // (its film's)
    restart();
    return true;
}

bool Session::set_connection_map(const std::vector<uint8_t>& map) {
    std::lock_guard<std::mutex> serial(step_mutex_);  // between iterations, never within one
    const std::string why =
        connection_map_error(map, width_, height_, scene_->view().camera.panoramic != 0);
    if (!why.empty()) throw std::invalid_argument(why);
    settings_.connection_map = map;
    conn_alloc_.reset();  // a map set by hand replaces the allocation's
    return true;
}

bool Session::update_materials(const SceneInput& in) {
    std::lock_guard<std::mutex> serial(step_mutex_);
    if (gpu_ || !scene_->update_materials(in)) return false;
    restart();
    return true;
}

bool Session::move_instance(int k, const Transform& to_world) {
    std::lock_guard<std::mutex> serial(step_mutex_);
    if (gpu_ || !backend_ || !backend_->instanced()) return false;
    Transform inv;
    if (!invert_affine(to_world, &inv)) return false;
    if (!scene_->move_mesh(k, to_world)) return false;
    if (!backend_->move_instance(k, to_world)) {  // cannot happen after move_mesh agreed
        throw std::logic_error("the accel refused a move the scene took");
    }
    ++stats_.instance_moves;
    stats_.accel_bottom_builds = backend_->bottom_builds();
    restart();
    return true;
}

}  // namespace lantern
