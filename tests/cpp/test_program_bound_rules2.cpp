// Interval rules of node programs, the second set (scene/program_bound.cpp,
// program_bound_tex.cpp; issue 29): Fresnel and Layer Weight, Mix's Divide and its hue /
// saturation / value / colour blends, Vector Math's project, reflect and refract. As
// test_program_bound_rules.cpp: one op fed by constants and the position's components, dense
// samples of the program (program_run) in random boxes, none outside the interval
// program_bound gives for the box; the controls: a bound shrunk to the box's inner half is left
// by the outer box's samples in a share of the boxes (the rules are not loose by that much), and
// Fresnel's samples reach both ends of [0, 1].
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "scene/medium_hetero.h"
#include "scene/program_bound.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;

namespace {

void rb2_instr(std::vector<uint32_t>& code, int op, int mode, int flags, int dim, int in,
               int out, int aux = 0, int aux2 = 0) {
    code.insert(code.end(), {uint32_t(op | (mode << 8) | (flags << 16) | (dim << 24)),
                             uint32_t(in | (out << 16)), uint32_t(aux), uint32_t(aux2)});
}

// One op under test: its inputs the constants `in`, except the slots fed by the position's
// components (slot, component); outs: which of its outputs are the program's result.
struct Rb2Case {
    std::string name;
    int op, mode, flags;
    std::vector<float> in;
    std::vector<std::pair<int, int>> pos;
    int outs[3];
    float clo = -2.0f, chi = 3.0f;  // where the boxes' centres lie (per axis)
};

SceneInput rb2_scene(const Rb2Case& t) {
    SceneInput in;
    std::vector<float> c = {0, 0, 0, 0, 0, 0, 0, 0};
    c.insert(c.end(), t.in.begin(), t.in.end());  // from 8
    std::vector<uint32_t> code;
    rb2_instr(code, kOpInput, 0, 0, 0, 0, 40);  // position 40..42
    for (size_t k = 0; k < t.in.size(); k += 3)
        rb2_instr(code, kOpCopy, 0, 0, int(std::min<size_t>(3, t.in.size() - k)), 8 + int(k),
                  50 + int(k));
    for (const auto& [slot, comp] : t.pos)
        rb2_instr(code, kOpCopy, 0, 0, 1, 40 + comp, 50 + slot);
    rb2_instr(code, t.op, t.mode, t.flags, 0, 50, 80);
    for (int k = 0; k < 3; ++k) rb2_instr(code, kOpCopy, 0, 0, 1, 80 + t.outs[k], 90 + k);
    in.program_code = code;
    in.program_consts = c;
    in.programs = {0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()),
                   uint32_t(kTargetBaseColor), 90u};
    MaterialInput mat;
    mat.name = "rules2";
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    in.meshes.push_back(lantern::test::box_mesh(vec3(0.0f), vec3(1.0f), 0));
    return in;
}

struct Rb2Tally {
    int boxes = 0, exceeded = 0;   // the control: samples outside the inner half's bound
    float vmin = 1e30f, vmax = -1e30f;  // channel 0's samples
};

// bounded: 1 every box has a bound, 0 none, 2 some (the rule needs its inputs in a range).
void rb2_check(const Rb2Case& t, std::mt19937& rng, int boxes, int samples, float size,
               int bounded, Rb2Tally* tally) {
    HostScene scene(rb2_scene(t));
    const SceneView& s = scene.view();
    ASSERT_NE(s.programs, nullptr) << t.name;
    const MaterialProgram& p = s.programs[0];
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int failures = 0, with_bound = 0;
    for (int b = 0; b < boxes; ++b) {
        const float span = t.chi - t.clo;
        const Vec3 c{t.clo + span * u(rng), t.clo + span * u(rng), t.clo + span * u(rng)};
        const float hs = 0.004f * std::pow(size / 0.004f, u(rng));
        const Vec3 h{hs * (0.5f + u(rng)), hs * (0.5f + u(rng)), hs * (0.5f + u(rng))};
        Interval iv[3], inner[3];
        const bool ok = program_bound(s, p, -1, c - h, c + h, iv);
        if (bounded != 2) EXPECT_EQ(ok, bounded == 1) << t.name;
        if (!ok) continue;
        ++with_bound;
        const bool inner_ok = program_bound(s, p, -1, c - h * 0.5f, c + h * 0.5f, inner);
        bool exceeded = false;
        for (int k = 0; k < samples; ++k) {
            Vec3 q = c - h + 2.0f * h * Vec3{u(rng), u(rng), u(rng)};
            if (k < 8)
                q = Vec3{k & 1 ? c.x + h.x : c.x - h.x, k & 2 ? c.y + h.y : c.y - h.y,
                         k & 4 ? c.z + h.z : c.z - h.z};
            const Vec3 v = program_run(s, p, medium_shade_point(-1, q, Vec3{1, 0, 0}));
            const float vv[3] = {v.x, v.y, v.z};
            tally->vmin = std::min(tally->vmin, vv[0]);
            tally->vmax = std::max(tally->vmax, vv[0]);
            for (int ch = 0; ch < 3; ++ch) {
                exceeded = exceeded ||
                           (inner_ok && !(vv[ch] >= inner[ch].lo && vv[ch] <= inner[ch].hi));
                if (!(vv[ch] >= iv[ch].lo && vv[ch] <= iv[ch].hi) && ++failures <= 3)
                    ADD_FAILURE() << t.name << " channel " << ch << ": " << vv[ch]
                                  << " outside [" << iv[ch].lo << ", " << iv[ch].hi << "] at ("
                                  << q.x << ", " << q.y << ", " << q.z << ")";
            }
        }
        ++tally->boxes;
        tally->exceeded += exceeded;
    }
    if (bounded == 2) EXPECT_GT(with_bound, 0) << t.name;
}

}  // namespace

