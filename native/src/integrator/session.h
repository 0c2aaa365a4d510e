// A progressive render: each step() runs one iteration of the wavefront over every pixel
// (spp_per_iteration paths each) in chunks of paths, then adds the chunk's pixels to the
// running sum. Cancel leaves the image at the last finished iteration.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "integrator/adaptive.h"
#include "integrator/allocation.h"
#include "integrator/pixel_alloc.h"
#include "integrator/bdpt.h"
#include "scene/scene.h"

namespace lantern {

class CpuBackend;
class CpuExec;
class CudaRenderer;
template <class Exec>
struct Wavefront;

// Integrator "lt" cannot render receiver-dependent lights (soft-falloff point/spot of radius > 0):
// throws std::invalid_argument naming the first one (docs/lvc_notes.md). lt_session.cpp.
void check_light_tracing(const SceneInput& in);

// SessionSettings::gpu_checked's bits: the GPU self-check's feature cases that passed
constexpr int kGpuCheckedSubsurface = 1, kGpuCheckedMedia = 2;

struct SessionSettings {
    // pt, lt, bdpt, lvc, cis, or auto: pt or cis per iteration (integrator/allocation.h)
    std::string integrator = "pt";
    std::string backend = "cpu";
    int spp_per_iteration = 1;
    int max_depth = 16;
    int rr_depth = 4;  // Russian roulette from this depth (path_state.h); 0: off
    uint64_t seed = 0;
    int threads = 0;
    // bidirectional integrators (bdpt, lvc, cis)
    int sort = -1;          // sort each bounce's hits by material type: 1 on, 0 off, -1 = cis only
    int connections = 5;    // N: cache vertices each camera vertex connects to (paper: 5)
    int candidates = 10;    // M: cis candidates (paper: 10)
    // lvc, cis: light paths per camera sample, L = round(f width height spp) (bdpt: 1 only);
    // 0: no light pass, so no light tracing and no connections: the camera pass alone, whose
    // weights are then path tracing's (bdpt.h)
    float light_path_fraction = 1.0f;
    std::string cis_target = "contribution";  // or "bsdf" (the paper's BSDF product)
    bool naive_ris = false; // test only: weight resampled picks like uniform ones (biased)
    bool soft_visibility = true;  // test only: false drops V(c, x) of soft lights (in media
                                  // F(c -> x) too; biased)
    int cache_budget_mb = 0;  // light vertex cache per pass; 0: min(4 GiB, RAM / 4)
    int light_candidates = 1;  // pt: resampled next-event estimation over M candidates (1: off)
    // per-pixel adaptive sampling (integrator/adaptive.h; CPU backend): Cycles' noise
    // threshold (0: off), the samples before the first check (0: Cycles' automatic minimum)
    // and the samples between checks
    float adaptive_threshold = 0.0f;
    int adaptive_min_samples = 0;
    int adaptive_step = 4;
    // two-level ray queries (a bottom level per mesh) so that move_instance() needs no build:
    // the viewport's; off, one flat structure (final renders)
    bool instancing = false;
    // integrator "auto": keep the pilot's iterations in the image, as the GPU does (tests)
    bool auto_keep_pilot = false;
    // integrator "auto" in homogeneous, non-emissive media: let its pt and cis trials choose
    // there (on by default since the medium stages make moment channels; off: auto = pt in
    // media, with a warning; docs/auto_integrator.md, "Media")
    bool auto_media = true;
    // (internal) integrator "auto" on a GPU: the features whose GPU self-check cases passed on
    // it (python/lantern/gpu_selfcheck.py; kGpuChecked*), so that auto may choose cis there in
    // scenes with them; 0 (a forced "cuda" backend, no self-check): pt in such scenes
    int gpu_checked = 0;
    // (internal) a cis trial of "auto": each pixel's sum holds the moment channels of
    // BdptSettings::moments (bdpt.h) instead of RGB; never set on a rendered iteration
    bool auto_moments = false;
    // lvc, cis: per pixel (N, M), 2 bytes, row-major (integrator/pixel_conn.h); empty: N and
    // M above everywhere. N in [0, 64], M in [1, 64] where N > 0; not on panoramic cameras.
    std::vector<uint8_t> connection_map;
    bool naive_map = false;  // test only: the map's counts under uniform-N weights (biased)
    // choose the connection map from the render's own iterations (integrator/pixel_alloc.h;
    // CPU and GPU, without adaptive sampling): 1 for lvc, cis and auto's kept cis iterations,
    // 0 off, -1 (the default) auto's kept cis iterations only (measured at least as efficient
    // there on every scene of bench/auto_efficiency.py; for cis and lvc themselves it was not:
    // bench/results/2026-12-04-auto6)
    int connection_allocation = -1;
};

// Why `map` cannot be a connection map of a width x height film (empty: it can).
std::string connection_map_error(const std::vector<uint8_t>& map, int width, int height,
                                 bool panoramic);

// The settings of one pass of a bidirectional iteration: mode (BdptMode), MIS count r
// (bdpt_session.cpp; the schedule's, integrator/schedule_bdpt.h, for every backend).
BdptSettings make_bdpt_settings(const SessionSettings& s, int width, int height,
                                uint64_t iteration, int mode, float r);
// Light paths L of a pass of s.spp_per_iteration samples (SessionSettings::light_path_fraction).
int64_t bdpt_light_paths(const SessionSettings& s, int width, int height);
// Samples per light pass, the cache's capacity and growth: integrator/wavefront_cache.h.

struct SessionStats {
    int64_t iterations = 0;
    int64_t rays_camera = 0, rays_indirect = 0, rays_shadow = 0;
    int64_t rays_light = 0, rays_connection = 0, rays_light_tracing = 0;
    int64_t nonfinite_dropped = 0;
    int64_t cache_vertices = 0;      // light vertex cache of the last iteration
    int64_t cache_memory_peak = 0;   // CPU: most bytes the cache and its bdpt index held at once
                                     // (a growth's old and new array together included)
    int64_t sorted_bounces = 0, unsorted_bounces = 0;
    double time_build = 0, time_generate = 0, time_trace = 0, time_shade = 0, time_shadow = 0,
           time_film = 0, time_total = 0;
    double time_light_pass = 0, time_camera_pass = 0, time_sort = 0, time_cache = 0,
           time_splat = 0;
    int64_t device_memory_peak = 0;  // CUDA: most device memory the renderer's buffers held
    int64_t device_memory_used = 0;  // CUDA: most of the device's memory in use by this
                                     // session (cudaMemGetInfo; with the kernels' local memory)
    // integrator "auto" (integrator/allocation.h): -1 another integrator, 0 piloting, 1 pt,
    // 2 cis; the estimated efficiency of cis over pt; the iterations each rendered
    int auto_choice = -1;
    double auto_cis_over_pt = 0.0;
    // pt's variance through the MIS identity from cis's trials over its own samples' spread
    // (allocation.cpp; 0: not estimated)
    double auto_pt_tail = 0.0;
    int64_t auto_pt_iterations = 0, auto_cis_iterations = 0;
    // camera vertices (camera and indirect rays) of auto's cis iterations, trials included:
    // each paid for M candidate evaluations (bench/auto_efficiency.py's work count)
    int64_t auto_cis_vertices = 0;
    // cis: candidates paid for, M of each camera vertex's pixel (a connection map's; else M)
    int64_t cis_candidates = 0;
    double mean_connections = -1.0;  // connection_allocation: mean N of the last map (-1: off)
    int connection_choices = 0;      // ... maps it has chosen (0: piloting)
    int64_t accel_bottom_builds = 0;  // CPU: bottom-level structures built (flat: 1)
    int64_t instance_moves = 0;       // move_instance() calls served
};

// Thread safety: step() calls are serialised (a second caller waits for the first); image(),
// spp(), stats() and warnings() may be called from any thread at any time and see the last
// finished step; cancel() from any thread stops the running step, or, when none runs, the next
// one: it stays set until a step has returned.
class Session {
public:
    Session(const SceneInput& scene, const SessionSettings& settings);
    // Tests: renders with `gpu` (a test double of the CUDA renderer) until it fails.
    Session(const SceneInput& scene, const SessionSettings& settings,
            std::unique_ptr<CudaRenderer> gpu);
    ~Session();

