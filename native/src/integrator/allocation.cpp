// Integrator "auto": the pilot, the estimates and the choice (allocation.h).
#include "integrator/allocation.h"

#include <algorithm>
#include <cmath>

#include "integrator/session.h"
#include "scene/scene.h"
#include "scene/subsurface_input.h"

namespace lantern {

namespace {

// the pilot's cis iterations, and its pt trials (whole iterations: pilot_pt_ = 4). Two pt trials
// suffice: paired with cis's, they chose right on 32 of 32 seeds of the 64 x 64 Cornell box
// (bench/results/2026-12-04-auto4)
constexpr int kPilotCis = 2, kPilotPtTrials = 2;
// trials: a pilot whose estimate lands within this factor of a tie takes one more pair of trials
// before it chooses (once): on 32 seeds of the 64 x 64 Principled box (cis 3.6x pt by work)
// the lowest estimate was 1.01, the Cornell box's (0.66x) highest 0.75
constexpr double kTieBand = 1.25;

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

Allocation::Allocation(int64_t pixels, bool pt_only, int candidates, bool watch, bool trials,
                       int64_t width)
    : pt_only_(pt_only), watch_(watch), candidates_(candidates), pixels_(pixels) {
    if (pt_only_) {
        choice_ = 1;
        return;
    }
    int64_t want = std::min<int64_t>(pixels, std::max<int64_t>(kMinTracked, pixels / 8));
    want = std::min<int64_t>(want, kMaxTracked);
    if (trials) {
        want = std::min<int64_t>(pixels, std::max<int64_t>(kMinTrackedTrials, want / 8));
        pilot_pt_ = kPilotPtTrials;
        trials_ = true;
    }
    stride_ = std::max<int64_t>(1, pixels / want);
    // evenly spaced; each image row's picks move on by 3 pixels (mod the stride), so that a
    // stride dividing the width picks no fixed columns
    for (int64_t k = 0; k * stride_ < pixels; ++k) {
        const int64_t base = k * stride_;
        const int64_t row = width > 0 ? base / width : 0;
        const int64_t p = base + (3 * row) % stride_;
        tracked_.push_back(int32_t(std::min<int64_t>(p, pixels - 1)));
    }
    for (std::vector<double>* v : {&sum_pt_, &sum2_pt_, &sum_cis_, &sum2_cis_, &sum_m2_,
                                   &sum_miss_, &sum_cm_, &sum2_cm_})
        v->assign(tracked_.size(), 0.0);
}

const char* Allocation::next() const {
    if (cis_due_ > 0) return "cis";
    if (trials_due_ > 0) return "pt";
    if (choice_ == 1) return "pt";
    if (choice_ == 2) return "cis";
    return seen_[0] < pilot_pt_ ? "pt" : "cis";  // (an extended pilot: pt's, then cis's)
}

int64_t Allocation::trial_stream() const {
    return (std::string(next()) == "cis" ? n_[1] : n_[0]) + 1;
}

bool Allocation::next_is_trial() const {
    return choice_ == 0 || trials_due_ > 0 || cis_due_ > 0;
}

bool Allocation::wants_image() const { return choice_ == 0; }  // the GPU: the pilot only

void Allocation::observe(const char* integ, const double* sum, int spp_it, int64_t pixels,
                         const SessionStats& before, const SessionStats& after, bool moments) {
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
        std::vector<double>& s1 = cis ? sum_cis_ : sum_pt_;
        std::vector<double>& s2 = cis ? sum2_cis_ : sum2_pt_;
        moments = moments && cis;
        for (size_t k = 0; k < tracked_.size(); ++k) {
            const double* px = sum + 3 * int64_t(tracked_[k]);
            const double v = (moments ? px[0] : luma(px)) * inv;
            if (moments) {
                sum_cm_[k] += v;
                sum2_cm_[k] += v * v;
                sum_m2_[k] += px[1] * inv;
                sum_miss_[k] += px[2] * inv;
            }
            s1[k] += v;
            s2[k] += v * v;
        }
        ++seen_[t];
        if (moments) ++seen_m_;
    }
    if (choice_ == 0) {
        if (seen_[0] >= pilot_pt_ && seen_[1] >= pilot_cis_) {
            const double r = estimate();
            if (trials_ && pilot_cis_ == kPilotCis && r > 1.0 / kTieBand && r < kTieBand) {
                ++pilot_pt_;  // near a tie: one more pt and cis trial (one scramble), then choose
                ++pilot_cis_;
                ratio_ = r;
            } else {
                decide();
            }
        }
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

// Efficiency 1 / (S^2 C): S the summed standard deviation of a sample over the tracked pixels
// (the mean pixel's noise, as bench/auto_efficiency.py measures it), C its mean cost. Summed
// standard deviations, not variances: a few pixels' spikes (a firefly, a light seen through
// glass that both render alike) rule a sum of variances, and its pilot estimate with them.
// Each integrator's samples are of its pilot's sample count a pixel (pt_spp_, cis_spp_).
// - cis: its samples' spread. pt: the larger of its samples' spread and its second moment
//   through the MIS identity from cis's trials (bdpt.h, bdpt_moment). pt's own samples miss
//   the rare paths of a heavy tail (the glass lantern, the fixture: light reaching the room
//   through glass or a shade; its few samples read low-variance); the identity misses the
//   covariance of a path's terms (its vertices' next-event samples and emission hits at once).
// - Each sum of per-pixel standard deviations from m samples reads low by c4(m) (normal
//   samples) and by more where the noise is heavy-tailed; the identity's sum and cis's from
//   the same trials read low alike, so pt's identity estimate is cis's whole estimate times
//   their ratio (cis's own iterations refine cis's estimate; the identity has the trials only).
// - Every choice depends on earlier iterations only (the image stays unbiased).
double Allocation::estimate() {
    const double n = double(seen_[0]), nc = double(seen_[1]), nm = double(seen_m_);
    auto sd = [](double s1, double s2, double m) {
        return m > 1.0 ? std::sqrt(std::max(0.0, (s2 - s1 * s1 / m) / (m - 1.0))) : 0.0;
    };
    double sd_pt = 0.0, sd_cis = 0.0, sd_cis_m = 0.0, sd_id = 0.0, missed = 0.0, light = 0.0;
    for (size_t k = 0; k < tracked_.size(); ++k) {
        sd_pt += sd(sum_pt_[k], sum2_pt_[k], n);
        sd_cis += sd(sum_cis_[k], sum2_cis_[k], nc);
        if (nm > 0.0) {  // pt's second moment from cis's trials, less their mean's square
            const double mean = sum_cm_[k] / nm;
            sd_id += std::sqrt(std::max(0.0, sum_m2_[k] / nm - mean * mean));
            sd_cis_m += sd(sum_cm_[k], sum2_cm_[k], nm);
            missed += sum_miss_[k] / nm;
            light += std::fabs(mean);
        }
    }
    auto c4 = [](double m) {
        return m < 2.0 ? 1.0
                       : std::sqrt(2.0 / (m - 1.0)) *
                             std::exp(std::lgamma(m / 2.0) - std::lgamma((m - 1.0) / 2.0));
    };
    sd_pt /= c4(n);
    sd_cis /= c4(nc);
    // trials of one sample on the CPU, an iteration's on the GPU (no moment trials there)
    double var_pt = sd_pt * sd_pt * double(pt_spp_), var_cis = sd_cis * sd_cis * double(cis_spp_);
    tail_ = 0.0;
    if (nm > 1.0 && sd_cis_m > 0.0) {
        const double id = sd_id / sd_cis_m * sd_cis;
        const double var_id = id * id * double(cis_spp_);
        tail_ = var_pt > 0.0 ? var_id / var_pt : 0.0;
        var_pt = std::max(var_pt, var_id);
    }
    // light that pt cannot sample at all (a + b = 0 in bdpt_moment: a caustic of a point light
    // through glass): pt's image lacks it, an error no sample count cures
    if (light > 0.0 && missed > kMissedShare * light) return 1e6;
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

void Allocation::release() {
    for (std::vector<double>* v : {&sum_pt_, &sum2_pt_, &sum_cis_, &sum2_cis_, &sum_m2_,
                                   &sum_miss_, &sum_cm_, &sum2_cm_})
        std::vector<double>().swap(*v);
    std::vector<int32_t>().swap(tracked_);
}

std::string ray_visibility_reason(const SceneInput& in) {
    for (const MeshInput& m : in.meshes)  // integrator/pt_ray_visibility.h
        if ((m.rays & kRayKindsAll) != kRayKindsAll)
            return "an object hidden from diffuse, glossy, transmission or volume rays (mesh '" +
                   m.name + "')";
    for (const CurveInput& c : in.curves)  // strands: their object's flags (pt_pass_hidden_strand)
        if ((c.rays & kRayKindsAll) != kRayKindsAll)
            return "strands hidden from diffuse, glossy, transmission or volume rays (curves '" +
                   c.name + "')";
    for (const MeshInput& m : in.meshes)  // light linking: integrator/pt_light_linking.h
        if (m.light_set != 0 || m.emitter_receivers != kAllReceivers || m.shadow_set != 0 ||
            m.emitter_blockers != kAllReceivers)
            return "light or shadow linking (mesh '" + m.name + "')";
    for (const LightInput& l : in.lights)  // a lamp's own ray visibility
        if ((l.rays & kRayKindsAll) != kRayKindsAll)
            return "a light hidden from diffuse, glossy, transmission or volume rays (light '" +
                   l.name + "')";
    for (const LightInput& l : in.lights)
        if (l.receivers != kAllReceivers || l.blockers != kAllReceivers)
            return "light or shadow linking (light '" + l.name + "')";
    for (const LightInput& l : in.lights)  // Cast Shadow off: pt_ray_visibility.h
        if (!l.cast_shadow) return "a light that casts no shadow (light '" + l.name + "')";
    return "";
}

std::string no_shadow_object_reason(const SceneInput& in) {
    for (const MeshInput& m : in.meshes)
        if (!m.cast_shadow) return "an object that casts no shadow (mesh '" + m.name + "')";
    for (const CurveInput& c : in.curves)
        if (!c.cast_shadow) return "an object that casts no shadow (curves '" + c.name + "')";
    return "";
}

namespace {
// lt: a soft-falloff light whose light paths would walk past surfaces that cast it no shadow
// (lt_linking.h; its lines start off the light, soft_light_path.h): not done
std::string lt_soft_walk_reason(const SceneInput& in) {
    const bool no_shadow = !no_shadow_object_reason(in).empty();
    for (const LightInput& l : in.lights)
        if ((l.type == "point" || l.type == "spot") && l.soft_falloff && l.radius > 0.0f &&
            (no_shadow || !l.cast_shadow || l.blockers != kAllReceivers))
            return "a soft-falloff light with shadow linking or Cast Shadow off (light '" +
                   l.name + "')";
    return "";
}

// Whether the scene has light or shadow linking, or a lamp's or an object's Cast Shadow off:
// the rules ray visibility by kind was checked beside only one at a time (media, auto).
bool linking_or_no_shadow(const SceneInput& in) {
    for (const MeshInput& m : in.meshes)
        if (m.light_set != 0 || m.emitter_receivers != kAllReceivers || m.shadow_set != 0 ||
            m.emitter_blockers != kAllReceivers)
            return true;
    for (const LightInput& l : in.lights)
        if (l.receivers != kAllReceivers || l.blockers != kAllReceivers || !l.cast_shadow)
            return true;
    return !no_shadow_object_reason(in).empty();
}

// World > Ray Visibility hiding the world from a kind of scattering the scene has (Volume
// Scatter: only with media): pt's rule alone (pt.h pt_world_sees, pt_volume.h); "" when none
std::string world_rays_reason(const SceneInput& in) {
    static const char* const kNames[] = {"diffuse", "glossy", "transmission", "volume scatter"};
    std::string off;
    for (int k = 0; k < 4; ++k)
        if (!(in.world_rays & (1u << k)) && (k < 3 || !media_reason(in).empty()))
            off += (off.empty() ? "" : ", ") + std::string(kNames[k]);
    return off.empty() ? off : "the world hidden from " + off + " rays";
}
}  // namespace

std::string bidir_visibility_reason(const SceneInput& in, bool light_tracer) {
    // World > Ray Visibility: pt's alone so far (docs/lvc_notes.md "The world's ray visibility")
    if (std::string v = world_rays_reason(in); !v.empty()) return v;
    // an object's Cast Shadow off: bdpt, lvc and cis (bidir_no_shadow.h) on meshes and strands
    // (their shadow query passes a non-casting strand as a triangle), with subsurface
    // scattering too (a walk's exit is a surface vertex, bdpt_sss.h), beside shadow linking,
    // beside media, both at once (a shadow-linked light's next event is its only technique:
    // the ratio is 1), shadow linking with subsurface scattering, a volume's mesh in media (its
    // shadow rays cross other media than its BSDF rays: bidir_no_shadow_medium.h).
    // lt too (lt_linking.h, shadow linking and subsurface scattering beside it there), not
    // with media or strands
    if (light_tracer)
        if (std::string v = lt_soft_walk_reason(in); !v.empty()) return v;
    if (const std::string v = no_shadow_object_reason(in); !v.empty()) {
        if (light_tracer)
            for (const CurveInput& c : in.curves)
                if (!c.cast_shadow) return v;
        if (std::string u = media_reason(in); !u.empty()) {
            if (light_tracer) return v + " with " + u;
            // a volume's mesh that casts no shadow: s = 1 traces both queries
            // (bidir_no_shadow_medium.h); not beside a soft-falloff light, whose light paths'
            // first segment takes the shadow query (soft_light_medium.h), nor a surface with a
            // volume inside (untested)
            for (const MeshInput& m : in.meshes)
                for (uint32_t k : m.material_ids)
                    if (!m.cast_shadow && k < in.materials.size() &&
                        in.materials[k].medium >= 0 && !in.materials[k].volume_only)
                        return "a surface with a volume that casts no shadow (mesh '" + m.name +
                               "')";
                    else if (!m.cast_shadow && k < in.materials.size() &&
                             in.materials[k].volume_only)
                        for (const LightInput& l : in.lights)
                            if ((l.type == "point" || l.type == "spot") && l.soft_falloff &&
                                l.radius > 0.0f)
                                return "a volume's mesh that casts no shadow (mesh '" + m.name +
                                       "') with a soft-falloff light (light '" + l.name + "')";
        }
    }
    const std::string all = ray_visibility_reason(in);
    if (all.empty()) return all;
    // strands hidden from some kind (their object's flags): bdpt, lvc and cis as a mesh's
    // (a passed strand: pt_pass_hidden_strand); lt's walk takes every strand as seen, pt's
    bool strands_hidden = false;
    for (const CurveInput& c : in.curves)
        if ((c.rays & kRayKindsAll) != kRayKindsAll) {
            if (light_tracer)
                return "lt's strands hidden from diffuse, glossy, transmission or volume rays "
                       "(curves '" + c.name + "')";
            strands_hidden = true;
        }
    // integrator/bidir_linking.h: light linking, shadow linking and a lamp's Cast Shadow off
    // (lt: lt_linking.h), on surfaces; light and shadow linking in media too (lt: shadow
    // linking in homogeneous media, lt_medium.h lt_walk_ratio); past a subsurface walk's exit
    // too (bdpt, lvc, cis: the exit receives as its own surface, bdpt_sss.h; lt: y1 = x_o,
    // lt_linking.h lt_sss_nee_weight)
    bool shadow = false, unshadowed = false, other = strands_hidden;
    for (const MeshInput& m : in.meshes) {
        if ((m.rays & kRayKindsAll) != kRayKindsAll) other = true;
        if (m.shadow_set != 0 || m.emitter_blockers != kAllReceivers) shadow = true;
    }
    for (const LightInput& l : in.lights) {
        if ((l.rays & kRayKindsAll) != kRayKindsAll) other = true;
        if (l.blockers != kAllReceivers) shadow = true;
        if (!l.cast_shadow) unshadowed = true;
    }
    // object and lamp ray visibility by kind: bdpt, lvc and cis on surfaces
    // (bidir_ray_visibility.h), beside light and shadow linking and a lamp's or an object's
    // Cast Shadow off too (a restricted path is pt's, an unrestricted one keeps the linking
    // rules: docs/lvc_notes.md "Ray visibility by kind"); lt on surfaces too
    // (lt_ray_visibility.h), beside linking and Cast Shadow off too (its first segment's one
    // walk, lt_rays_step), not with strands (their vertices' kinds unchecked), nor a
    // soft-falloff light beside an object hidden from some kind (its lines' first segment
    // cannot walk); past subsurface walks too (lt_rays_sss_weight). Beside media (world fog,
    // mesh volumes, homogeneous or heterogeneous): bdpt, lvc and cis (bidir_ray_visibility.h,
    // bdpt_medium_stages.h), beside linking and Cast Shadow off there too and beside
    // subsurface walks (medmix: the rules compose as on surfaces,
    // test_ray_visibility_media_linking.py, test_ray_visibility_media_sss.py); lt beside media
    // alone (lt_medium.h), not with linking or Cast Shadow off there nor with walks too
    if (other) {
        const std::string rays = "object or lamp ray visibility";
        if (light_tracer) {
            const std::string lt_rays = "lt's " + rays;
            for (const CurveInput& c : in.curves)
                if (c.offsets.size() > 1)
                    return lt_rays + " with strands (curves '" + c.name + "')";
            bool hidden_mesh = false;
            for (const MeshInput& m : in.meshes)
                hidden_mesh |= (m.rays & kRayKindsAll) != kRayKindsAll;
            for (const LightInput& l : in.lights)
                if (hidden_mesh && (l.type == "point" || l.type == "spot") && l.soft_falloff &&
                    l.radius > 0.0f)
                    return lt_rays + " with a soft-falloff light (light '" + l.name + "')";
            // pt's kinds by closure (branch closure, pt_ray_visibility.h): a Mix's ray takes the
            // sampled leaf's kind, next event leaves out the leaves whose class the light
            // hides; a Translucent BSDF is of the diffuse class for next event, its bounce rays
            // of the path kind (diffuse and transmission for a lamp, transmission for an
            // object). lt's one kind per material (lt_ray_visibility.h) is not that: those
            // stay pt's
            auto split = [&](uint8_t rays, bool lamp, const std::string& what) -> std::string {
                const bool diffuse = rays & kRayDiffuse, trans = rays & kRayTransmission;
                for (const MaterialInput& m : in.materials)
                    if (m.type == "translucent" && (lamp ? diffuse && !trans : diffuse != trans))
                        return lt_rays + " with " + what + " hidden from " +
                               (trans ? "Diffuse" : "Transmission") +
                               " alone beside a Translucent BSDF (material '" + m.name + "')";
                return "";
            };
            for (const MaterialInput& m : in.materials)
                if (m.type == "mix")
                    return lt_rays + " with a Mix Shader (material '" + m.name + "')";
            for (const LightInput& l : in.lights)
                if (std::string v = split(l.rays, true, "light '" + l.name + "'"); !v.empty())
                    return v;
            for (const MeshInput& m : in.meshes) {
                bool emits = false;  // (its own material; a mix handed over above)
                for (uint32_t k : m.material_ids)
                    emits |= k < in.materials.size() &&
                             (max_component(in.materials[k].emission) > 0.0f ||
                              in.materials[k].tex_emission >= 0 ||
                              in.materials[k].program_count > 0);
                if (std::string v = split(m.rays, false, "mesh '" + m.name + "'");
                    emits && !v.empty())
                    return v;
            }
        }
        if (std::string v = media_reason(in); !v.empty()) {
            // (media and subsurface walks together in bdpt, lvc, cis: the walk's exit is a
            // camera vertex whose next event, continuation and restriction run the media code
            // as any; medmix, test_ray_visibility_media_sss.py. lt: its medium vertices'
            // phase scattering of kind Volume Scatter, lt_ray_visibility.h
            // lt_rays_medium_weight, checked alone)
            if (light_tracer && linking_or_no_shadow(in))
                return rays + " with linking or Cast Shadow off beside " + v;
            if (std::string u = subsurface_reason(in); !u.empty() && light_tracer)
                return rays + " with " + v + " and " + u;
        }
        // (subsurface walks: bdpt, lvc and cis render them, the walk no segment of its own and
        // the exits' rays a diffuse bounce's, bdpt_sss.h; lt too, its walk from x_o pt's exit's
        // diffuse scattering, lt_ray_visibility.h lt_rays_sss_weight)
    }
    // light and shadow linking and a lamp's Cast Shadow off with media: bdpt, lvc, cis
    // (bidir_linking_medium.h); lt's light linking and shadow linking (lt_linking.h,
    // lt_medium.h), its shadow linking in homogeneous media alone (its walk takes sigma_t's
    // transmittance). lt's lamp Cast Shadow off there stays with pt
    if (std::string v = media_reason(in); !v.empty() && unshadowed && light_tracer)
        return "linking or no shadows with " + v;
    if (shadow && light_tracer)
        for (const MaterialInput& m : in.materials)
            if (m.medium >= 0 && (m.density_grid >= 0 || m.program_count > 0))
                return "lt's shadow linking with a volume of a graph or grid (material '" + m.name +
                       "')";
    return "";
}

namespace {
// Strands or a hair material (docs/curves.md): what auto was not checked on beside linking or
// Cast Shadow off (pt_only_reason); "" when none.
std::string curves_reason(const SceneInput& in) {
    for (const CurveInput& c : in.curves)
        if (c.offsets.size() > 1) return "strands (curves '" + c.name + "')";
    for (const MaterialInput& m : in.materials)
        if (m.type == "hair") return "a hair material ('" + m.name + "')";
    return "";
}
}  // namespace

namespace {
// A strand material's leaves: itself, or a mix's children (leaves, not mixes: scene.h).
template <class F>
bool any_strand_leaf(const SceneInput& in, uint32_t k, F&& f) {
    if (k >= in.materials.size()) return false;  // (the scene's own fallback: a diffuse)
    const MaterialInput& m = in.materials[k];
    if (f(m)) return true;
    if (m.type == "mix")
        for (int c : m.mix_children)
            if (c >= 0 && size_t(c) < in.materials.size() && f(in.materials[size_t(c)]))
                return true;
    return false;
}
}  // namespace

std::string curves_bidir_reason(const SceneInput& in) {
    // (Principled Hair in a mix: a tube vertex, its lobe in the surface measure, bdpt_curve.h;
    // strands beside volumes: a strand is no volume boundary, the medium connections read its
    // cosines as the others do, bdpt_medium_stages.h)
    for (const MeshInput& m : in.meshes)
        for (uint32_t k : m.material_ids)
            if (k < in.materials.size() && in.materials[k].type == "hair")
                return "a hair material on a mesh (mesh '" + m.name + "')";
    return "";
}

std::string curves_lt_reason(const SceneInput& in) {
    // Principled Hair as a mix's leaf is a tube vertex (bdpt_curve.h) whose transmission lt
    // reaches through the strand (lt_strand.h); the other transmitting leaves go to pt still
    auto transmits = [&](const MaterialInput& m) {  // (material_transmits_leaf, but hair's)
        return m.type == "dielectric" || m.type == "translucent" ||
               (m.type == "principled" && m.transmission > 0.0f);
    };
    for (const CurveInput& c : in.curves) {
        if (c.offsets.size() <= 1) continue;
        for (uint32_t k : c.material_ids)
            if (any_strand_leaf(in, k, transmits))
                return "strands shaded by a BSDF that transmits (curves '" + c.name +
                       "', material '" + in.materials[k].name + "')";
    }
    return "";
}

std::string pt_only_reason(const SceneInput& in) {
    for (const MaterialInput& m : in.materials)
        if (m.holdout) return "a holdout (material '" + m.name + "')";
    for (const MeshInput& m : in.meshes)
        if (m.shadow_catcher) return "a shadow catcher (mesh '" + m.name + "')";
    // light and shadow linking, a lamp's or an object's Cast Shadow off (branch autowide), and
    // object and lamp ray visibility (branch automis): cis renders them itself where
    // bidir_visibility_reason says so (bidir_linking.h, bidir_no_shadow.h,
    // bidir_ray_visibility.h), and auto weighs them on surfaces (docs/auto_integrator.md: the
    // moment channels of restricted paths are pt's weights' own); linking and Cast Shadow off
    // beside media, subsurface or strands, and the kinds beside strands, stay pt's
    // (combinations auto was not checked on)
    if (const std::string v = ray_visibility_reason(in), u = no_shadow_object_reason(in);
        !v.empty() || !u.empty()) {
        if (std::string w = bidir_visibility_reason(in, false); !w.empty()) return w;
        // object and lamp ray visibility by kind wherever cis renders it (what
        // bidir_visibility_reason does not hand over): a restricted path is pt's two techniques
        // at pt's weights, so its channels are pt's own term beside linking, Cast Shadow off,
        // media and walks too; checked (branch autotidy, test_auto_kinds.py: a kind no path
        // traces hidden leaves the identity as it was beside each). What follows is the other
        // features' own rule (linking beside media, ...), named as such, and strands
        bool hidden = false;
        for (const MeshInput& m : in.meshes) hidden |= (m.rays & kRayKindsAll) != kRayKindsAll;
        for (const LightInput& l : in.lights) hidden |= (l.rays & kRayKindsAll) != kRayKindsAll;
        const bool kinds_only = hidden && !linking_or_no_shadow(in);
        const std::string what = kinds_only ? v
                                 : hidden   ? "light or shadow linking or Cast Shadow off"
                                            : v.empty() ? u : v;
        if (std::string w = media_reason(in); !w.empty() && !kinds_only)
            return what + " with " + w;
        // light linking alone beside subsurface scattering (branch automis): a zero that every
        // technique applies, a walk's exit receiving as its surface (bdpt_sss.h), so the
        // identity holds as through walks without it (test_auto_wide.py)
        bool light_links_only = u.empty();
        for (const MeshInput& m : in.meshes)
            light_links_only &= (m.rays & kRayKindsAll) == kRayKindsAll && m.shadow_set == 0 &&
                                m.emitter_blockers == kAllReceivers;
        for (const LightInput& l : in.lights)
            light_links_only &= (l.rays & kRayKindsAll) == kRayKindsAll &&
                                l.blockers == kAllReceivers && l.cast_shadow;
        for (const CurveInput& c : in.curves) light_links_only &= c.shadow_set == 0;
        if (std::string w = subsurface_reason(in); !w.empty() && !light_links_only && !kinds_only)
            return what + " with " + w;
        if (std::string w = curves_reason(in); !w.empty()) return what + " with " + w;
    }
    if (in.catcher_mode != 0) return "a shadow catcher pass";
    if (std::string v = world_rays_reason(in); !v.empty()) return v;
    // media (with auto_media on; session.cpp): cis has medium vertices in homogeneous and
    // heterogeneous media (bdpt_medium_stages.h, bdpt_medium_hetero.h); emissive ones stay pt's
    // here (emissive_media_reason), as auto's trials carry no moment channels in media at all
    if (std::string v = emissive_media_reason(in); !v.empty()) return v;
    // motion blur: no longer pt's (branch autowide). cis gives each pass one shutter time and
    // renders the pass at it (docs/motion_blur.md); its trials' moment channels, each at its
    // pass's time, are pt's second moment at that time, whose mean over the uniform times is
    // pt's own (pt draws the time per sample: its density of a (time, path) pair is its
    // still-frame density at that time), test_auto_wide.py. With more than one sample a pass
    // cis's passes hold one time for several samples, which one-sample trials do not see: the
    // session keeps pt there (session.cpp)
    // subsurface scattering: no longer pt's (branch autowide) on the CPU, where cis's camera
    // paths walk as pt's do (bdpt_sss.h; a GPU: session.cpp keeps pt there unless its
    // self-check passed the subsurface cases). With the moment channels on, light paths do not walk (bdpt_sss_light.h
    // bdpt_sss_split_on), nor under a connection map (auto's kept cis iterations by default)
    if (std::string v = curves_bidir_reason(in); !v.empty()) return v;  // docs/curves.md
    return "";
}

}  // namespace lantern
