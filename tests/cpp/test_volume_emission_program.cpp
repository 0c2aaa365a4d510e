// A mesh volume's Emission Strength graph (kTargetVolumeEmission, docs/volumes.md "Mesh
// volumes' Emission Strength graphs"): a unit cube of volume-only material, no extinction,
// emission flame_emission x max(k x, 0) per point. medium_emission_at gives it at points; the
// emission gathered at the tentative collisions of spectral tracking along +x (W e / mu, at the
// collision floor of one per bounding-box diagonal) averages to its integral flame x k / 2
// (a 3 % change of k is the control); lt refuses the scene (emissive_media_reason). A graph
// whose bound is 0 everywhere (k = 0, or k < 0: a strength <= 0, which Lantern takes as 0)
// drops the emission and its floor.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/rng.h"
#include "scene/medium_hetero.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;

namespace {

const Vec3 kEpFlame{1.0f, 0.5f, 0.25f};

void ep_instr(std::vector<uint32_t>& code, int op, int mode, int dim, int in, int out) {
    code.insert(code.end(), {uint32_t(op | (mode << 8) | (dim << 24)), uint32_t(in | (out << 16)),
                             0u, 0u});
}

// strength k x position.x (Math multiply)
SceneInput ep_scene(float k, Vec3 flame = kEpFlame) {
    SceneInput in;
    std::vector<float> c = {k, 0.0f};
    std::vector<uint32_t> code;
    ep_instr(code, kOpInput, 0, 0, 0, 16);   // position 16..18
    ep_instr(code, kOpCopy, 0, 1, 16, 30);
    ep_instr(code, kOpCopy, 0, 1, 0, 31);
    ep_instr(code, kOpCopy, 0, 1, 1, 32);
    ep_instr(code, kOpMath, 2, 0, 30, 33);   // x * k
    for (int j = 0; j < 3; ++j) ep_instr(code, kOpCopy, 0, 1, 33, 40 + j);
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()),
                   uint32_t(kTargetVolumeEmission), 40u};
    MediumInput med;
    med.name = "flame";
    med.flame_emission = flame;
    in.media.push_back(med);
    MaterialInput mat;
    mat.name = "flame";
    mat.medium = 0;
    mat.volume_only = true;
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    in.meshes.push_back(lantern::test::box_mesh(vec3(0.0f), vec3(1.0f), 0));
    return in;
}

// The emission gathered along +x through the cube at (., 0.37, 0.58): the mean of sum W e / mu
// over n spectral trackings
Vec3 ep_gathered(const SceneView& s, const Medium& m, int32_t med, int n) {
    const Vec3 o{0.0f, 0.37f, 0.58f}, d{1, 0, 0};
    Vec3 sum = vec3(0.0f);
    for (int k = 0; k < n; ++k) {
        Rng path = Rng::for_path(91, 0, uint64_t(k));
        Rng r = medium_tracking_rng(path, 0);
        Vec3 got = vec3(0.0f);
        medium_track(s, m, med, o, d, 1.0f, vec3(1.0f), r,
                     [&](float t, Vec3 w, float mu) {
                         got = got + w * medium_emission_at(s, m, med, o + d * t) / mu;
                     },
                     [](float, float, Vec3) {});
        sum = sum + got;
    }
    return sum / float(n);
}

}  // namespace

TEST(VolumeEmissionProgram, MeshStrengthGraphEmitsItsIntegral) {
    const float k = 4.0f;
    SceneInput in = ep_scene(k);
    EXPECT_NE(emissive_media_reason(in).find("node graph on the emission"), std::string::npos)
        << emissive_media_reason(in);
    HostScene scene(in);
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    ASSERT_GE(med, 0);
    const Medium& m = s.media[med];
    ASSERT_GE(m.emission_prog, 0);
    EXPECT_EQ(m.emits, 1u);
    EXPECT_NEAR(m.majorant, 1.0f / std::sqrt(3.0f), 1e-4f);   // the floor: one per diagonal
    for (float x : {0.1f, 0.5f, 0.9f}) {
        const Vec3 e = medium_emission_at(s, m, med, Vec3{x, 0.5f, 0.5f});
        EXPECT_NEAR(e.x, kEpFlame.x * k * x, 1e-5f);
        EXPECT_NEAR(e.z, kEpFlame.z * k * x, 1e-5f);
    }
    const Vec3 got = ep_gathered(s, m, med, 400000);
    const float want = kEpFlame.x * k * 0.5f;
    std::printf("gathered %.4f %.4f %.4f, the integral %.4f %.4f %.4f\n", got.x, got.y, got.z,
                want, want * 0.5f, want * 0.25f);
    EXPECT_NEAR(got.x, want, 0.01f * want);
    EXPECT_NEAR(got.y, 0.5f * want, 0.01f * want);
    // the control: k 3 % off is told apart
    EXPECT_GT(std::fabs(got.x - 1.03f * want), 0.02f * want);
}

TEST(VolumeEmissionProgram, StrengthBoundOfZeroDropsTheEmission) {
    for (float k : {0.0f, -4.0f}) {
        HostScene scene(ep_scene(k));
        const SceneView& s = scene.view();
        const Medium& m = s.media[s.material_medium[0]];
        EXPECT_EQ(m.emits, 0u) << k;
        EXPECT_LT(m.emission_prog, 0) << k;
        EXPECT_EQ(m.majorant, 0.0f) << k;
    }
    // no colour factor: nothing emits, and lt renders it
    EXPECT_TRUE(emissive_media_reason(ep_scene(4.0f, vec3(0.0f))).empty());
}