    // One iteration; returns false if it was cancelled (the image is unchanged then).
    bool step();
    void cancel() { cancel_.store(true); }
    // session_update.cpp: a new camera and film size (in's film and camera fields), sampling
    // restarted, nothing rebuilt; waits for a running step. False where the renderer keeps a
    // copy of the scene (the GPU): make a new Session. Call it from the thread that reads
    // image(), width() and height() (their shapes change).
    bool update_camera(const SceneInput& in);
    // session_update.cpp: in's materials and textures (HostScene::update_materials), sampling
    // restarted; false where the scene or renderer would need rebuilding.
    bool update_materials(const SceneInput& in);
    // session_update.cpp: mesh k (of the SceneInput's meshes) placed by to_world relative to
    // the positions it was given with: HostScene::move_mesh, the two-level accel's top level
    // rebuilt (no bottom level), sampling restarted. False, nothing changed, without
    // settings.instancing, on the GPU, or where HostScene::move_mesh refuses: a new Session.
    bool move_instance(int k, const Transform& to_world);
    // The connection map (SessionSettings::connection_map) of the next iterations, the image
    // kept (each iteration's map fixed, chosen before it: unbiased); throws
    // std::invalid_argument where connection_map_error says why not (CPU and GPU).
    bool set_connection_map(const std::vector<uint8_t>& map);
    // Mean radiance, top row first, 3 floats per pixel (each pixel over its own samples).
    std::vector<float> image() const;
    // The iterations' samples per pixel: what a pixel that never converged has.
    int64_t spp() const;
    // Adaptive sampling: each pixel's own samples (top row first), the pixels still sampling,
    // true once none is (further steps add nothing), the worst active pixel's error at the
    // last check (-1 before it).
    std::vector<int32_t> pixel_samples() const;
    int64_t active_pixels() const;
    bool converged() const;
    double noise_error() const;
    int width() const { return width_; }
    int height() const { return height_; }
    SessionStats stats() const;
    std::vector<std::string> warnings() const;
    // The backend that renders ("cpu" or "cuda": "auto" and a failed "cuda" resolve to one) and
    // its device ("cpu" or the GPU's name).
    const std::string& backend_name() const { return backend_name_; }
    const std::string& device_name() const { return device_name_; }

private:
    void init(const SceneInput& scene, std::unique_ptr<CudaRenderer> gpu);
    bool step_locked();
    void restart();  // session_update.cpp: accumulation from zero, as in a new session
    void publish();  // copies the stepping thread's stats and warnings for the readers
    void start_cpu_backend();
    bool step_cuda(std::chrono::steady_clock::time_point t0);
    // The settings of the next iteration: settings_, with "auto" resolved (allocation.h), and
    // its random-number streams' counter: iteration_, or under "auto" the pilot's (each of its
    // iterations with a seed of its own) apart from the render's, so that the render's
    // iterations are one unbroken run of the QMC sequence (its first 2^k samples well spread).
    SessionSettings iteration_settings() const;
    uint64_t& iteration_counter();
    void observe(const SessionSettings& run, const double* sum, const SessionStats& before,
                 int64_t pixels);
    bool trial_next() const;  // the next iteration is a pilot trial of "auto" (CPU)
    bool run_trial();         // ... which the image does not keep

