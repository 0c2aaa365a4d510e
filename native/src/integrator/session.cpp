#include "integrator/session.h"
#include "scene/motion_build.h"
#include "scene/subsurface_input.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <stdexcept>

#include "backend/backend.h"
#include "backend/cpu/cpu_exec.h"
#include "backend/cuda/cuda_renderer.h"
#include "integrator/wavefront.h"

namespace lantern {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr int kChunkPaths = 1 << 18;    // paths in flight per wavefront chunk on the CPU
constexpr int kShadowBudget = 1 << 21;  // connection shadow-ray slots per camera chunk

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
    if (integ != "pt" && integ != "lt" && integ != "bdpt" && integ != "lvc" && integ != "cis" &&
        integ != "auto") {
        throw std::invalid_argument("integrator '" + integ +
                                    "' is not available (auto, pt, lt, bdpt, lvc, cis)");
    }
    if (settings_.connections < 1 || settings_.connections > 64) {
        throw std::invalid_argument("connections (N) must be in [1, 64]");
    }
    if (!(settings_.light_path_fraction >= 0.0f && settings_.light_path_fraction <= 1.0f) ||
        (integ == "bdpt" && settings_.light_path_fraction != 1.0f)) {
        throw std::invalid_argument("light_path_fraction must be in [0, 1] (bdpt: 1, a light "
                                    "path for every camera path)");
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
    if (!(settings_.adaptive_threshold >= 0.0f) || settings_.adaptive_min_samples < 0 ||
        settings_.adaptive_step < 1) {
        throw std::invalid_argument("adaptive sampling: the threshold must be >= 0, the min "
                                    "samples >= 0 and the step >= 1");
    }
    // media: lt, bdpt, lvc and cis have medium vertices in homogeneous and heterogeneous media
    // (lt_medium.h, bdpt_medium_stages.h, bdpt_medium_hetero.h); bdpt, lvc and cis gather
    // emissive media on their camera paths, lt (no camera gather) hands them over; the rest
    // hands every medium over
    std::string media_note;
    if (integ != "pt" && integ != "auto") {
        const bool bidir = integ == "bdpt" || integ == "lvc" || integ == "cis";
        const bool lt = integ == "lt";
        const std::string why = bidir ? std::string()
                                : lt  ? emissive_media_reason(scene)
                                      : media_reason(scene);
        if (!why.empty()) {
            media_note = "integrator '" + integ + "' does not render participating media (the " +
                         "scene has " + why + "; " +
                         (lt ? std::string("its light paths start on lights only, not in "
                                           "emitting media")
                             : std::string("no medium vertices in its paths")) +
                         "): rendering with pt";
            settings_.integrator = "pt";
        } else if (const std::string ss = subsurface_volume_reason(scene); !ss.empty()) {
            // subsurface: pt, the camera paths of bdpt, lvc and cis (bdpt_sss.h) and lt's light
            // paths (the adjoint walk, lt_sss.h) walk; their exits leave into the medium around
            // the object (pt's rule), not a volume inside the walking mesh (a walk entered from
            // inside that volume would leave into it wherever it lands: docs/subsurface.md,
            // "Handed to pt")
            media_note = "integrator '" + integ + "' does not render " + ss +
                         ": rendering with pt";
            settings_.integrator = "pt";
        } else if (const std::string rw = subsurface_random_walk_reason(scene);
                   lt && !rw.empty() && !std::getenv("LANTERN_SSS_ADJOINT")) {
            // lt's adjoint walk is shown right with Skin only: with Random Walk its estimates
            // have tails too heavy to converge in a hollow lit from inside (subsurface_input.h;
            // LANTERN_SSS_ADJOINT, tests' and bench's switch, keeps lt walking)
            media_note = "integrator 'lt' does not render " + rw +
                         " yet (its light paths' walk converges too slowly there; Random Walk "
                         "(Skin) it renders): rendering with pt";
            settings_.integrator = "pt";
        }
    }
    // motion blur: pt, lt, bdpt, lvc and cis give each path a time (docs/motion_blur.md)
    // object ray visibility: pt (pt_ray_visibility.h), bdpt, lvc and cis on surfaces
    // (bidir_ray_visibility.h), lt on surfaces (lt_ray_visibility.h); a lamp's Cast Shadow
    // off: Cycles' answer weighs next-event estimation against BSDF sampling
    // (pt_lamp_unshadowed), which bdpt, lvc and cis reproduce, as they do light linking and
    // shadow linking (bidir_linking.h); an object's Cast Shadow off: bidir_no_shadow.h; lt
    // linking and Cast Shadow off by its first segment's walk (lt_linking.h). What is left
    // (bidir_visibility_reason) is named
    if (media_note.empty() && integ != "pt" && integ != "auto") {
        const std::string why = bidir_visibility_reason(scene, integ == "lt");
        if (!why.empty()) {
            media_note = "integrator '" + integ + "' does not render this combination of ray " +
                         "visibility, linking or Cast Shadow off yet (the scene has " + why +
                         "): rendering with pt";
            settings_.integrator = "pt";
        }
    }
    // motion blur with volumes: every integrator's rays through media carry their path's time
    // (pt_volume.h; lt_medium.h, bdpt_medium.h, medium_motion.h)
    // strands: lt, bdpt, lvc and cis have strand vertices, the hair lobe's and pt's points on
    // the tube for other BSDFs (bdpt_curve.h); the rest only pt shades so far (docs/curves.md)
    std::string curves_bidir_why = curves_bidir_reason(scene);
    if (curves_bidir_why.empty() && integ == "lt") curves_bidir_why = curves_lt_reason(scene);
    if (media_note.empty() && integ != "pt" && integ != "auto" && !curves_bidir_why.empty()) {
        media_note = "integrator '" + integ + "' does not render this hair yet (the scene has " +
                     curves_bidir_why + "): rendering with pt";
        settings_.integrator = "pt";
    }
    auto t0 = Clock::now();
    // a scene meant for the GPU starts no light paths on soft-falloff lights (bdpt_light.h);
    // should the GPU then refuse it, the CPU renders those lights camera-side, as the GPU would
    const bool gpu_meant = test_gpu != nullptr ||
                           ((want == "cuda" || want == "auto") && cuda_info().available);
    scene_ = std::make_unique<HostScene>(scene, !gpu_meant);
    scene_->set_hair_reverse(settings_.integrator != "pt");  // (bsdf/hair_lobe.h)
    if (settings_.integrator == "lt") check_light_tracing(scene);
    warnings_ = scene_->warnings();
    if (!media_note.empty()) warnings_.push_back(media_note);
    if (settings_.integrator == "lt" && scene.world_visible_camera && !scene.film_transparent) {
        for (const LightInput& l : scene.lights)
            if (l.of_world) {  // no light path reaches the camera from an infinite light
                warnings_.push_back("integrator 'lt' does not draw the world's sun disc (nor the "
                                    "world) for the camera; pt, bdpt, lvc and cis do");
                break;
            }
    }
    // "auto" takes the GPU when there is a usable one; "cuda" without one says why. Either way
    // the render goes on, on the CPU.
    if (test_gpu) {
        gpu_ = std::move(test_gpu);
        backend_name_ = "cuda";
        device_name_ = gpu_->device_name();
    } else if (want == "cuda" || want == "auto") {
        const CudaInfo info = cuda_info();
        // strands and motion blur: the device's ray query is accel/scene_query.h's, as the
        // built-in BVH's on the CPU (backend/cuda/cuda_exec.cuh); subsurface: every integrator's
        // walk stages are kernels within the stack cap (docs/cuda_backend.md "Subsurface walks
        // of bdpt, lvc, cis and lt"; compiled and measured, not yet run on a GPU)
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
    media_ = !media_reason(scene).empty();
    if (integ == "auto") {
        std::string why = pt_only_reason(scene);
        // motion blur: cis's pass holds one shutter time for all its samples, a noise its
        // one-sample trials do not measure (allocation.cpp pt_only_reason)
        if (why.empty() && settings_.spp_per_iteration > 1)
            if (std::string v = motion_reason(scene); !v.empty())
                why = v + " with more than one sample an iteration";
        // cis's walk stages and the bidirectional medium stages on a GPU: auto chooses there
        // once that GPU's self-check passed the feature's cases (skin/cis, fog/cis: the same
        // kernels; gpu_selfcheck.py, which python/lantern/session.py reads into gpu_checked
        // under backend "auto"); else (a forced "cuda", the check off or failed) pt
        const std::string unchecked = " on a GPU whose self-check has not passed its cases";
        if (why.empty() && gpu_ && scene_->view().has_subsurface &&
            !(settings_.gpu_checked & kGpuCheckedSubsurface))
            if (std::string v = subsurface_reason(scene); !v.empty()) why = v + unchecked;
        if (why.empty() && gpu_ && media_ && !(settings_.gpu_checked & kGpuCheckedMedia))
            why = "participating media" + unchecked;
        // (auto_media off: pt in media, docs/auto_integrator.md "Media")
        const bool media_off = why.empty() && media_ && !settings_.auto_media;
        alloc_ = std::make_unique<Allocation>(int64_t(scene.width) * scene.height,
                                              !why.empty() || media_off,
                                              settings_.candidates, !gpu_,
                                              !gpu_ && !settings_.auto_keep_pilot, scene.width);
        stats_.auto_choice = alloc_->choice();
        if (!why.empty())
            warnings_.push_back("integrator 'auto' renders this scene with path tracing: it has " +
                                why + ", which only pt renders");
        else if (media_off)
            warnings_.push_back("integrator 'auto' renders this scene with path tracing: its "
                                "choice in participating media is off (setting auto_media)");
    }
    width_ = scene.width;
    height_ = scene.height;
    const bool conn_alloc_on = settings_.connection_allocation > 0 ||
                               (settings_.connection_allocation < 0 && integ == "auto");
    // media: the medium stages (bdpt_medium_stages.h) neither scale a cache vertex's parts
    // that end on the light (dpt0, dpt1) nor normalise the camera side to a pixel's count, so
    // a per-pixel map's weights there are not the partition of unity pixel_conn.h proves
    if (conn_alloc_on && media_ && settings_.connection_allocation > 0)
        warnings_.push_back("connection_allocation is off in scenes with participating media: "
                            "the medium vertices' weights do not take a per-pixel count yet");
    if (conn_alloc_on && !media_ && settings_.adaptive_threshold <= 0.0f &&
        (integ == "lvc" || integ == "cis" || integ == "auto") && settings_.connection_map.empty() &&
        !scene.panoramic)
        conn_alloc_ = std::make_unique<ConnectionAllocation>(
            width_, height_, settings_.connections, settings_.candidates,
            ConnectionAllocation::zero_allowed(scene_->view()));
    {
        const std::string why = connection_map_error(settings_.connection_map, width_, height_,
                                                     scene.panoramic);
        if (!why.empty()) throw std::invalid_argument(why);
    }
    accum_.assign(size_t(width_) * height_ * 3, 0.0);
    film_.configure(settings_.adaptive_threshold, settings_.adaptive_min_samples,
                    settings_.adaptive_step);
    film_.reset(width_, height_);
    if (gpu_ && film_.on())
        warnings_.push_back("adaptive sampling per pixel runs on the CPU backend only; on the "
                            "GPU every pixel samples until the frame has converged");
    stats_.time_build = seconds_since(t0);
    publish();
}

Session::~Session() = default;

void Session::start_cpu_backend() {
    const std::vector<MeshRange>* instances =  // two levels: move_instance, moving meshes
        settings_.instancing || scene_->view().motion.num_objects > 0 ? &scene_->mesh_ranges()
                                                                      : nullptr;
    backend_ =
        std::make_unique<CpuBackend>(scene_->view(), settings_.threads, warnings_, instances);
    stats_.accel_bottom_builds = backend_->bottom_builds();
    exec_ = std::make_unique<CpuExec>(*backend_);
    wave_ = std::make_unique<Wavefront<CpuExec>>();
    wave_->bind(&exec_->meter());
    backend_name_ = "cpu";
    device_name_ = "cpu";
}

// A step on the GPU. When the GPU runs out of memory (or fails otherwise), the samples so far
// stay where they can be read back, the GPU is let go and this and later steps render on the
// CPU. A sticky CUDA error loses the GPU's samples: the render restarts on the CPU.
bool Session::step_cuda(Clock::time_point t0) {
    SessionSettings run = iteration_settings();
    // the connection allocation's map (pixel_alloc.h, the CPU's host code): the schedule uploads
    // it into the device's memory as on the CPU
    const bool conn_alloc = conn_alloc_ && (run.integrator == "lvc" || run.integrator == "cis");
    if (conn_alloc) run.connection_map = conn_alloc_->map();
    const SessionStats before = stats_;
    std::vector<double> prev;  // the running sum before the step, where "auto" or the
    int64_t prev_samples = 0;  // connection allocation wants the iteration's image
    try {
        if ((alloc_ && alloc_->wants_image()) || conn_alloc) prev = gpu_->accum(&prev_samples);
        if (!gpu_->step(run, iteration_counter(), stats_, cancel_, warnings_)) return false;
        std::vector<double> sum;
        if (!prev.empty()) {
            int64_t samples = 0;
            sum = gpu_->accum(&samples);
            for (size_t k = 0; k < sum.size() && k < prev.size(); ++k) sum[k] -= prev[k];
        }
        if (alloc_)
            observe(run, sum.empty() || !alloc_->wants_image() ? nullptr : sum.data(), before,
                    int64_t(width_) * height_);
        if (conn_alloc && sum.size() == accum_.size()) {
            conn_alloc_->observe(sum.data(), run.spp_per_iteration, before, stats_);
            stats_.mean_connections = conn_alloc_->mean_connections();
            stats_.connection_choices = conn_alloc_->choices();
        }
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
            film_.assume_uniform(spp_);
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

bool Session::trial_next() const {
    return alloc_ && alloc_->next_is_trial() && !gpu_ && !settings_.auto_keep_pilot;
}

// A pilot trial of "auto": one sample on the tracked pixels, measured, never added to the image.
bool Session::run_trial() {
    iteration_sum_.assign(accum_.size(), 0.0);
    const SessionSettings run = iteration_settings();
    const SessionStats before = stats_;
    uint64_t& counter = iteration_counter();
    WavefrontStep st(run, width_, height_, counter, iteration_sum_.data(), &stats_, &cancel_,
                     &warnings_);
    const std::vector<int32_t>& px = alloc_->tracked();
    if (int64_t(px.size()) < int64_t(width_) * height_) {
        st.pixel_list = px.data();
        st.pixel_count = int64_t(px.size());
    }
    st.chunk_paths = kChunkPaths;
    st.shadow_budget = kShadowBudget;
    st.cache_budget = CpuExec::cache_budget(settings_.cache_budget_mb);
    const bool ok = wf::run_iteration(*exec_, *wave_, scene_->view(), st);
    counter = st.iteration;
    if (ok) observe(run, iteration_sum_.data(), before, st.camera_pixels());
    return ok;
}

SessionSettings Session::iteration_settings() const {
    SessionSettings run = settings_;
    if (!alloc_) return run;
    run.integrator = alloc_->next();
    // the pilot draws numbers independent of every kept iteration's and of each other's (the
    // first samples of scrambles of their own: two samples of one QMC sequence are stratified
    // against each other, and their spread would read low)
    run.auto_moments = false;  // (a test's moment_channels: lvc, cis and bdpt alone)
    if (alloc_->piloting() || trial_next()) {
        // trials: pt's i-th and cis's i-th of one scramble (common random numbers,
        // allocation.h); whole iterations (kept in the image): each of its own
        const uint64_t k = trial_next() ? uint64_t(alloc_->trial_stream())
                                        : uint64_t(alloc_->pt_iterations() +
                                                   alloc_->cis_iterations() + 1);
        run.seed = settings_.seed ^ (0x9e3779b97f4a7c15ull * k);
        if (trial_next()) run.spp_per_iteration = 1;  // a trial: one sample a pixel
        // a cis trial also estimates pt's second moment (allocation.h): its sum holds moment
        // channels, not RGB (never added to the image)
        // (media: the medium stages make the channels at the shadow ray, where a queued
        // contribution's weight and transmittance are finished: bdpt_medium_finish_c)
        if (trial_next() && run.integrator == "cis") run.auto_moments = true;
        if (trial_next()) run.connection_map.clear();  // (trials: the counts the pilot weighs)
    }
    return run;
}

uint64_t& Session::iteration_counter() {
    if (!alloc_) return iteration_;
    if (alloc_->piloting() || trial_next()) return auto_iteration_[0] = 0;
    return auto_iteration_[1];
}

void Session::observe(const SessionSettings& run, const double* sum, const SessionStats& before,
                      int64_t pixels) {
    alloc_->observe(run.integrator.c_str(), sum, run.spp_per_iteration, pixels, before, stats_,
                    run.auto_moments);
    stats_.auto_choice = alloc_->choice();
    stats_.auto_cis_over_pt = alloc_->cis_over_pt();
    stats_.auto_pt_tail = alloc_->pt_tail();
    stats_.auto_pt_iterations = alloc_->pt_iterations();
    stats_.auto_cis_iterations = alloc_->cis_iterations();
    if (run.integrator == "cis")
        stats_.auto_cis_vertices += (stats_.rays_camera - before.rays_camera) +
                                    (stats_.rays_indirect - before.rays_indirect);
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

// A step on the CPU: the schedule (integrator/wavefront.h) on CpuExec, into iteration_sum_,
// which joins accum_ only if the step finishes.
bool Session::step_locked() {
    auto t0 = Clock::now();
    if (gpu_) return step_cuda(t0);
    if (spp_ == 0) {  // a new or restarted accumulation (session_update.cpp)
        std::lock_guard<std::mutex> lock(result_mutex_);
        film_.reset(width_, height_);
    }
    if (film_.converged()) return true;  // every pixel has converged: nothing left to add
    while (trial_next() && film_.all_active())
        if (!run_trial()) return false;
    iteration_sum_.assign(accum_.size(), 0.0);
    SessionSettings run = iteration_settings();
    const bool conn_alloc = conn_alloc_ && (run.integrator == "lvc" || run.integrator == "cis");
    if (conn_alloc) run.connection_map = conn_alloc_->map();  // (pixel_alloc.h)
    const SessionStats before = stats_;
    uint64_t& counter = iteration_counter();
    WavefrontStep st(run, width_, height_, counter, iteration_sum_.data(), &stats_, &cancel_,
                     &warnings_);
    st.pixel_list = film_.pixel_list();
    st.pixel_count = film_.active_count();
    st.chunk_paths = kChunkPaths;
    st.shadow_budget = kShadowBudget;
    st.cache_budget = CpuExec::cache_budget(settings_.cache_budget_mb);
    const uint64_t first_iteration = counter;  // the sampler's sample index: it x spp
    const bool ok = wf::run_iteration(*exec_, *wave_, scene_->view(), st);
    counter = st.iteration;
    if (!ok) return false;
    // the image of every pixel, before add() drops the converged pixels' splats
    if (alloc_)
        observe(run, film_.all_active() ? iteration_sum_.data() : nullptr, before,
                st.camera_pixels());
    if (conn_alloc) {
        conn_alloc_->observe(iteration_sum_.data(), run.spp_per_iteration, before, stats_);
        stats_.mean_connections = conn_alloc_->mean_connections();
        stats_.connection_choices = conn_alloc_->choices();
    }
    {
        std::lock_guard<std::mutex> lock(result_mutex_);
        // the active pixels only: a converged pixel's splats of this iteration are dropped
        // with its camera paths, so that each of its iterations is a whole estimate
        film_.add(iteration_sum_.data(), accum_, settings_.spp_per_iteration,
                  int64_t(first_iteration) * settings_.spp_per_iteration);
        spp_ += settings_.spp_per_iteration;
        film_.update(accum_, spp_);
    }
    ++stats_.iterations;
    stats_.time_total += seconds_since(t0);
    return true;
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
    const std::vector<int32_t>& count = film_.samples();
    if (!gpu_ && film_.on() && count.size() * 3 == sum.size()) {  // each pixel its own count
        for (size_t k = 0; k < sum.size() && k < img.size(); ++k)
            img[k] = count[k / 3] > 0 ? float(sum[k] / double(count[k / 3])) : 0.0f;
        return img;
    }
    const double inv = 1.0 / double(samples);
    for (size_t k = 0; k < sum.size() && k < img.size(); ++k) img[k] = float(sum[k] * inv);
    return img;
}

std::vector<int32_t> Session::pixel_samples() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    if (spp_ == 0) return std::vector<int32_t>(size_t(width_) * height_, 0);
    if (gpu_ || film_.samples().size() != size_t(width_) * height_)
        return std::vector<int32_t>(size_t(width_) * height_, int32_t(spp_));
    return film_.samples();
}

int64_t Session::active_pixels() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    return gpu_ ? int64_t(width_) * height_ : film_.active_count();
}

bool Session::converged() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    return !gpu_ && film_.converged();
}

double Session::noise_error() const {
    std::lock_guard<std::mutex> lock(result_mutex_);
    return film_.max_error();
}

}  // namespace lantern