// Fresnel (in: ior normal(3)) and Layer Weight (in: blend normal(3); out: fresnel facing): the
// viewer (-1, 0, 0), the normal the position (|n| < 1 in boxes about the origin: [0, 1]; past
// length 1 no bound), the IOR / blend constant or the position's z (extremes included).
TEST(ProgramBoundRules2, FresnelLayerWeightInsideRandomBoxes) {
    std::mt19937 rng(41);
    Rb2Tally fr, lw;
    for (float ior : {1.45f, 0.2f, 1e-6f, 40.0f})
        for (int zpos = 0; zpos < 2; ++zpos) {
            Rb2Case c{"fresnel ior " + std::to_string(ior) + (zpos ? " n.z" : ""), kOpFresnel, 0,
                      0, {ior, 0, 0, 0}, {{1, 0}, {2, 1}}, {0, 0, 0}, -0.45f, 0.45f};
            if (zpos) c.pos.push_back({3, 2});
            rb2_check(c, rng, 25, 200, 0.1f, 1, &fr);
        }
    for (float blend : {0.5f, 0.1f, 0.0f, 0.9f, 1.0f, -0.5f})
        for (int out = 0; out < 2; ++out) {
            Rb2Case c{"layer weight " + std::to_string(blend) + (out ? " facing" : " fresnel"),
                      kOpLayerWeight, 0, 0, {blend, 0, 0, 0}, {{1, 0}, {2, 1}, {3, 2}},
                      {out, out, out}, -0.5f, 0.5f};
            rb2_check(c, rng, 25, 200, 0.07f, 1, &lw);
        }
    // a normal along x up to length 0.98: c reaches about 1 (normal incidence)
    for (float ior : {1.45f, 3.0f})
        rb2_check({"fresnel n.x " + std::to_string(ior), kOpFresnel, 0, 0, {ior, 0, 0, 0},
                   {{1, 0}}, {0, 0, 0}, -0.9f, 0.9f}, rng, 40, 100, 0.05f, 1, &fr);
    // the blend from the position
    rb2_check({"layer weight blend(p)", kOpLayerWeight, 0, 0, {0, 0, 0, 0}, {{0, 2}, {1, 0}, {2, 1}},
               {1, 1, 1}, -0.5f, 0.5f}, rng, 25, 200, 0.1f, 1, &lw);
    // a normal longer than 1 (|dot| past 1): no bound
    Rb2Tally none;
    rb2_check({"fresnel long normal", kOpFresnel, 0, 0, {1.45f, 0, 0, 0}, {{1, 0}, {2, 1}, {3, 2}},
               {0, 0, 0}, 2.0f, 3.0f}, rng, 5, 10, 0.2f, 0, &none);
    std::printf("fresnel samples [%.4f, %.4f], layer weight [%.4f, %.4f]\n", fr.vmin, fr.vmax,
                lw.vmin, lw.vmax);
    // the control: the samples reach both ends of [0, 1] (Fresnel's least value at IOR
    // 1.45, normal incidence: 0.034; a bound shrunk by 5 % would fail)
    EXPECT_LT(fr.vmin, 0.05f);
    EXPECT_GT(fr.vmax, 0.98f);
    EXPECT_LT(lw.vmin, 0.02f);
    EXPECT_GT(lw.vmax, 0.98f);
}

