// Updates of a running session that keep its scene and acceleration structure: the viewport's
// camera and view moves, material edits. Sampling restarts as in a new session (iteration 0,
// the same random streams), so the image after an update is the image a new session of the
// updated scene gives.
#include <algorithm>
#include <mutex>

#include "integrator/session.h"

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
    if (wave_) wave_->vertices_per_path = -1.0;  // the light vertex cache estimate is per view
    cancel_.store(false);       // a cancel of the old view's step is served
    publish();
}

bool Session::update_camera(const SceneInput& in) {
    std::lock_guard<std::mutex> serial(step_mutex_);  // after a running step returns
    if (gpu_) return false;
    scene_->set_camera(in);
    restart();
    return true;
}

bool Session::update_materials(const SceneInput& in) {
    std::lock_guard<std::mutex> serial(step_mutex_);
    if (gpu_ || !scene_->update_materials(in)) return false;
    restart();
    return true;
}

}  // namespace lantern
