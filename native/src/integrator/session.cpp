#include "integrator/session.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "backend/backend.h"
#include "backend/cpu/cpu_exec.h"
#include "backend/cuda/cuda_renderer.h"
#include "integrator/pt.h"

namespace lantern {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr int kChunkPaths = 1 << 18;  // paths in flight per wavefront chunk on the CPU

}  // namespace

Session::Session(const SceneInput& scene, const SessionSettings& settings) : settings_(settings) {
    init(scene, nullptr);
}

Session::Session(const SceneInput& scene, const SessionSettings& settings,
                 std::unique_ptr<CudaRenderer> gpu)
    : settings_(settings) {
    init(scene, std::move(gpu));
}

void Session::init(const SceneInput& scene, std::unique_ptr<CudaRenderer> test_gpu) {
    const std::string& integ = settings_.integrator;
    if (integ != "pt" && integ != "lt" && integ != "bdpt" && integ != "lvc" && integ != "cis") {
        throw std::invalid_argument("integrator '" + integ +
                                    "' is not available (pt, lt, bdpt, lvc, cis)");
    }
    bidirectional_ = integ == "bdpt" || integ == "lvc" || integ == "cis";
    mode_ = integ == "bdpt" ? kBdptOwnPath : integ == "lvc" ? kLvcUniform : kCisResampled;
    sort_ = settings_.sort < 0 ? integ == "cis" : settings_.sort != 0;
    if (settings_.connections < 1 || settings_.connections > 64) {
        throw std::invalid_argument("connections (N) must be in [1, 64]");
    }
    if (settings_.candidates < 1 || settings_.candidates > 64) {
        throw std::invalid_argument("candidates (M) must be in [1, 64]");
    }
    if (settings_.cis_target != "contribution" && settings_.cis_target != "bsdf") {
        throw std::invalid_argument("cis_target must be 'contribution' or 'bsdf'");
    }
    const std::string& want = settings_.backend;
    if (want != "cpu" && want != "cuda" && want != "auto") {
        throw std::invalid_argument("backend '" + want + "' is not one of cpu, cuda, auto");
    }
    if (settings_.spp_per_iteration < 1 || settings_.spp_per_iteration > 4096) {
        throw std::invalid_argument("spp_per_iteration must be in [1, 4096]");
    }
    if (settings_.max_depth < 1 || settings_.max_depth > 1024) {
        throw std::invalid_argument("max_depth must be in [1, 1024]");
    }
    auto t0 = Clock::now();
    scene_ = std::make_unique<HostScene>(scene);
    if (settings_.integrator == "lt") check_light_tracing(scene);
    warnings_ = scene_->warnings();
    // "auto" takes the GPU when there is a usable one; "cuda" without one says why. Either way
    // the render goes on, on the CPU.
    if (test_gpu) {
        gpu_ = std::move(test_gpu);
        backend_name_ = "cuda";
        device_name_ = gpu_->device_name();
    } else if (want == "cuda" || want == "auto") {
        const CudaInfo info = cuda_info();
        if (info.available) {
            try {
                gpu_ = make_cuda_renderer(*scene_, settings_, warnings_);
                backend_name_ = "cuda";
                device_name_ = gpu_->device_name();
            } catch (const CudaUnavailable& e) {
                warnings_.push_back(std::string("the CUDA backend cannot render this scene (") +
                                    e.what() + "); rendering on the CPU");
            }
        } else if (want == "cuda") {
            warnings_.push_back("the CUDA backend is not available: " + info.reason +
                                "; rendering on the CPU");
        }
    }
    if (!gpu_) start_cpu_backend();
    width_ = scene.width;
    height_ = scene.height;
    accum_.assign(size_t(width_) * height_ * 3, 0.0);
    stats_.time_build = seconds_since(t0);
    publish();
}

Session::~Session() = default;

void Session::start_cpu_backend() {
    backend_ = std::make_unique<CpuBackend>(scene_->view(), settings_.threads, warnings_);
    backend_name_ = "cpu";
    device_name_ = "cpu";
}

