// A moving emitter (docs/motion_blur.md "A moving emitter"; scene/lights.h light_triangle_at):
// an emissive triangle of a mesh that turns, scales and slides (and one that deforms) is
// sampled where it is at the given shutter time: its corners are the object's matrix at that
// time applied exactly (double precision here), its area the moved triangle's; next-event
// estimation's pdf equals light_pdf_w_at's of the same point at the same time, light paths'
// pdfs equal emission_pdf's; a still emitter ignores the time (the same bits), and the scene
// builds without the old warning.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/rng.h"
#include "integrator/light_path.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

// The lamp's object-to-world at shutter time t: slide x, turn about z by 0.8 t, scale 0.5 + t.
void moving_lamp_matrix(double t, double m[16]) {
    const double a = 0.8 * t, c = std::cos(a), s = std::sin(a), k = 0.5 + t;
    const double r[16] = {c * k, -s * k, 0, -1.0 + 2.0 * t, s * k, c * k, 0, 0.3,
                          0,     0,      1, 1.5,            0,     0,     0, 1};
    for (int i = 0; i < 16; ++i) m[i] = r[i];
}

const double kLampLocal[3][3] = {{-0.5, -0.2, 0.0}, {0.6, -0.1, 0.0}, {0.1, 0.4, 0.05}};

Vec3 moving_lamp_corner(double t, int j) {
    double m[16];
    moving_lamp_matrix(t, m);
    const double* p = kLampLocal[j];
    double w[3];
    for (int i = 0; i < 3; ++i)
        w[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3];
    return vec3(float(w[0]), float(w[1]), float(w[2]));
}

// A floor triangle and the lamp, exported at the shutter's middle with 3 steps; `moves` false:
// the lamp still there.
SceneInput moving_lamp_scene(bool moves) {
    SceneInput in;
    MaterialInput floor, lamp;
    lamp.emission = vec3(3.0f);
    in.materials = {floor, lamp};
    MeshInput f;
    f.name = "floor";
    f.positions = {-5, -5, 0, 5, -5, 0, 0, 5, 0};
    f.indices = {0, 1, 2};
    f.material_ids = {0};
    in.meshes.push_back(f);
    MeshInput m;
    m.name = "lamp";
    for (int j = 0; j < 3; ++j) {
        const Vec3 p = moving_lamp_corner(0.5, j);
        m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
    }
    m.indices = {0, 1, 2};
    m.material_ids = {1};
    if (moves) {
        double mm[16];
        for (int k = 0; k < 3; ++k) {
            moving_lamp_matrix(0.5 * k, mm);
            for (double v : mm) m.motion.push_back(float(v));
        }
        moving_lamp_matrix(0.5, mm);
        for (int i = 0; i < 16; ++i) m.motion_base[i] = float(mm[i]);
    }
    in.meshes.push_back(m);
    return in;
}

const Light& moving_lamp_light(const SceneView& v) {
    for (int i = 0; i < v.num_lights; ++i)
        if (v.lights[i].type == kLightTriangle) return v.lights[i];
    ADD_FAILURE() << "no triangle light";
    return v.lights[0];
}

double moving_lamp_area(double t) {
    const Vec3 a = moving_lamp_corner(t, 0), b = moving_lamp_corner(t, 1),
               c = moving_lamp_corner(t, 2);
    return 0.5 * double(length(cross(b - a, c - a)));
}

}  // namespace

TEST(MovingEmitter, SampledWhereItIsAtTheTime) {
    HostScene hs(moving_lamp_scene(true));
    for (const std::string& w : hs.warnings()) EXPECT_EQ(w.find("emit"), std::string::npos) << w;
    const SceneView& v = hs.view();
    ASSERT_EQ(v.motion.num_objects, 1);
    const Light& l = moving_lamp_light(v);
    const Vec3 p = vec3(0.3f, -0.2f, 0.0f);  // a floor point under it
    Pcg32 rng = Pcg32::for_path(5, 0, 0);
    for (float t : {0.0f, 0.21f, 0.5f, 0.77f, 1.0f}) {
        const MovedTriangle mt = light_triangle_at(v, l, t);
        ASSERT_TRUE(mt.moved);
        for (int j = 0; j < 3; ++j) {
            const Vec3 e = moving_lamp_corner(t, j);
            EXPECT_LT(length(mt.v[j] - e), 2e-5f) << "t " << t << " corner " << j;
        }
        EXPECT_NEAR(mt.area, moving_lamp_area(t), 1e-5 * moving_lamp_area(t)) << t;
        EXPECT_EQ(light_area_at(v, l, t), mt.area);
        const Vec3 a = mt.v[0], n = normalize(cross(mt.v[1] - a, mt.v[2] - a));
        for (int k = 0; k < 64; ++k) {
            const LightSample ls = sample_light(v, l, p, rng.uniform2(), t);
            ASSERT_TRUE(ls.valid);
            EXPECT_NEAR(dot(ls.p_light - a, n), 0.0f, 1e-5f);  // on the moved triangle's plane
            EXPECT_NEAR(fabsf(dot(ls.n_light, n)), 1.0f, 1e-5f);
            const float pdf = light_pdf_w_at(v, l, p, ls.wi, ls.dist, ls.n_light, t);
            EXPECT_NEAR(pdf, ls.pdf_w, 1e-5f * ls.pdf_w);
            const EmissionSample es = sample_emission(v, l, rng.uniform2(), rng.uniform2(), t);
            ASSERT_TRUE(es.valid);
            EXPECT_NEAR(dot(es.p - a, n), 0.0f, 1e-5f);
            EXPECT_EQ(es.pdf_direct, 1.0f / mt.area);
            const EmissionPdf ep = emission_pdf(v, l, es.n, es.d, t);
            EXPECT_EQ(ep.pdf_direct, es.pdf_direct);
            EXPECT_NEAR(ep.pdf_emit, es.pdf_emit, 1e-5f * es.pdf_emit);
        }
    }
    // control: the area at another time is not this one's (it grows 9-fold over the shutter)
    EXPECT_GT(light_area_at(v, l, 1.0f), 8.0f * light_area_at(v, l, 0.0f));
}

