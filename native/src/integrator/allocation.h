// Integrator "auto" (issue 27), host code every backend's session shares: per iteration it
// chooses path tracing (no light paths) or CIS-LBDPT from the running render's own estimates
// of each one's efficiency, 1 / (variance of an iteration x its cost).
//
// - A pilot runs pt four times, then cis; then the technique of higher estimated efficiency renders every
//   later iteration. Each iteration is a whole, unbiased estimate of the image and the film
//   averages iterations with equal weight per sample, so choosing later iterations from
//   earlier ones keeps the image unbiased (no weight depends on the samples it multiplies).
//   On the CPU the pilot's pt iterations are trials, measured and never added to the image
//   (a fixed rule, so still unbiased): where cis wins, pt's samples are many times noisier and
//   would weigh on the image (on the fixture, 36x cis's variance a sample); they cost four pt
//   iterations. The GPU keeps them (its renderer accumulates every step).
// - The estimates are noisy where pt's noise is heavy-tailed and the image small (32 x 32:
//   the fixture's estimate of cis over pt ranged 0.8 to 1e5 over 16 seeds, one below 1); a
//   re-probe later in the render would refine them (not done).
// - Variance: the sum over (at most kMaxTracked evenly spaced) pixels of the luminance's
//   per-iteration variance; pt's from its pilot trials' spread (each trial the first sample
//   of a scramble of its own, so independent), cis's from its pilot iteration against pt's
//   mean, less that mean's own variance.
// - Cost: a deterministic count, never a clock (same seed, same bits): rays traced plus
//   kCandidateCost per cis candidate evaluated (M per camera vertex), fitted to CPU time on
//   the Cornell box, the two-light room, the fixture and the glass lantern (0.23-0.49 of a ray;
//   bench/results/2026-12-04-auto/README.md).
// - Scenes with what only pt renders (holdouts, shadow catchers, the world hidden from some
//   rays) are rendered by pt alone.
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
    static constexpr double kCandidateCost = 0.36;  // one candidate evaluation, in rays

    // pixels: the film's; pt_only: the scene has what only pt renders (pt_only_reason).
    Allocation(int64_t pixels, bool pt_only, int candidates);

    // The integrator of the next iteration: "pt" or "cis".
    const char* next() const;
    // Whether the next iteration's image is wanted by observe() (the GPU reads it back only
    // then).
    bool wants_image() const;
    // Whether the next iteration is a pilot trial: measured, not added to the image (CPU).
    bool next_is_trial() const;
    // After an iteration of integrator `integ` (what next() said): its sum (3 doubles a
    // pixel, spp_it samples each, every pixel's) or null, and the stats before and after it.
    // Trials are of one sample a pixel (Session::iteration_settings).
    void observe(const char* integ, const double* sum, int spp_it, const SessionStats& before,
                 const SessionStats& after);

    // What it chose, for the stats: 0 while piloting, 1 pt, 2 cis; the estimated efficiency of
    // cis over pt (0 before it is known); iterations of each.
    int choice() const { return choice_; }
    double cis_over_pt() const { return ratio_; }
    int64_t pt_iterations() const { return n_[0]; }
    int64_t cis_iterations() const { return n_[1]; }

private:
    void decide();

    bool pt_only_;
    int candidates_;
    int64_t stride_ = 1;
    std::vector<double> sum_pt_, sum2_pt_, cis_;  // per tracked pixel (luminance)
    int64_t n_[2] = {0, 0};
    double cost_[2] = {0.0, 0.0};  // summed over each technique's iterations
    int choice_ = 0;
    int cis_spp_ = 1;  // samples per pixel of the pilot's cis iteration
    double ratio_ = 0.0;
};

// Why a scene must be rendered by pt alone under "auto" (empty: it need not).
std::string pt_only_reason(const SceneInput& in);

}  // namespace lantern
