// Integrator "auto" (issue 27), host code every backend's session shares: it chooses path
// tracing (no light paths) or CIS-LBDPT from the render's own estimates of each one's
// efficiency, 1 / (variance of a sample x its cost).
//
// - A pilot of two pt trials and two cis trials of one sample a pixel, on the tracked pixels
//   only: an eighth of those whole iterations read (below), at least kMinTrackedTrials (512
//   of 64 x 64, 1,024 of 256 x 256), on a lattice whose rows are staggered. The cis trials'
//   light passes are the whole film's, as in a render (fewer light paths change cis's noise:
//   the glossy box read 0.8x pt with an eighth of them, 2.7x with all). pt's i-th and cis's
//   i-th trial draw from one Owen scramble of their own, independent of every kept
//   iteration's (common random numbers: the same camera rays, so noise both integrators
//   share, a light's edge seen by the camera, reads alike in both; unpaired, the few edge
//   pixels of a small set ruled the estimate: the 64 x 64 Cornell box chose cis on a third of
//   the seeds). An estimate within 1.25x of a tie takes one more pair first. On the CPU the
//   trials are never added to the image, a fixed rule, so the image is unbiased; the render
//   then starts as a fresh render of the chosen integrator (one unbroken run of its QMC
//   sequence).
// - The GPU (and `auto_keep_pilot`, for tests) keeps the pilot in the image: four pt and two
//   cis iterations of the full image, each of a scramble of its own, read on an eighth of the
//   image (at least kMinTracked pixels, at most kMaxTracked): each is an unbiased estimate,
//   weighted equally, and later choices depend on earlier iterations only, so that image is
//   unbiased too.
// - Noise: the luminance's per-sample standard deviation averaged over the tracked pixels
//   (the mean pixel's noise), squared. cis's from its samples' spread; pt's the larger of its
//   samples' spread and its second moment through the MIS identity from cis's trials, which
//   sees the heavy tail pt's own few samples miss (bdpt.h, bdpt_moment; estimate()).
// - Cost: a deterministic count, never a clock (same seed, same bits): rays traced plus
//   kCandidateCost per cis candidate evaluated (M per camera vertex), fitted to CPU time on
//   the Cornell box, the two-light room, the fixture and the glass lantern (0.23-0.49 of a
//   ray; docs/auto_integrator.md).
// - The render's own iterations go on feeding their integrator's estimate (CPU, iterations of
//   the pilot's sample count), and at its 8th, 16th, 32nd, ... iteration (up to kMaxWatched)
//   the choice is made again, after two more pt trials where cis renders: one pilot's
//   estimates are noisy (pt's noise is often heavy-tailed; on a 32 x 32 Cornell box 3 of 16
//   pilots put cis above pt, where it is 0.5x). Choices on earlier iterations only, equal
//   weights: the image stays unbiased.
// - Scenes with what only pt renders (holdouts, shadow catchers, the world hidden from some
//   rays, emissive media, a hair material on a mesh), what cis hands to pt
//   (bidir_visibility_reason) and the combinations auto's moment channels were not checked on
//   are rendered by pt alone (pt_only_reason; session.cpp adds motion blur with more than one
//   sample an iteration, and subsurface scattering and media on the GPU).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lantern {

struct SceneInput;
struct SessionStats;

class Allocation {
public:
    static constexpr int kMaxTracked = 1 << 16;    // pixels whose variance is tracked
    // ... at least (else an eighth of the image): fewer makes the pilot's choice unreliable on
    // small images (48 x 48 Cornell box: wrong in 0 of 8 seeds with all 2,304 pixels, 2 of 8
    // with 768, 3 of 8 with 461; bench/results/2026-12-04-auto3)
    static constexpr int kMinTracked = 4096;
    // ... where the pilot is of trials: an eighth as many, at least this many (a cis trial's
    // camera pass costs ~5 pt samples on every pixel; with two on 4,096 pixels the pilot cost
    // 16 pt samples of the 64 x 64 Cornell box's 64: bench/results/2026-12-04-auto4)
    static constexpr int kMinTrackedTrials = 512;
    static constexpr double kCandidateCost = 0.36;  // one candidate evaluation, in rays
    static constexpr int64_t kMaxWatched = 4096;    // iterations watched after the pilot
    static constexpr double kSwitchMargin = 1.3;    // a checkpoint switches past 1.3x or 1/1.3
    static constexpr double kMissedShare = 0.01;    // light pt cannot sample: past 1 %, cis

    // pixels: the film's; pt_only: the scene has what only pt renders (pt_only_reason);
    // watch: choose again at checkpoints (the CPU; the GPU chooses once, after its pilot);
    // trials: the pilot is of trials, never in the image (the CPU), else of whole iterations
    // kept in it (the GPU, auto_keep_pilot). width: the film's (0: unknown).
    Allocation(int64_t pixels, bool pt_only, int candidates, bool watch, bool trials = true,
               int64_t width = 0);
    int64_t pilot_index() const { return seen_[0] + seen_[1]; }  // the pilot's so far