TEST(MovingEmitter, StillEmitterIgnoresTheTime) {
    HostScene hs(moving_lamp_scene(false));
    const SceneView& v = hs.view();
    EXPECT_EQ(v.motion.num_objects, 0);
    const Light& l = moving_lamp_light(v);
    EXPECT_EQ(light_area_at(v, l, 0.9f), l.area);
    const Vec2 u{0.3f, 0.6f};
    const LightSample a = sample_light(v, l, vec3(0.3f, -0.2f, 0.0f), u, 0.0f);
    const LightSample b = sample_light(v, l, vec3(0.3f, -0.2f, 0.0f), u, 0.9f);
    EXPECT_EQ(a.pdf_w, b.pdf_w);
    EXPECT_EQ(a.p_light.x, b.p_light.x);
    EXPECT_EQ(a.p_light.y, b.p_light.y);
    EXPECT_EQ(a.p_light.z, b.p_light.z);
}

// The light tree's bounds over the shutter (docs/motion_blur.md "A moving emitter"): beside a
// still point light (so that the tree is built), the moving lamp's leaf holds its triangle at
// every time, not only where it was exported; the still lamp's leaf is its frame's box.
TEST(MovingEmitter, LightTreeLeafHoldsTheShutter) {
    for (bool moves : {true, false}) {
        SceneInput in = moving_lamp_scene(moves);
        LightInput pl;
        pl.type = "point";
        pl.position = vec3(3.0f, 3.0f, 4.0f);
        pl.power = vec3(10.0f);
        in.lights.push_back(pl);
        HostScene hs(in);
        const SceneView& v = hs.view();
        ASSERT_TRUE(v.light_tree_on);
        const Light& l = moving_lamp_light(v);
        ASSERT_GE(l.tree_leaf, 0);
        const LightTreeNode& leaf = v.light_tree[l.tree_leaf];
        int outside = 0;
        for (int k = 0; k <= 40; ++k) {
            const double t = k / 40.0;
            for (int j = 0; j < 3; ++j) {
                const Vec3 c = moving_lamp_corner(moves ? t : 0.5, j);
                const float e = 1e-4f;
                outside += c.x < leaf.lo.x - e || c.y < leaf.lo.y - e || c.z < leaf.lo.z - e ||
                           c.x > leaf.hi.x + e || c.y > leaf.hi.y + e || c.z > leaf.hi.z + e;
            }
        }
        EXPECT_EQ(outside, 0) << (moves ? "moving" : "still");
        // the root holds the leaf, and the still lamp's box is its triangle's own
        EXPECT_LE(v.light_tree[0].lo.x, leaf.lo.x);
        EXPECT_GE(v.light_tree[0].hi.x, leaf.hi.x);
        float lo_x = 1e30f, hi_x = -1e30f;  // the frame's triangle
        for (int j = 0; j < 3; ++j) {
            lo_x = ::fminf(lo_x, moving_lamp_corner(0.5, j).x);
            hi_x = ::fmaxf(hi_x, moving_lamp_corner(0.5, j).x);
        }
        if (!moves) {
            EXPECT_NEAR(leaf.lo.x, lo_x, 1e-5f);
            EXPECT_NEAR(leaf.hi.x, hi_x, 1e-5f);
        } else {  // control: the frame's triangle alone is far narrower than the slide's box
            EXPECT_GT(leaf.hi.x - leaf.lo.x, (hi_x - lo_x) + 1.5f);
        }
    }
}

// Under -DLANTERN_RNG_PCG (bench/qmc_noise.py) Rng is Pcg32: the path's time must not change as
// its stages draw numbers (they recompute it: nothing is stored per slot), and paths differ.
TEST(MovingEmitter, PcgStreamTimeSurvivesDraws) {
    Pcg32 a = Pcg32::for_path(7, 3, 11);
    const float t = motion_time(a);
    const uint64_t start = a.state;
    for (int k = 0; k < 37; ++k) a.uniform();
    EXPECT_EQ(motion_time(a), t);
    EXPECT_NE(a.state, start);  // (the state the time was once hashed from has moved on)
    EXPECT_EQ(motion_time(Pcg32::for_path(7, 3, 11)), t);
    int same = 0;
    for (uint64_t p = 0; p < 64; ++p) same += motion_time(Pcg32::for_path(7, 3, p)) == t;
    EXPECT_EQ(same, 1);  // only path 11's
    EXPECT_GE(t, 0.0f);
    EXPECT_LT(t, 1.0f);
}