// A step on the GPU. When the GPU runs out of memory (or fails otherwise), the samples so far
// stay where they can be read back, the GPU is let go and this and later steps render on the
// CPU. A sticky CUDA error loses the GPU's samples: the render restarts on the CPU.
bool Session::step_cuda(Clock::time_point t0) {
    try {
        if (!gpu_->step(settings_, iteration_, stats_, cancel_, warnings_)) return false;
    } catch (const std::runtime_error& e) {  // out of memory, or a CUDA error: never a crash
        std::vector<double> sum;
        int64_t samples = 0;
        try {
            sum = gpu_->accum(&samples);
        } catch (const std::exception&) {
            sum.clear();
        }
        {
            std::lock_guard<std::mutex> lock(result_mutex_);  // image() may be reading gpu_
            gpu_.reset();
            if (sum.size() == accum_.size()) {
                accum_ = sum;
                spp_ = samples;
            } else {
                std::fill(accum_.begin(), accum_.end(), 0.0);
                spp_ = 0;
            }
        }
        warnings_.push_back(std::string("the GPU stopped (") + e.what() +
                            "); the render goes on on the CPU");
        start_cpu_backend();
        return step_locked();
    }
    {
        std::lock_guard<std::mutex> lock(result_mutex_);
        spp_ += settings_.spp_per_iteration;
    }
    ++stats_.iterations;
    stats_.time_total += seconds_since(t0);
    return true;
}

int Session::bdpt_samples_per_pass(int spp_it) {
    cache_budget_ = CpuExec::cache_budget(settings_.cache_budget_mb);
    cache_costs_ = CpuExec::cache_costs(mode_ == kBdptOwnPath);
    return cache_samples_per_pass(cache_budget_, vertices_per_path_, cache_costs_,
                                  settings_.max_depth, spp_it, width_, height_,
                                  "light vertex cache", &split_warned_, warnings_);
}

void Session::resize_state(int n) {
    if (int(alive_.size()) >= n) return;
    for (auto* v : {&ray_o_, &ray_d_, &throughput_, &radiance_, &shadow_o_, &shadow_d_, &shadow_c_,
                    &prev_p_, &prev_n_})
        v->resize(n);
    for (auto* v : {&ray_tmin_, &ray_tmax_, &prev_pdf_, &hit_t_, &shadow_tmax_}) v->resize(n);
    rng_.resize(n);
    for (auto* v : {&depth_, &hit_prim_, &queue_, &next_queue_}) v->resize(n);
    hit_uv_.resize(n);
    for (auto* v : {&alive_, &dropped_, &shadow_valid_, &occluded_}) v->resize(n);
    state_ = PathState{ray_o_.data(),    ray_d_.data(),     ray_tmin_.data(),    ray_tmax_.data(),
                       throughput_.data(), radiance_.data(), rng_.data(),        depth_.data(),
                       prev_pdf_.data(),  alive_.data(),     dropped_.data(),     hit_t_.data(),
                       hit_prim_.data(),  hit_uv_.data(),    shadow_o_.data(),    shadow_d_.data(),
                       shadow_tmax_.data(), shadow_c_.data(), shadow_valid_.data(),
                       prev_p_.data(),    prev_n_.data()};
}

bool Session::step() {
    std::lock_guard<std::mutex> serial(step_mutex_);
    struct Finish {  // also when the step throws
        Session* s;
        ~Finish() {
            s->cancel_.store(false);  // a cancel is served by the step that saw it
            s->publish();
        }
    } finish{this};
    if (cancel_.load()) return false;  // cancelled before it started
    return step_locked();
}

void Session::publish() {
    std::lock_guard<std::mutex> lock(result_mutex_);
    published_stats_ = stats_;
    published_warnings_ = warnings_;
}

int64_t Session::spp() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    return spp_;
}

SessionStats Session::stats() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    return published_stats_;
}

std::vector<std::string> Session::warnings() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    return published_warnings_;
}

bool Session::step_locked() {
    auto t0 = Clock::now();
    if (gpu_) return step_cuda(t0);
    const int spp_it = settings_.spp_per_iteration;
    const int64_t pixels = int64_t(width_) * height_;
    const int64_t chunk_pixels = std::max<int64_t>(1, kChunkPaths / spp_it);
    // chunks write their pixels into iteration_; it joins accum_ only if the step finishes
    iteration_sum_.assign(accum_.size(), 0.0);
    if (bidirectional_) {
        if (!step_bidirectional(spp_it)) return false;
        {
            std::lock_guard<std::mutex> lock(result_mutex_);
            for (size_t k = 0; k < accum_.size(); ++k) accum_[k] += iteration_sum_[k];
            spp_ += spp_it;
        }
        ++stats_.iterations;
        stats_.time_total += seconds_since(t0);
        return true;
    }
    for (int64_t p0 = 0; p0 < pixels; p0 += chunk_pixels) {
        int64_t np = std::min(chunk_pixels, pixels - p0);
        if (settings_.integrator == "lt") {
            run_lt_chunk(p0 * spp_it, int(np * spp_it));
        } else {
            run_chunk(p0 * spp_it, int(np * spp_it));
        }
        if (cancel_.load()) return false;
    }
    {
        std::lock_guard<std::mutex> lock(result_mutex_);
        for (size_t k = 0; k < accum_.size(); ++k) accum_[k] += iteration_sum_[k];
        spp_ += spp_it;
    }
    ++iteration_;
    ++stats_.iterations;
    stats_.time_total += seconds_since(t0);
    return true;
}

