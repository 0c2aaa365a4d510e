// Interval rules of node programs, the second set (scene/program_bound.cpp,
// program_bound_tex.cpp; issue 29): Fresnel and Layer Weight, Mix's Divide and its hue /
// saturation / value / colour blends, Vector Math's project, reflect and refract. The harness
// of program_bound_cases.h (test_program_bound_rules.cpp's): one op fed by constants and the
// position's components, dense samples of the program (program_run) in random boxes, none
// outside the interval program_bound gives for the box; the controls (in every channel): a
// bound shrunk to the box's inner half is left by the outer box's samples in a share of the
// boxes (the rules are not loose by that much), and Fresnel's samples reach both ends of [0, 1].
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "program_bound_cases.h"

using namespace lantern;

// Fresnel (in: ior normal(3)) and Layer Weight (in: blend normal(3); out: fresnel facing): the
// viewer (-1, 0, 0), the normal the position (|n| < 1 in boxes about the origin: [0, 1]; past
// length 1 no bound), the IOR / blend constant or the position's z (extremes included).
TEST(ProgramBoundRules2, FresnelLayerWeightInsideRandomBoxes) {
    std::mt19937 rng(41);
    pbc::Tally fr, lw;
    fr.control_channels = lw.control_channels = 3;
    for (float ior : {1.45f, 0.2f, 1e-6f, 40.0f})
        for (int zpos = 0; zpos < 2; ++zpos) {
            pbc::Case c{"fresnel ior " + std::to_string(ior) + (zpos ? " n.z" : ""), kOpFresnel, 0,
                      0, 0, 0, 0, {ior, 0, 0, 0}, {{1, 0}, {2, 1}}, {0, 0, 0}, -0.45f, 0.45f};
            if (zpos) c.pos.push_back({3, 2});
            pbc::check(c, rng, 25, 200, 0.1f, 1, &fr);
        }
    for (float blend : {0.5f, 0.1f, 0.0f, 0.9f, 1.0f, -0.5f})
        for (int out = 0; out < 2; ++out) {
            pbc::Case c{"layer weight " + std::to_string(blend) + (out ? " facing" : " fresnel"),
                      kOpLayerWeight, 0, 0, 0, 0, 0, {blend, 0, 0, 0}, {{1, 0}, {2, 1}, {3, 2}},
                      {out, out, out}, -0.5f, 0.5f};
            pbc::check(c, rng, 25, 200, 0.07f, 1, &lw);
        }
    // a normal along x up to length 0.98: c reaches about 1 (normal incidence)
    for (float ior : {1.45f, 3.0f})
        pbc::check({"fresnel n.x " + std::to_string(ior), kOpFresnel, 0, 0, 0, 0, 0, {ior, 0, 0, 0},
                   {{1, 0}}, {0, 0, 0}, -0.9f, 0.9f}, rng, 40, 100, 0.05f, 1, &fr);
    // the blend from the position
    pbc::check({"layer weight blend(p)", kOpLayerWeight, 0, 0, 0, 0, 0, {0, 0, 0, 0},
                {{0, 2}, {1, 0}, {2, 1}}, {1, 1, 1}, -0.5f, 0.5f},
               rng, 25, 200, 0.1f, 1, &lw);
    // a normal longer than 1 (|dot| past 1): no bound
    pbc::Tally none;
    none.control_channels = 3;
    pbc::check({"fresnel long normal", kOpFresnel, 0, 0, 0, 0, 0, {1.45f, 0, 0, 0},
                {{1, 0}, {2, 1}, {3, 2}}, {0, 0, 0}, 2.0f, 3.0f},
               rng, 5, 10, 0.2f, 0, &none);
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
    pbc::Tally div, hsv;
    div.control_channels = hsv.control_channels = 3;
    for (int variant = 0; variant < 3; ++variant) {
        pbc::Case c{"mix divide v" + std::to_string(variant), kOpMix, 10, variant == 2 ? 3 : 1, 0,
                    0, 0,
                  {0.35f, 0, 0, 0, 0, 0, 0.6f, -0.4f, 1.3f}, {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}};
        if (variant >= 1) {
            c.pos.insert(c.pos.end(), {{6, 2}, {7, 0}, {8, 1}});
            c.clo = 0.4f;   // b = the position, off 0
        }
        if (variant == 2) c.pos.push_back({0, 2});
        pbc::check(c, rng, 25, 150, 0.3f, 1, &div);
    }
    pbc::check({"mix divide b crossing 0", kOpMix, 10, 1, 0, 0, 0, {0.35f, 0, 0, 0, 0, 0, 0, 0, 0},
               {{3, 0}, {4, 1}, {5, 2}, {6, 2}, {7, 0}, {8, 1}}, {0, 1, 2}, -0.5f, 0.5f},
              rng, 10, 20, 0.6f, 2, &div);
    for (int mode = 15; mode <= 18; ++mode)
        for (int variant = 0; variant < 3; ++variant) {
            pbc::Case c{"mix hsv blend " + std::to_string(mode) + " v" + std::to_string(variant),
                      kOpMix, mode, variant == 2 ? 3 : 1, 0, 0, 0, {0.6f, 0, 0, 0, 0, 0, 0.9f, 0.2f, 0.5f},
                      {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}, 0.5f, 1.5f};
            if (variant >= 1) c.pos.insert(c.pos.end(), {{6, 2}, {7, 0}, {8, 1}});
            if (variant == 2) c.pos.push_back({0, 1});
            pbc::check(c, rng, 25, 150, 0.3f, 1, &hsv);
        }
    pbc::check({"mix hsv blend negative a", kOpMix, 16, 1, 0, 0, 0,
                {0.6f, 0, 0, 0, 0, 0, 0.9f, 0.2f, 0.5f}, {{3, 0}, {4, 1}, {5, 2}}, {0, 1, 2}, -2.0f,
                -1.0f},
               rng, 5, 10, 0.3f, 0, &hsv);
    std::printf("control: divide %d of %d boxes, hsv blends %d of %d boxes have samples outside "
                "the inner half's bound\n", div.exceeded, div.boxes, hsv.exceeded, hsv.boxes);
    EXPECT_GT(div.exceeded, div.boxes / 2);
    EXPECT_GT(hsv.exceeded, hsv.boxes / 4);
}

