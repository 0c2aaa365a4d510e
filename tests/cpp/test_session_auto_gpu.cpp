// Integrator "auto" on a GPU (a test double) in scenes with subsurface scattering or media: it
// keeps pt there unless the GPU self-check passed that feature's cases (SessionSettings::
// gpu_checked, which python/lantern/session.py fills from gpu_selfcheck.py's verdict), and
// chooses (a pilot) where it did; a feature checked does not open the other. Host code only:
// this never ran on a GPU.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "backend/cpu/embree_loader.h"
#include "backend/cuda/cuda_renderer.h"
#include "integrator/session.h"

using namespace lantern;

namespace {

// A GPU that adds nothing: only the session's choice is under test.
class AutoGpuDouble final : public CudaRenderer {
public:
    explicit AutoGpuDouble(size_t px3) : sum_(px3, 0.0) {}
    bool step(const SessionSettings& settings, uint64_t& iteration, SessionStats&,
              const std::atomic<bool>&, std::vector<std::string>&) override {
        samples_ += settings.spp_per_iteration;
        ++iteration;
        return true;
    }
    std::vector<double> accum(int64_t* samples) override {
        *samples = samples_;
        return sum_;
    }
    std::string device_name() const override { return "auto's test double"; }

private:
    std::vector<double> sum_;
    int64_t samples_ = 0;
};

// A floor quad under a point light; `sss`: its material Principled with subsurface scattering;
// `fog`: a world volume.
SceneInput auto_gpu_scene(bool sss, bool fog) {
    SceneInput in;
    in.width = in.height = 8;
    in.screen[0] = -1.0f; in.screen[1] = 1.0f; in.screen[2] = -1.0f; in.screen[3] = 1.0f;
    in.clip_start = 0.01f;
    MaterialInput m;
    m.name = "floor";
    m.base_color = vec3(0.8f);
    if (sss) {
        m.type = "principled";
        m.subsurface_weight = 1.0f;
        m.subsurface_radius = vec3(0.1f);
    }
    in.materials.push_back(m);
    MeshInput mesh;
    mesh.name = "floor";
    mesh.positions = {-2.0f, -2.0f, -3.0f, 2.0f, -2.0f, -3.0f,
                      2.0f,  2.0f,  -3.0f, -2.0f, 2.0f, -3.0f};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    mesh.material_ids = {0, 0};
    in.meshes.push_back(mesh);
    LightInput l;
    l.type = "point";
    l.name = "lamp";
    l.position = vec3(0.0f, 0.0f, -1.0f);
    l.power = vec3(100.0f);
    l.soft_falloff = false;
    in.lights.push_back(l);
    if (fog) {
        MediumInput f;
        f.name = "fog";
        f.sigma_s = vec3(0.1f);
        in.media.push_back(f);
        in.world_medium = 0;
    }
    return in;
}

// The session's auto_choice (0 the pilot: auto chooses; 1 pt) and whether it warned of pt.
std::pair<int, bool> auto_gpu_choice(bool sss, bool fog, int checked) {
    SessionSettings st;
    st.integrator = "auto";
    st.gpu_checked = checked;
    Session s(auto_gpu_scene(sss, fog), st, std::make_unique<AutoGpuDouble>(size_t(8 * 8 * 3)));
    EXPECT_EQ(s.backend_name(), "cuda");
    bool warned = false;
    for (const std::string& w : s.warnings())
        warned |= w.find("whose self-check has not passed its cases") != std::string::npos;
    return {s.stats().auto_choice, warned};
}

}  // namespace

TEST(AutoOnGpu, SubsurfaceAndMediaWaitForTheirSelfCheckCases) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    const std::pair<int, bool> pilot{0, false}, pt{1, true};
    // no feature: auto chooses whatever was checked
    EXPECT_EQ(auto_gpu_choice(false, false, 0), pilot);
    // subsurface: pt until its cases passed; the media cases do not stand in for them
    EXPECT_EQ(auto_gpu_choice(true, false, 0), pt);
    EXPECT_EQ(auto_gpu_choice(true, false, kGpuCheckedMedia), pt);
    EXPECT_EQ(auto_gpu_choice(true, false, kGpuCheckedSubsurface), pilot);
    // media: likewise
    EXPECT_EQ(auto_gpu_choice(false, true, 0), pt);
    EXPECT_EQ(auto_gpu_choice(false, true, kGpuCheckedSubsurface), pt);
    EXPECT_EQ(auto_gpu_choice(false, true, kGpuCheckedMedia), pilot);
    // both: each needs its own
    EXPECT_EQ(auto_gpu_choice(true, true, kGpuCheckedSubsurface), pt);
    EXPECT_EQ(auto_gpu_choice(true, true, kGpuCheckedMedia), pt);
    EXPECT_EQ(auto_gpu_choice(true, true, kGpuCheckedSubsurface | kGpuCheckedMedia), pilot);
}
