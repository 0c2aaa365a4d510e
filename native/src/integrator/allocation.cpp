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
    stride_ = std::max<int64_t>(1, (pixels + kMaxTracked - 1) / kMaxTracked);
    const size_t tracked = size_t((pixels + stride_ - 1) / stride_);
    sum_pt_.assign(tracked, 0.0);
    sum2_pt_.assign(tracked, 0.0);
    cis_.assign(tracked, 0.0);
}

const char* Allocation::next() const {
    if (choice_ == 1) return "pt";
    if (choice_ == 2) return "cis";
    return n_[0] < kPilotPt ? "pt" : "cis";
}

bool Allocation::wants_image() const { return choice_ == 0; }

bool Allocation::next_is_trial() const { return choice_ == 0 && n_[0] < kPilotPt; }

void Allocation::observe(const char* integ, const double* sum, int spp_it,
                         const SessionStats& before, const SessionStats& after) {
    const bool cis = std::string(integ) == "cis";
    const int t = cis ? 1 : 0;
    // no image (adaptive sampling has stopped pixels): the pilot goes on without it
    if (choice_ == 0 && !sum) return;
    spp_it = std::max(spp_it, 1);
    cost_[t] += iteration_cost(cis, candidates_, before, after) / spp_it;  // per sample
    ++n_[t];
    if (choice_ != 0) return;
    if (cis) cis_spp_ = spp_it;
    const double inv = 1.0 / double(spp_it);
    for (size_t k = 0; k < cis_.size(); ++k) {
        const double v = luma(sum + 3 * int64_t(k) * stride_) * inv;
        if (cis) {
            cis_[k] = v;
        } else {
            sum_pt_[k] += v;
            sum2_pt_[k] += v * v;
        }
    }
    if (n_[0] >= kPilotPt && n_[1] >= kPilotCis) decide();
}

// Efficiency 1 / (V C): V the summed per-pixel variance of a sample, C its mean cost. The trials
// are of one sample each; the cis iteration's mean over cis_spp_ samples has 1 / cis_spp_ of a
// sample's variance.
void Allocation::decide() {
    const double n = double(n_[0]);
    double var_pt = 0.0, var_cis = 0.0;
    for (size_t k = 0; k < cis_.size(); ++k) {
        const double mean = sum_pt_[k] / n;
        const double v = std::max(0.0, (sum2_pt_[k] - sum_pt_[k] * mean) / (n - 1.0));
        var_pt += v;
        // one cis iteration against pt's mean: E[(x - m)^2] = var_cis + var_pt / n
        var_cis += (cis_[k] - mean) * (cis_[k] - mean) - v / n;
    }
    var_cis *= double(cis_spp_);
    const double cost_pt = cost_[0] / n, cost_cis = cost_[1] / double(n_[1]);
    if (!(var_pt > 0.0) || !(cost_pt > 0.0) || !(cost_cis > 0.0)) {
        ratio_ = 0.0;  // nothing to gain (a noiseless image): the cheaper
        choice_ = cost_cis < cost_pt ? 2 : 1;
    } else {
        // an estimate at or below zero: cis's noise is below what pt's pilot can resolve
        const double vc = std::max(var_cis, 1e-6 * var_pt);
        ratio_ = std::min((var_pt * cost_pt) / (vc * cost_cis), 1e6);
        choice_ = ratio_ > 1.0 ? 2 : 1;
    }
    std::vector<double>().swap(sum_pt_);
    std::vector<double>().swap(sum2_pt_);
    std::vector<double>().swap(cis_);
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
