// Updates of a running session that keep its scene and acceleration structure: the viewport's
// camera and view moves. Sampling restarts as in a new session (iteration 0, the same random
// streams), so the image after an update is the image a new session of the moved camera gives.
#include <algorithm>
#include <mutex>

#include "integrator/session.h"

namespace lantern {

bool Session::update_camera(const SceneInput& in) {
    std::lock_guard<std::mutex> serial(step_mutex_);  // after a running step returns
    if (gpu_) return false;
    scene_->set_camera(in);
    {
        std::lock_guard<std::mutex> lock(result_mutex_);
        width_ = in.width;
        height_ = in.height;
        accum_.assign(size_t(width_) * height_ * 3, 0.0);
        spp_ = 0;
    }
    iteration_ = 0;
    vertices_per_path_ = -1.0;  // the light vertex cache estimate is per view
    cancel_.store(false);       // a cancel of the old view's step is served
    publish();
    return true;
}

}  // namespace lantern
