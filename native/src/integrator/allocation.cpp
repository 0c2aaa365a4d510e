// Integrator "auto": the pilot, the estimates and the choice (allocation.h).
#include "integrator/allocation.h"

#include <algorithm>
#include <cmath>

#include "integrator/session.h"
#include "scene/scene.h"

namespace lantern {

namespace {

constexpr int kPilotPt = 4, kPilotCis = 2;

double luma(const double* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// An iteration's cost per pixel sample, in rays: the camera side's work (camera, indirect,
// shadow and connection rays, and the candidates cis evaluates, M per camera vertex: each
// camera or indirect ray's hit) over the camera paths it traced, plus the light side's (light
// and light-tracing rays) over its light paths (one per pixel sample of the whole film, even
// where a trial's camera pass covers the tracked pixels only).
double sample_cost(bool cis, int candidates, const SessionStats& a, const SessionStats& b,
                   double camera_paths, double light_paths) {
    const double vertices = double(b.rays_camera - a.rays_camera) +
                            double(b.rays_indirect - a.rays_indirect);
    double camera = vertices + double(b.rays_shadow - a.rays_shadow) +
                    double(b.rays_connection - a.rays_connection);
    if (cis) camera += Allocation::kCandidateCost * candidates * vertices;
    const double light = double(b.rays_light - a.rays_light) +
                         double(b.rays_light_tracing - a.rays_light_tracing);
    return camera / std::max(camera_paths, 1.0) + light / std::max(light_paths, 1.0);
}

}  // namespace

Allocation::Allocation(int64_t pixels, bool pt_only, int candidates, bool watch)
    : pt_only_(pt_only), watch_(watch), candidates_(candidates), pixels_(pixels) {
    if (pt_only_) {
        choice_ = 1;
        return;
    }
    const int64_t want = std::min<int64_t>(pixels, std::max<int64_t>(4096, pixels / 8));
    stride_ = std::max<int64_t>(1, (pixels + std::min<int64_t>(want, kMaxTracked) - 1) /
                                       std::min<int64_t>(want, kMaxTracked));
    for (int64_t p = 0; p < pixels; p += stride_) tracked_.push_back(int32_t(p));
    for (std::vector<double>* v : {&sum_pt_, &sum2_pt_, &sum_cis_, &sum2_cis_})
        v->assign(tracked_.size(), 0.0);
    pilot_.assign(tracked_.size() * (kPilotPt + kPilotCis), 0.0f);
}

const char* Allocation::next() const {
    if (cis_due_ > 0) return "cis";
    if (trials_due_ > 0) return "pt";
    if (choice_ == 1) return "pt";
    if (choice_ == 2) return "cis";
    return seen_[0] < kPilotPt ? "pt" : "cis";
}

bool Allocation::next_is_trial() const {
    return choice_ == 0 || trials_due_ > 0 || cis_due_ > 0;
}

bool Allocation::wants_image() const { return choice_ == 0; }  // the GPU: the pilot only

void Allocation::observe(const char* integ, const double* sum, int spp_it, int64_t pixels,
                         const SessionStats& before, const SessionStats& after) {
    const bool cis = std::string(integ) == "cis";
    const int t = cis ? 1 : 0;
    const bool trial = next_is_trial();
    // no image (adaptive sampling has stopped pixels): the pilot goes on without it
    if (choice_ == 0 && !sum) return;
    spp_it = std::max(spp_it, 1);
    cost_[t] += sample_cost(cis, candidates_, before, after, double(pixels) * spp_it,
                            double(pixels_) * spp_it);
    ++n_[t];
    if (trial && choice_ != 0) --(cis ? cis_due_ : trials_due_);
    if (!trial) ++kept_;
    if (choice_ == 0) (cis ? cis_spp_ : pt_spp_) = spp_it;
    // every iteration of the pilot's sample count feeds its integrator's estimate while watched
    const bool feed = sum && !tracked_.empty() && spp_it == (cis ? cis_spp_ : pt_spp_);
    if (feed) {
        const double inv = 1.0 / double(spp_it);
        const int64_t slot = choice_ == 0 ? pilot_index() - 1 : -1;  // the pilot's
        std::vector<double>& s1 = cis ? sum_cis_ : sum_pt_;
        std::vector<double>& s2 = cis ? sum2_cis_ : sum2_pt_;
        for (size_t k = 0; k < tracked_.size(); ++k) {
            const double v = luma(sum + 3 * int64_t(tracked_[k])) * inv;
            if (slot >= 0 && slot < kPilotPt + kPilotCis)
                pilot_[k * (kPilotPt + kPilotCis) + size_t(slot)] = float(v);
            s1[k] += v;
            s2[k] += v * v;
        }
        ++seen_[t];
    }
    if (choice_ == 0) {
        if (seen_[0] >= kPilotPt && seen_[1] >= kPilotCis) decide();
        return;
    }
    if (tracked_.empty() || !watch_) return;
    // checkpoints at the render's 8th, 16th, 32nd, ... iteration. Under cis: two pt trials,
    // then the choice (cis's own iterations refine cis's estimate). Under pt, whose own
    // iterations refine pt's: where cis now looks better, one cis trial first (its estimate
    // would otherwise rest on the pilot's two samples; the two-light room flipped to cis and back
    // on them), then the choice
    if (!trial && kept_ >= 8 && (kept_ & (kept_ - 1)) == 0) {
        if (choice_ == 2) {
            trials_due_ = 2;
        } else {
            ratio_ = estimate();
            if (ratio_ > 1.0) cis_due_ = 1;
        }
    } else if (trial && trials_due_ == 0 && cis_due_ == 0) {
        decide();
    }
    if (kept_ >= kMaxWatched && trials_due_ == 0 && cis_due_ == 0) release();
}

// Efficiency 1 / (V C): V the summed weighted per-pixel variance of a sample, C its mean cost.
// Each integrator's samples are of its pilot's sample count a pixel (pt_spp_, cis_spp_), and
// each integrator's variance is its own samples' spread: not cis's spread about pt's mean,
// which holds pt's error too, and where pt's noise is heavy-tailed the trials miss that error
// (a pixel whose four pt trials all missed the light through the glass reads cis's whole value
// as cis's deviation). The render's iterations are one QMC run, stratified against each other:
// their spread reads each sample's variance a little high, not low.
double Allocation::estimate() {
    // the pilot's medians weigh the pixels for good: a mean of the samples so far would let a
    // pixel's own firefly weigh its noise away (the fixture then went to pt, 0 of 16 seeds)
    if (weight_.empty()) weigh();
    const double n = double(seen_[0]), nc = double(seen_[1]);
    double var_pt = 0.0, var_cis = 0.0;
    for (size_t k = 0; k < tracked_.size(); ++k) {
        const double mean = sum_pt_[k] / n, mean_c = sum_cis_[k] / nc;
        var_pt += weight_[k] * std::max(0.0, (sum2_pt_[k] - sum_pt_[k] * mean) / (n - 1.0));
        var_cis +=
            weight_[k] * std::max(0.0, (sum2_cis_[k] - sum_cis_[k] * mean_c) / (nc - 1.0));
    }
    var_cis *= double(cis_spp_);
    var_pt *= double(pt_spp_);  // trials of one sample on the CPU, an iteration's on the GPU
    const double cost_pt = cost_[0] / double(n_[0]), cost_cis = cost_[1] / double(n_[1]);
    // nothing to gain (a noiseless image so far): the cheaper per sample
    if (!(var_pt > 0.0) || !(cost_pt > 0.0) || !(cost_cis > 0.0))
        return cost_cis < cost_pt ? 1e6 : 0.0;
    // no spread in cis's samples at all: as good as it gets
    const double vc = std::max(var_cis, 1e-6 * var_pt);
    return std::min((var_pt * cost_pt) / (vc * cost_cis), 1e6);
}

void Allocation::decide() {
    ratio_ = estimate();
    {
        // past the pilot a switch needs a margin: near 1 the estimates flip from checkpoint to
        // checkpoint (the glossy box: 0.3-1.4), and each flip costs a cis iteration or trials
        const double margin = choice_ == 0 ? 1.0 : kSwitchMargin;
        if (choice_ != 2 && ratio_ > margin) choice_ = 2;
        else if (choice_ != 1 && ratio_ < 1.0 / margin) choice_ = 1;
        if (choice_ == 0) choice_ = 1;  // exactly 1 (or NaN): the cheaper per sample
    }
}

// Each pixel's variance relative to its value: weight 1 / (median^2 + floor^2), the median of
// its five pilot samples (robust to the one firefly a pt trial may hold, which would hide that
// pixel's noise behind its own mean), the floor 5 % of the image's mean median, so dark pixels'
// noise counts without dividing by zero. Relative, not absolute: summed absolute variances are
// ruled by a few bright pixels (a light seen through glass) that every integrator renders
// alike, and miss where cis helps (the glass lantern: cis 18x pt by the mean pixel's noise,
// 1.25x by the root mean square).
void Allocation::weigh() {
    constexpr int kSamples = kPilotPt + kPilotCis;
    const size_t n = tracked_.size();
    std::vector<double> med(n);
    double mean = 0.0;
    for (size_t k = 0; k < n; ++k) {
        float v[kSamples];
        std::copy(pilot_.begin() + k * kSamples, pilot_.begin() + (k + 1) * kSamples, v);
        std::nth_element(v, v + kSamples / 2, v + kSamples);
        med[k] = std::fabs(double(v[kSamples / 2]));
        mean += med[k];
    }
    mean = n ? mean / double(n) : 0.0;
    const double floor2 = mean > 0.0 ? 0.0025 * mean * mean : 1.0;
    weight_.resize(n);
    for (size_t k = 0; k < n; ++k) weight_[k] = 1.0 / (med[k] * med[k] + floor2);
    std::vector<float>().swap(pilot_);
}

void Allocation::release() {
    for (std::vector<double>* v : {&sum_pt_, &sum2_pt_, &sum_cis_, &sum2_cis_})
        std::vector<double>().swap(*v);
    std::vector<double>().swap(weight_);
    std::vector<float>().swap(pilot_);
    std::vector<int32_t>().swap(tracked_);
}

std::string pt_only_reason(const SceneInput& in) {
    for (const MaterialInput& m : in.materials)
        if (m.holdout) return "a holdout (material '" + m.name + "')";
    for (const MeshInput& m : in.meshes)
        if (m.shadow_catcher) return "a shadow catcher (mesh '" + m.name + "')";
    if (in.catcher_mode != 0) return "a shadow catcher pass";
    if (in.world_rays != 7) return "the world hidden from some rays";
    if (std::string v = media_reason(in); !v.empty()) return v;  // media: pt only (volumes.md)
    return "";
}

}  // namespace lantern
