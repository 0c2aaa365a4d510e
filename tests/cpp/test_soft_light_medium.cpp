// Soft-falloff light paths in homogeneous media (integrator/soft_light_medium.h): the light
// path's density of its first vertex with the flights' factor F(c -> x) (pass probabilities,
// the scatter density at a medium vertex: the channel rule's, bdpt_medium.h), zero where the
// route is blocked, the negative control's vacuum value; and the first hit's transmittance
// y0 -> x1 with the s = 0 technique's factor over the same segment. A stand-in for the
// executor's closest-hit queries.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "integrator/bdpt.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

struct Hit {
    int prim;
    float t;
    Vec2 uv{};  // (a moving boundary's hit point: medium_motion.h's boundary_side_at)
};
// Every query a miss, or a hit on triangle 0 (not a volume boundary) halfway.
struct FakeClosest {
    bool block = false;
    mutable int asked = 0;
    Hit closest(const Ray& r, int) const {
        ++asked;
        return block ? Hit{0, 0.5f * r.tmax} : Hit{-1, kInf};
    }
};
struct FakeStageRays {
    FakeClosest rays;
    int indirect = 0, shadow = 1;
    bool no_centre_test = false;
    float time = 0.0f;
    Hit closest_indirect(const Ray& r) const { return rays.closest(r, indirect); }
};

const Vec3 kSigmaS{0.5f, 0.6f, 0.7f}, kSigmaA{0.1f, 0.2f, 0.3f};

SceneInput fog_scene() {
    SceneInput in;
    in.materials.push_back(MaterialInput{});
    MeshInput mesh;
    mesh.name = "tri";
    mesh.positions = {-1, -1, -1, 1, -1, 0, 0, 1, 1};
    mesh.indices = {0, 1, 2};
    mesh.material_ids = {0};
    in.meshes.push_back(mesh);
    LightInput l;
    l.type = "point";
    l.power = {10, 10, 10};
    l.position = {0.2f, 0.1f, 0.3f};
    l.radius = 0.1f;
    l.soft_falloff = true;
    in.lights.push_back(l);
    MediumInput fog;
    fog.name = "fog";
    fog.sigma_s = kSigmaS;
    fog.sigma_a = kSigmaA;
    in.media.push_back(fog);
    in.world_medium = 0;
    return in;
}

float mean_tr(float t) {
    const Vec3 st = kSigmaS + kSigmaA;
    return (expf(-st.x * t) + expf(-st.y * t) + expf(-st.z * t)) / 3.0f;
}
float mean_scatter(float t) {
    const Vec3 st = kSigmaS + kSigmaA;
    return (st.x * expf(-st.x * t) + st.y * expf(-st.y * t) + st.z * expf(-st.z * t)) / 3.0f;
}

}  // namespace

TEST(SoftLightMedium, LightPathsStartInHomogeneousFog) {
    HostScene hs(fog_scene());
    ASSERT_GT(hs.view().num_media, 0);
    EXPECT_FLOAT_EQ(hs.view().lights[0].emit_pick_pdf, 1.0f);
}

TEST(SoftLightMedium, FirstVertexDensityCarriesTheFlightsFactor) {
    HostScene hs(fog_scene());
    const SceneView& v = hs.view();
    const Light& l = v.lights[0];
    const Vec3 x = l.position + vec3(0.3f, -0.4f, 1.2f);
    const float d = length(x - l.position);
    const float vacuum = (0.25f * kInvPi) / (kPi * 0.01f) / (d * d);
    FakeStageRays open;
    // a medium vertex: no cosine, the scatter density at d
    const float pm = soft_light_path_pdf_a_medium(v, open, l, x, vec3(0.0f));
    EXPECT_NEAR(pm, vacuum * mean_scatter(d), 1e-5f * vacuum);
    EXPECT_EQ(open.rays.asked, 1);  // one ray per piece (no boundary here)
    // a surface: the cosine, the pass probability (to its offset point: 1e-4 of d short)
    const Vec3 ng = normalize(vec3(0.2f, 0.1f, -1.0f));
    const float cos_x = fabsf(dot(normalize(x - l.position), ng));
    const float ps = soft_light_path_pdf_a_medium(v, open, l, x, ng);
    EXPECT_NEAR(ps, vacuum * cos_x * mean_tr(d), 2e-4f * vacuum);
    EXPECT_LT(ps, vacuum * cos_x * 0.5f);  // the fog's factor is there (about 0.2 here)
    FakeStageRays blocked;
    blocked.rays.block = true;
    EXPECT_EQ(soft_light_path_pdf_a_medium(v, blocked, l, x, ng), 0.0f);  // V(c, x) = 0
    EXPECT_EQ(soft_light_path_pdf_a_medium(v, blocked, l, x, vec3(0.0f)), 0.0f);
    blocked.no_centre_test = true;  // the negative control: F and V left out
    EXPECT_NEAR(soft_light_path_pdf_a_medium(v, blocked, l, x, ng), vacuum * cos_x,
                1e-5f * vacuum);
}

// y0 -> x1 through the fog: the transmittance per channel exp(-sigma_t |y0 - x1|) and the s = 0
// technique's factor over the same segment, the mean of those (the channel rule's pass
// probability); a medium vertex leaves the flux's cosine and its medium as given.
TEST(SoftLightMedium, FirstHitTransmittanceAndPassFactor) {
    HostScene hs(fog_scene());
    const SceneView& v = hs.view();
    const Light& l = v.lights[0];
    const Vec3 x = l.position + vec3(-0.2f, 0.5f, 0.7f);
    FakeStageRays open;
    Rng rng = Rng::for_path(5, 0, 0);
    const Vec3 st = kSigmaS + kSigmaA;
    for (int k = 0; k < 200; ++k) {
        const SoftFirstHitMedium sm =
            soft_light_first_hit_medium(v, open, l, x, vec3(0.0f), 0, 0, rng.uniform2());
        ASSERT_TRUE(sm.hit.valid);
        EXPECT_EQ(sm.medium, 0);
        const float t = -logf(sm.tr.x) / st.x;  // the segment's length, from channel 0
        EXPECT_GT(t, length(x - l.position) - 0.11f);
        EXPECT_NEAR(sm.tr.y, expf(-st.y * t), 1e-5f);
        EXPECT_NEAR(sm.tr.z, expf(-st.z * t), 1e-5f);
        EXPECT_NEAR(sm.pass, (sm.tr.x + sm.tr.y + sm.tr.z) / 3.0f, 1e-5f);
    }
    FakeStageRays shut;
    shut.rays.block = true;  // y0 hidden from x1: no path
    EXPECT_FALSE(soft_light_first_hit_medium(v, shut, l, x, vec3(0.0f), 0, 0, {0.5f, 0.5f})
                     .hit.valid);
}