    SessionSettings settings_;
    std::unique_ptr<HostScene> scene_;
    std::unique_ptr<CpuBackend> backend_;   // null while the GPU renders
    std::unique_ptr<CpuExec> exec_;         // on backend_: the schedule's executor
    std::unique_ptr<Wavefront<CpuExec>> wave_;  // the schedule's state (integrator/wavefront.h)
    std::unique_ptr<CudaRenderer> gpu_;
    std::unique_ptr<Allocation> alloc_;  // integrator "auto" only
    std::unique_ptr<ConnectionAllocation> conn_alloc_;  // connection_allocation only
    // the scene has participating media: "auto"'s cis trials carry no moment channels and no
    // connection map is chosen (docs/auto_integrator.md, "Media")
    bool media_ = false;
    uint64_t auto_iteration_[2] = {0, 0};  // its trials' streams and its kept iterations'
    std::string backend_name_ = "cpu", device_name_ = "cpu";
    std::vector<std::string> warnings_;
    int width_ = 0, height_ = 0;
    std::vector<double> accum_, iteration_sum_;
    AdaptiveFilm film_;  // per-pixel counts; on the CPU only (the GPU samples every pixel)
    int64_t spp_ = 0;
    uint64_t iteration_ = 0;
    std::atomic<bool> cancel_{false};
    SessionStats stats_;  // written by the stepping thread only
    std::mutex step_mutex_;            // one step at a time
    mutable std::mutex result_mutex_;  // accum_, spp_, gpu_'s lifetime, the published copies
    SessionStats published_stats_;
    std::vector<std::string> published_warnings_;
};

}  // namespace lantern