// Mix (in: fac(3) a(3) b(3)): Divide by a b away from 0 (constant, or the position in boxes
// that keep it off 0; none where b may be 0), and the hue / saturation / value / colour blends
// of colours >= 0 (none where a may be negative).
TEST(ProgramBoundRules2, MixDivideAndHsvBlendsInsideRandomBoxes) {
    std::mt19937 rng(43);
    Rb2Tally div, hsv;
    for (int variant = 0; variant < 3; ++variant) {
        Rb2Case c{"mix divide v" + std::to_string(variant), kOpMix, 10, variant == 2 ? 3 : 1,
                  {0.35f, 0, 0, 0, 0, 0, 0.6f, -0.4f, 1.3f}, {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}};
        if (variant >= 1) {
            c.pos.insert(c.pos.end(), {{6, 2}, {7, 0}, {8, 1}});
            c.clo = 0.4f;   // b = the position, off 0
        }
        if (variant == 2) c.pos.push_back({0, 2});
        rb2_check(c, rng, 25, 150, 0.3f, 1, &div);
    }
    rb2_check({"mix divide b crossing 0", kOpMix, 10, 1, {0.35f, 0, 0, 0, 0, 0, 0, 0, 0},
               {{3, 0}, {4, 1}, {5, 2}, {6, 2}, {7, 0}, {8, 1}}, {0, 1, 2}, -0.5f, 0.5f},
              rng, 10, 20, 0.6f, 2, &div);
    for (int mode = 15; mode <= 18; ++mode)
        for (int variant = 0; variant < 3; ++variant) {
            Rb2Case c{"mix hsv blend " + std::to_string(mode) + " v" + std::to_string(variant),
                      kOpMix, mode, variant == 2 ? 3 : 1, {0.6f, 0, 0, 0, 0, 0, 0.9f, 0.2f, 0.5f},
                      {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}, 0.5f, 1.5f};
            if (variant >= 1) c.pos.insert(c.pos.end(), {{6, 2}, {7, 0}, {8, 1}});
            if (variant == 2) c.pos.push_back({0, 1});
            rb2_check(c, rng, 25, 150, 0.3f, 1, &hsv);
        }
    rb2_check({"mix hsv blend negative a", kOpMix, 16, 1, {0.6f, 0, 0, 0, 0, 0, 0.9f, 0.2f, 0.5f},
               {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}, -2.0f, -1.0f}, rng, 5, 10, 0.3f, 0, &hsv);
    std::printf("control: divide %d of %d boxes, hsv blends %d of %d boxes have samples outside "
                "the inner half's bound\n", div.exceeded, div.boxes, hsv.exceeded, hsv.boxes);
    EXPECT_GT(div.exceeded, div.boxes / 2);
    EXPECT_GT(hsv.exceeded, hsv.boxes / 4);
}

// Vector Math (in: a(3) b(3) c(3) scale): project (6), reflect (7), refract (8, the scale its
// IOR), a the position, b constant or the position permuted.
TEST(ProgramBoundRules2, VectorProjectReflectRefractInsideRandomBoxes) {
    std::mt19937 rng(47);
    Rb2Tally t;
    for (int mode : {6, 7, 8})
        for (int bpos = 0; bpos < 2; ++bpos)
            for (float scale : {0.67f, 1.5f}) {
                if (mode != 8 && scale != 0.67f) continue;
                Rb2Case c{"vector math " + std::to_string(mode) + (bpos ? " b(p)" : "") +
                              " s " + std::to_string(scale),
                          kOpVectorMath, mode, 0,
                          {0, 0, 0, 0.7f, -1.3f, 2.1f, 0.4f, 0.2f, -0.9f, scale},
                          {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}};
                if (bpos) c.pos.insert(c.pos.end(), {{3, 2}, {4, 0}, {5, 1}});
                rb2_check(c, rng, 25, 200, 0.6f, 1, &t);
            }
    // b = 0: project gives 0, reflect a
    rb2_check({"project b = 0", kOpVectorMath, 6, 0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 1},
               {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}}, rng, 10, 50, 0.6f, 1, &t);
    // the bound is a radius (|a|, or refract's), loose per component where the vector is not
    // along an axis: the inner half's bound is left in fewer boxes than the other rules'
    std::printf("control: %d of %d boxes have samples outside the inner half's bound\n",
                t.exceeded, t.boxes);
    EXPECT_GT(t.exceeded, t.boxes / 8);
}