void Session::run_chunk(int64_t first_path, int n) {
    resize_state(n);
    const SceneView& sv = scene_->view();
    const PtSettings st{settings_.max_depth, settings_.rr_depth, settings_.spp_per_iteration,
                        settings_.seed, iteration_, settings_.light_candidates};
    const PathState ps = state_;
    auto t = Clock::now();
    // Slots are chunk-local; the path's global index drives its random stream and pixel.
    backend_->for_all(n, [&](int i) {
        pt_generate(sv, ps, st, i, first_path + i);
        queue_[i] = i;
    });
    stats_.time_generate += seconds_since(t);
    int active = n;
    stats_.rays_camera += n;
    bool first = true;
    while (active > 0 && !cancel_.load()) {
        trace_queue(active, first);
        t = Clock::now();
        backend_->for_all(active, [&](int k) { pt_shade(sv, ps, st, queue_[k]); });
        stats_.time_shade += seconds_since(t);
        t = Clock::now();
        int64_t shadows = 0;
        for (int k = 0; k < active; ++k) shadows += ps.shadow_valid[queue_[k]];
        backend_->for_all(active, [&](int k) {
            int i = queue_[k];
            if (!ps.shadow_valid[i]) return;
            Ray r{ps.shadow_o[i], ps.shadow_d[i], 0.0f, ps.shadow_tmax[i]};
            pt_shadow_result(ps, i, backend_->occluded(r));
        });
        stats_.rays_shadow += shadows;
        stats_.time_shadow += seconds_since(t);
        // compaction, in order: the next queue keeps the paths that continue
        active = backend_->compact(queue_.data(), active, ps.alive, next_queue_.data());
        std::swap(queue_, next_queue_);
        if (active) stats_.rays_indirect += active;
        first = false;
    }
    if (cancel_.load()) return;
    film(first_path, n);
}

void Session::trace_queue(int active, bool camera_rays) {
    auto t = Clock::now();
    const PathState ps = state_;
    const RayKind kind = camera_rays ? RayKind::kCamera : RayKind::kIndirect;
    backend_->for_all(active, [&](int k) {
        int i = queue_[k];
        Ray r{ps.ray_o[i], ps.ray_d[i], ps.ray_tmin[i], ps.ray_tmax[i]};
        HitRecord h = backend_->intersect(r, kind);
        ps.hit_t[i] = h.t;
        ps.hit_prim[i] = h.prim;
        ps.hit_uv[i] = h.uv;
    });
    stats_.time_trace += seconds_since(t);
}

void Session::count_dropped(int n) {
    int64_t dropped = 0;
    for (int i = 0; i < n; ++i) dropped += state_.dropped[i];
    stats_.nonfinite_dropped += dropped;
}

// Adds the chunk's per-path radiance to its pixels, in a fixed order.
void Session::film(int64_t first_path, int n) {
    const PathState ps = state_;
    auto t = Clock::now();
    const int spp_it = settings_.spp_per_iteration;
    const int64_t p0 = first_path / spp_it;
    const int np = n / spp_it;
    count_dropped(n);
    backend_->for_all(np, [&](int p) {
        double sum[3] = {0, 0, 0};
        for (int s = 0; s < spp_it; ++s) {
            Vec3 c = ps.radiance[p * spp_it + s];
            sum[0] += c.x;
            sum[1] += c.y;
            sum[2] += c.z;
        }
        double* dst = &iteration_sum_[size_t(p0 + p) * 3];
        dst[0] += sum[0];
        dst[1] += sum[1];
        dst[2] += sum[2];
    });
    stats_.time_film += seconds_since(t);
}

std::vector<float> Session::image() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    std::vector<float> img(accum_.size(), 0.0f);
    if (spp_ == 0) return img;
    std::vector<double> gpu_sum;
    int64_t samples = spp_;
    if (gpu_) gpu_sum = gpu_->accum(&samples);  // the sum and its own sample count
    if (samples <= 0) return img;
    const std::vector<double>& sum = gpu_ ? gpu_sum : accum_;
    const double inv = 1.0 / double(samples);
    for (size_t k = 0; k < sum.size() && k < img.size(); ++k) img[k] = float(sum[k] * inv);
    return img;
}

}  // namespace lantern
