// Nested and heterogeneous media through pt end to end (docs/volumes.md), against Beer-Lambert
// along chords of known length: an absorbing box inside another absorbing box (coefficients add
// inside the inner one, the outer one resumes after it: Cycles' summed volume stack), seen from
// outside both and from inside the inner one (the camera's medium), with the unnested answer as
// a negative control; and a heterogeneous absorbing box whose density is an attribute channel
// equal to -z (a node program reading it; the map fitted at load), whose transmittance is
// exp(-sigma x integral of the density), with the density's mean as a negative control.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "backend/cpu/embree_loader.h"
#include "integrator/session.h"
#include "scene/material_program.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;

namespace {

MaterialInput volume_material(int medium, const char* name) {
    MaterialInput m;
    m.name = name;
    m.medium = medium;
    m.volume_only = true;
    return m;
}

// A camera at the origin looking down -Z, orthographic over a tiny window; a white world.
SceneInput base_scene() {
    SceneInput in;
    in.width = 8;
    in.height = 8;
    in.orthographic = true;
    in.screen[0] = -0.1f; in.screen[1] = 0.1f; in.screen[2] = -0.1f; in.screen[3] = 0.1f;
    in.clip_start = 0.0f;
    in.world_color = vec3(1.0f);
    return in;
}

Vec3 render_mean(const SceneInput& in, int spp, uint64_t seed,
                 std::vector<std::string>* warnings = nullptr) {
    SessionSettings st;
    st.integrator = "pt";
    st.spp_per_iteration = spp;
    st.max_depth = 1;
    st.seed = seed;
    st.threads = 1;
    Session s(in, st);
    EXPECT_TRUE(s.step());
    if (warnings) *warnings = s.warnings();
    const std::vector<float> img = s.image();
    double c[3] = {0, 0, 0};
    for (size_t i = 0; i < img.size(); ++i) c[i % 3] += img[i];
    const double n = double(img.size() / 3);
    return vec3(float(c[0] / n), float(c[1] / n), float(c[2] / n));
}

const float kOuter[3] = {0.1f, 0.2f, 0.3f}, kInner[3] = {0.5f, 0.4f, 0.2f};

SceneInput nested_scene(float outer_z0, float outer_z1, float inner_z0, float inner_z1) {
    SceneInput in = base_scene();
    MediumInput outer, inner;
    outer.name = "outer";
    outer.sigma_a = vec3(kOuter[0], kOuter[1], kOuter[2]);
    inner.name = "inner";
    inner.sigma_a = vec3(kInner[0], kInner[1], kInner[2]);
    in.media = {outer, inner};
    in.materials = {volume_material(0, "outer"), volume_material(1, "inner")};
    in.meshes.push_back(box_mesh({-2, -2, outer_z0}, {2, 2, outer_z1}, 0, "outer"));
    in.meshes.push_back(box_mesh({-1, -1, inner_z0}, {1, 1, inner_z1}, 1, "inner"));
    return in;
}

// A box (z -3..-2, in front of the camera) holding medium `med` whose density is the node
// program "attribute channel 0" (kTargetDensity): the caller fills the box's attributes
SceneInput density_program_box(const MediumInput& med) {
    SceneInput in = base_scene();
    in.media.push_back(med);
    MaterialInput mat = volume_material(0, med.name.c_str());
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    in.num_attribute_channels = 1;
    in.meshes.push_back(box_mesh({-1, -1, -3}, {1, 1, -2}, 0, med.name.c_str()));
    // one instruction: kOpInput mode 4 (attribute) channel 0 into register 0, the result
    in.program_code = {uint32_t(kOpInput) | (4u << 8) | (3u << 24), 0u, 0u, 0u};
    in.programs = {0u, 1u, 0u, 0u, uint32_t(kTargetDensity), 0u};
    return in;
}

}  // namespace

TEST(MediumNested, InnerBoxAddsToTheOuterAndTheOuterResumes) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    // from outside: 4 m of the outer box (z -5..-1), 1 m of which inside the inner (-3.5..-2.5)
    const Vec3 a = render_mean(nested_scene(-5, -1, -3.5f, -2.5f), 4, 1);
    // from inside the inner box (z -1..1, the camera at 0) in the outer (z -5..1)
    const Vec3 b = render_mean(nested_scene(-5, 1, -1, 1), 4, 2);
    const float ga[3] = {a.x, a.y, a.z}, gb[3] = {b.x, b.y, b.z};
    for (int c = 0; c < 3; ++c) {
        const float want = std::exp(-(kOuter[c] * 4.0f + kInner[c] * 1.0f));
        EXPECT_NEAR(ga[c], want, 1e-4f * want) << "outside, channel " << c;
        // negative control: the unnested answer (the inner medium alone inside it, vacuum
        // after it: the outer one is not resumed)
        const float unnested = std::exp(-(kOuter[c] * 1.5f + kInner[c] * 1.0f));
        EXPECT_GT(std::fabs(ga[c] - unnested), 0.05f * want) << "channel " << c;
        const float want_b = std::exp(-(kOuter[c] * 5.0f + kInner[c] * 1.0f));
        EXPECT_NEAR(gb[c], want_b, 1e-4f * want_b) << "inside, channel " << c;
    }
}

