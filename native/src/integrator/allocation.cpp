// Integrator "auto": the pilot, the estimates and the choice (allocation.h).
#include "integrator/allocation.h"

#include <algorithm>
#include <cmath>

#include "integrator/session.h"
#include "scene/scene.h"

namespace lantern {

namespace {

constexpr int kPilotPt = 4, kPilotCis = 1;

double luma(const double* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// Rays traced in an iteration, and the candidates cis evaluated (M per camera vertex: each
// camera or indirect ray's hit), in rays.
double iteration_cost(bool cis, int candidates, const SessionStats& a, const SessionStats& b) {
    const double rays = double(b.rays_camera - a.rays_camera) +
                        double(b.rays_indirect - a.rays_indirect) +
                        double(b.rays_shadow - a.rays_shadow) + double(b.rays_light - a.rays_light) +
                        double(b.rays_connection - a.rays_connection) +
                        double(b.rays_light_tracing - a.rays_light_tracing);
    if (!cis) return rays;
    const double vertices = double(b.rays_camera - a.rays_camera) +
                            double(b.rays_indirect - a.rays_indirect);
    return rays + Allocation::kCandidateCost * candidates * vertices;
}

}  // namespace

Allocation::Allocation(int64_t pixels, bool pt_only, int candidates)
    : pt_only_(pt_only), candidates_(candidates) {
    if (pt_only_) {
        choice_ = 1;
        return;
    }
    const int64_t want = std::min<int64_t>(pixels, std::max<int64_t>(4096, pixels / 8));
    stride_ = std::max<int64_t>(1, (pixels + std::min<int64_t>(want, kMaxTracked) - 1) /
                                       std::min<int64_t>(want, kMaxTracked));
    for (int64_t p = 0; p < pixels; p += stride_) tracked_.push_back(int32_t(p));
    sum_pt_.assign(tracked_.size(), 0.0);
    sum2_pt_.assign(tracked_.size(), 0.0);
    cis_.assign(tracked_.size(), 0.0);
}

const char* Allocation::next() const {
    if (choice_ == 1) return "pt";
    if (choice_ == 2) return "cis";
    return n_[0] < kPilotPt ? "pt" : "cis";
}

bool Allocation::wants_image() const { return choice_ == 0; }  // the GPU: the pilot only


void Allocation::observe(const char* integ, const double* sum, int spp_it,
                         const SessionStats& before, const SessionStats& after) {
    const bool cis = std::string(integ) == "cis";
    const int t = cis ? 1 : 0;
    // no image (adaptive sampling has stopped pixels): the pilot goes on without it
    if (choice_ == 0 && !sum) return;
    spp_it = std::max(spp_it, 1);
    cost_[t] += iteration_cost(cis, candidates_, before, after) / spp_it;  // per sample
    ++n_[t];
    // after choosing pt, its iterations of the pilot's sample count go on feeding the estimate
    const bool watching = choice_ == 1 && !cis && sum && spp_it == pt_spp_ && !cis_.empty();
    if (choice_ != 0 && !watching) return;
    if (choice_ == 0) (cis ? cis_spp_ : pt_spp_) = spp_it;
    const double inv = 1.0 / double(spp_it);
    for (size_t k = 0; k < cis_.size(); ++k) {
        const double v = luma(sum + 3 * int64_t(tracked_[k])) * inv;
        if (cis) {
            cis_[k] = v;
        } else {
            sum_pt_[k] += v;
            sum2_pt_[k] += v * v;
        }
    }
    if (!cis) ++pt_seen_;
    if (choice_ == 0) {
        if (pt_seen_ >= kPilotPt && n_[1] >= kPilotCis) decide();
        return;
    }
    // checkpoints at 8, 16, 32, ... of the render's pt iterations; watched up to kMaxWatched
    const int64_t kept = pt_seen_ - kPilotPt;
    if (kept >= 8 && (kept & (kept - 1)) == 0) decide();
    if (choice_ == 1 && kept >= kMaxWatched) release();
}

// Efficiency 1 / (V C): V the summed per-pixel variance of a sample, C its mean cost. pt's
// samples (its trials', then its render's) are of pt_spp_ samples a pixel each; the cis trial's
// mean over cis_spp_ samples has 1 / cis_spp_ of a sample's variance.
void Allocation::decide() {
    const double n = double(pt_seen_);
    double var_pt = 0.0, var_cis = 0.0;
    for (size_t k = 0; k < cis_.size(); ++k) {
        const double mean = sum_pt_[k] / n;
        const double v = std::max(0.0, (sum2_pt_[k] - sum_pt_[k] * mean) / (n - 1.0));
        var_pt += v;
        // one cis iteration against pt's mean: E[(x - m)^2] = var_cis + var_pt / n
        var_cis += (cis_[k] - mean) * (cis_[k] - mean) - v / n;
    }
    var_cis *= double(cis_spp_);
    var_pt *= double(pt_spp_);  // trials of one sample on the CPU, an iteration's on the GPU
    const double cost_pt = cost_[0] / double(n_[0]), cost_cis = cost_[1] / double(n_[1]);
    if (!(var_pt > 0.0) || !(cost_pt > 0.0) || !(cost_cis > 0.0)) {
        ratio_ = 0.0;  // nothing to gain (a noiseless image so far): the cheaper
        choice_ = cost_cis < cost_pt ? 2 : 1;
    } else {
        // an estimate at or below zero: cis's noise is below what pt's samples can resolve
        const double vc = std::max(var_cis, 1e-6 * var_pt);
        ratio_ = std::min((var_pt * cost_pt) / (vc * cost_cis), 1e6);
        choice_ = ratio_ > 1.0 ? 2 : 1;
    }
    if (choice_ == 2) release();
}

void Allocation::release() {
    std::vector<double>().swap(sum_pt_);
    std::vector<double>().swap(sum2_pt_);
    std::vector<double>().swap(cis_);
    std::vector<int32_t>().swap(tracked_);
}

std::string pt_only_reason(const SceneInput& in) {
    for (const MaterialInput& m : in.materials)
        if (m.holdout) return "a holdout (material '" + m.name + "')";
    for (const MeshInput& m : in.meshes)
        if (m.shadow_catcher) return "a shadow catcher (mesh '" + m.name + "')";
    if (in.catcher_mode != 0) return "a shadow catcher pass";
    if (in.world_rays != 7) return "the world hidden from some rays";
    return "";
}

}  // namespace lantern