// Vector Math (in: a(3) b(3) c(3) scale): project (6), reflect (7), refract (8, the scale its
// IOR), a the position, b constant or the position permuted.
TEST(ProgramBoundRules2, VectorProjectReflectRefractInsideRandomBoxes) {
    std::mt19937 rng(47);
    pbc::Tally t;
    t.control_channels = 3;
    for (int mode : {6, 7, 8})
        for (int bpos = 0; bpos < 2; ++bpos)
            for (float scale : {0.67f, 1.5f}) {
                if (mode != 8 && scale != 0.67f) continue;
                pbc::Case c{"vector math " + std::to_string(mode) + (bpos ? " b(p)" : "") +
                              " s " + std::to_string(scale),
                          kOpVectorMath, mode, 0, 0, 0, 0,
                          {0, 0, 0, 0.7f, -1.3f, 2.1f, 0.4f, 0.2f, -0.9f, scale},
                          {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}};
                if (bpos) c.pos.insert(c.pos.end(), {{3, 2}, {4, 0}, {5, 1}});
                pbc::check(c, rng, 25, 200, 0.6f, 1, &t);
            }
    // b = 0: project gives 0, reflect a
    pbc::check({"project b = 0", kOpVectorMath, 6, 0, 0, 0, 0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 1},
               {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}}, rng, 10, 50, 0.6f, 1, &t);
    // the bound is a radius (|a|, or refract's), loose per component where the vector is not
    // along an axis: the inner half's bound is left in fewer boxes than the other rules'
    std::printf("control: %d of %d boxes have samples outside the inner half's bound\n",
                t.exceeded, t.boxes);
    EXPECT_GT(t.exceeded, t.boxes / 8);
}