TEST(MediumHeteroPt, AbsorbingBoxOfARampDensityIsBeerLambert) {
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    MediumInput med;
    med.name = "ramp";
    med.sigma_a = vec3(0.2f, 0.5f, 1.0f);  // per unit density
    SceneInput in = density_program_box(med);
    MeshInput& m = in.meshes[0];
    for (size_t v = 0; v < m.positions.size() / 3; ++v)  // channel 0: (-z, 0, 0)
        m.attributes.insert(m.attributes.end(), {-m.positions[3 * v + 2], 0.0f, 0.0f});
    // K seeds: the mean and its standard error over them (ratio tracking is the noise; 1024
    // spp: the 2 % control needs the power, the majorant bricks' ratio tracking (volleft)
    // being a little noisier per sample than the one majorant's, and cheaper)
    const int k_seeds = 8;
    double sum[3] = {}, sum2[3] = {};
    for (int k = 0; k < k_seeds; ++k) {
        std::vector<std::string> warnings;
        const Vec3 got = render_mean(in, 1024, uint64_t(3 + k), &warnings);
        EXPECT_TRUE(warnings.empty()) << (warnings.empty() ? "" : warnings[0]);
        const double g[3] = {got.x, got.y, got.z};
        for (int c = 0; c < 3; ++c) {
            sum[c] += g[c];
            sum2[c] += g[c] * g[c];
        }
    }
    // the density runs 2..3 along every ray: its integral is 2.5
    const double s[3] = {0.2, 0.5, 1.0};
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / k_seeds;
        const double se = std::sqrt(std::max(sum2[c] / k_seeds - mean * mean, 0.0) /
                                    (k_seeds - 1)) + 1e-6 * mean;
        const double want = std::exp(-s[c] * 2.5);
        std::printf("channel %d: %.6f want %.6f se %.2g\n", c, mean, want, se);
        EXPECT_LT(std::fabs(mean - want), 5.0 * se) << "channel " << c;
        // negative control: 2 % more extinction along the ray
        EXPECT_GT(std::fabs(mean - std::exp(-s[c] * 2.5 * 1.02)), 5.0 * se) << "channel " << c;
    }
}

TEST(MediumHeteroPt, EmissionWhereTheDensityIsZeroIsTheChordTimesTheEmission) {
    // density 0 everywhere (an attribute channel of zeros), emission (1, 2, 3) per metre: the
    // majorant is kept above 0 so that the emission is still estimated; 1 m chord
    if (!embree_available()) GTEST_SKIP() << "Embree not loadable: " << embree_version();
    MediumInput med;
    med.name = "glow";
    med.sigma_a = vec3(1.0f);
    med.emission = vec3(1.0f, 2.0f, 3.0f);
    SceneInput in = density_program_box(med);
    in.world_color = vec3(0.0f);
    in.meshes[0].attributes.assign(in.meshes[0].positions.size(), 0.0f);
    const int k_seeds = 8;
    double sum[3] = {}, sum2[3] = {};
    for (int k = 0; k < k_seeds; ++k) {
        const Vec3 got = render_mean(in, 1024, uint64_t(11 + k));
        const double g[3] = {got.x, got.y, got.z};
        for (int c = 0; c < 3; ++c) {
            sum[c] += g[c];
            sum2[c] += g[c] * g[c];
        }
    }
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / k_seeds, want = double(c + 1);
        const double se = std::sqrt(std::max(sum2[c] / k_seeds - mean * mean, 0.0) /
                                    (k_seeds - 1)) + 1e-6 * want;
        std::printf("emission channel %d: %.5f want %.5f se %.2g\n", c, mean, want, se);
        EXPECT_LT(std::fabs(mean - want), 5.0 * se) << "channel " << c;
        EXPECT_GT(std::fabs(mean - 1.03 * want), 5.0 * se) << "channel " << c;  // control
    }
}

TEST(MediumHeteroPt, LightTracingKeepsAHeterogeneousMediumAndHandsAnEmissiveOneToPt) {
    // lt's medium vertices track heterogeneous media too (integrator/lt_medium.h, hetmedia;
    // its images against pt: tests/python/test_volume_hetero_bdpt.py), so a density program
    // keeps lt; an emissive medium still goes to pt (no light path starts in a medium) and
    // says so
    MediumInput med;
    med.name = "ramp";
    med.sigma_a = vec3(0.2f, 0.5f, 1.0f);
    SceneInput in = density_program_box(med);
    in.meshes[0].attributes.assign(in.meshes[0].positions.size(), 1.0f);
    SessionSettings st;
    st.integrator = "lt";
    st.spp_per_iteration = 1;
    st.max_depth = 2;
    st.threads = 1;
    Session s(in, st);
    for (const std::string& w : s.warnings())
        EXPECT_EQ(w.find("rendering with pt"), std::string::npos) << w;
    // negative control: the same medium glowing is handed to pt, by name
    in.media[0].emission = vec3(1.0f);
    Session h(in, st);
    bool said = false;
    for (const std::string& w : h.warnings())
        said = said || (w.find("emissive") != std::string::npos &&
                        w.find("rendering with pt") != std::string::npos);
    EXPECT_TRUE(said);
}