    // The integrator of the next iteration: "pt" or "cis".
    const char* next() const;
    // Whether the next iteration's image is wanted by observe() (the GPU reads it back only
    // then).
    bool wants_image() const;
    // Whether the next iteration is the pilot's; whether it is a trial (the pilot's, or a pt
    // trial at a checkpoint while cis renders: on the CPU, never added to the image).
    bool piloting() const { return choice_ == 0; }
    bool next_is_trial() const;
    // The tracked pixels (indices into the film, row-major), in order; every pilot trial
    // renders these only.
    const std::vector<int32_t>& tracked() const { return tracked_; }
    // The Owen scramble of the next trial (1, 2, ...): pt's i-th and cis's i-th trials share one
    int64_t trial_stream() const;
    // After an iteration of integrator `integ` (what next() said): its sum (3 doubles a
    // pixel, spp_it samples each, every pixel's) or null, the pixels its camera pass covered,
    // and the stats before and after it. Trials are of one sample a pixel, on the tracked
    // pixels (Session::run_trial).
    // moments: a cis trial whose sum holds BdptSettings::moments's channels (bdpt.h): the
    // luminance, path tracing's second moment through the MIS identity, and the light pt
    // cannot sample, per pixel.
    void observe(const char* integ, const double* sum, int spp_it, int64_t pixels,
                 const SessionStats& before, const SessionStats& after, bool moments = false);

    // What it chose, for the stats: 0 while piloting, 1 pt, 2 cis; the estimated efficiency of
    // cis over pt (0 before it is known); iterations of each.
    int choice() const { return choice_; }
    double cis_over_pt() const { return ratio_; }
    // pt's variance through the MIS identity over its own samples' (0: not estimated)
    double pt_tail() const { return tail_; }
    int64_t pt_iterations() const { return n_[0]; }
    int64_t cis_iterations() const { return n_[1]; }

private:
    double estimate();  // cis's efficiency over pt's from the samples so far
    void decide();      // ... and the choice
    void release();  // the per-pixel sums, once no longer watched

    bool pt_only_, watch_;
    int candidates_;
    int64_t pixels_;  // the film's
    int64_t stride_ = 1;
    int pilot_pt_ = 4;   // the pilot's pt iterations (trials: 2, or 3 near a tie)
    int pilot_cis_ = 2;  // ... cis's (trials: 3 near a tie)
    bool trials_ = false;
    std::vector<int32_t> tracked_;
    std::vector<double> sum_pt_, sum2_pt_, sum_cis_, sum2_cis_;  // per tracked pixel (luma)
    // ... of cis's moment trials: pt's second moment, light pt misses, cis's values
    std::vector<double> sum_m2_, sum_miss_, sum_cm_, sum2_cm_;
    int64_t seen_m_ = 0;                     // cis trials in sum_m2_
    int64_t n_[2] = {0, 0};     // iterations of pt, cis (trials included)
    int64_t seen_[2] = {0, 0};  // ... in the sums
    int64_t kept_ = 0;          // the render's iterations (not trials)
    int trials_due_ = 0;        // pt trials asked for at a checkpoint under cis
    int cis_due_ = 0;           // a cis trial asked for at a checkpoint under pt
    double cost_[2] = {0.0, 0.0};  // summed over each technique's iterations
    int choice_ = 0;
    int cis_spp_ = 1, pt_spp_ = 1;  // samples per pixel of the pilot's iterations
    double ratio_ = 0.0;
    double tail_ = 0.0;
};

// Why a scene must be rendered by pt alone under "auto" (empty: it need not): a holdout, a
// shadow catcher (or its pass), the world hidden from some rays, an emissive medium, a hair
// material on a mesh; and where the scene has ray_visibility_reason's or
// no_shadow_object_reason's features, what bidir_visibility_reason(in, false) hands to pt,
// object or lamp ray visibility beside linking or Cast Shadow off, any of them beside media,
// strands or a hair material, or beside subsurface scattering (but light linking alone).
// Auto weighs the rest itself: linking, Cast Shadow off and ray visibility by kind on surfaces
// (docs/auto_integrator.md).
std::string pt_only_reason(const SceneInput& in);
// What of strands and hair only pt renders (docs/curves.md): a hair material on a mesh; ""
// when none.
std::string curves_bidir_reason(const SceneInput& in);
// What of strands lt cannot render besides (docs/curves.md): strands whose BSDF transmits
// (Translucent, Glass, Principled with Transmission; pt transmits through a strand from the side
// the camera sees, which lt reaches through the strand for Principled Hair in a mix only:
// lt_strand.h).
std::string curves_lt_reason(const SceneInput& in);
// The first of: an object (mesh or strands) or a lamp hidden from some ray kind (Diffuse, Glossy,
// Transmission, Volume Scatter), light or shadow linking, a lamp's Cast Shadow off; "" when the scene has
// none. pt renders them all; what the other integrators leave to pt is
// bidir_visibility_reason's, what auto leaves to pt pt_only_reason's.
std::string ray_visibility_reason(const SceneInput& in);
// An object (mesh or strands) whose Cast Shadow is off (bidir_no_shadow.h), or "".
std::string no_shadow_object_reason(const SceneInput& in);
// What of ray_visibility_reason's and no_shadow_object_reason's bdpt, lvc and cis (and, with
// light_tracer, lt) still hand to pt; "" when they render the scene themselves (bidir_linking.h,
// bidir_no_shadow.h, bidir_ray_visibility.h; lt: lt_linking.h, lt_ray_visibility.h;
// docs/lvc_notes.md "Linking"). Every integrator:
//   - object or lamp ray visibility by kind beside media or subsurface scattering;
//   - a volume's mesh that casts no shadow, in a scene with media.
// lt besides:
//   - ray visibility by kind on or beside strands, light or shadow linking, Cast Shadow off (a
//     lamp's, an object's), or a soft-falloff light where some object is hidden from a kind;
//   - a soft-falloff light with shadow linking or Cast Shadow off (its own, an object's);
//   - strands that cast no shadow; an object's or a lamp's Cast Shadow off with media;
//   - shadow linking beside a volume of a graph or grid.
std::string bidir_visibility_reason(const SceneInput& in, bool light_tracer);

}  // namespace lantern
