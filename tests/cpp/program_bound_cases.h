// The harness of the interval rules' tests (test_program_bound_rules.cpp,
// test_program_bound_rules2.cpp, test_program_bound_image.cpp; scene/program_bound.h): one op
// fed by constants and the position's components, dense samples of the program (program_run)
// in random boxes, none outside the interval program_bound gives for the box. The control: a
// bound shrunk to the box's inner half is left by the outer box's samples in a share of the
// boxes (the rules are not loose by that much). Named (not anonymous) and inline: the test
// files share it in one unity batch.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scene/medium_hetero.h"
#include "scene/program_bound.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

namespace lantern {
namespace pbc {

inline void instr(std::vector<uint32_t>& code, int op, int mode, int flags, int dim, int in,
                  int out, int aux = 0, int aux2 = 0) {
    code.insert(code.end(), {uint32_t(op | (mode << 8) | (flags << 16) | (dim << 24)),
                             uint32_t(in | (out << 16)), uint32_t(aux), uint32_t(aux2)});
}

// One op under test: its inputs the constants `in`, except the slots fed by the position's
// components (slot, component); outs: which of its outputs are the program's result.
struct Case {
    std::string name;
    int op, mode, flags, dim, aux, aux2;
    std::vector<float> in;
    std::vector<std::pair<int, int>> pos;
    int outs[3];
    float clo = -2.0f, chi = 3.0f;       // where the boxes' centres lie (per axis)
    std::vector<TextureInput> textures;  // the scene's (an Image Texture's aux indexes them)
};

inline SceneInput scene(const Case& t) {
    SceneInput in;
    std::vector<float> c = {0, 0, 0, 0, 0, 0, 0, 0};
    c.insert(c.end(), t.in.begin(), t.in.end());  // from 8
    std::vector<uint32_t> code;
    instr(code, kOpInput, 0, 0, 0, 0, 40);  // position 40..42
    for (size_t k = 0; k < t.in.size(); k += 3)
        instr(code, kOpCopy, 0, 0, int(std::min<size_t>(3, t.in.size() - k)), 8 + int(k),
              50 + int(k));
    for (const auto& [slot, comp] : t.pos) instr(code, kOpCopy, 0, 0, 1, 40 + comp, 50 + slot);
    instr(code, t.op, t.mode, t.flags, t.dim, 50, 80, t.aux, t.aux2);
    for (int k = 0; k < 3; ++k) instr(code, kOpCopy, 0, 0, 1, 80 + t.outs[k], 90 + k);
    in.program_code = code;
    in.program_consts = c;
    // a surface's base colour (a density would bound itself at the build: slower, and
    // program_bound needs no medium for a program of the position alone)
    in.programs = {
        0u, uint32_t(code.size() / 4), 0u, uint32_t(c.size()), uint32_t(kTargetBaseColor), 90u};
    in.textures = t.textures;
    MaterialInput mat;
    mat.name = "rules";
    mat.program_first = 0;
    mat.program_count = 1;
    in.materials.push_back(mat);
    in.meshes.push_back(lantern::test::box_mesh(vec3(0.0f), vec3(1.0f), 0));
    return in;
}

// The control's tally: boxes whose samples leave the bound of the box's inner half (in channel
// 0, or in any of the three where control_channels is 3), and channel 0's sampled range.
struct Tally {
    int boxes = 0, exceeded = 0;
    float vmin = 1e30f, vmax = -1e30f;
    int control_channels = 1;
};

// Samples of case t in random boxes (half-widths from 0.004 to `size`); every channel of
// every sample inside its box's interval. bounded: 1 every box has a bound, 0 none, 2 some (an
// op whose rule needs its inputs inside a range: the boxes where they are not fail). Returns
// the mean width of channel 0's intervals.
inline double check(const Case& t, std::mt19937& rng, int boxes, int samples, float size = 0.6f,
                    int bounded = 1, Tally* tally = nullptr) {
    HostScene scene_(scene(t));
    const SceneView& s = scene_.view();
    if (s.programs == nullptr) {
        ADD_FAILURE() << t.name << ": no program";
        return 0.0;
    }
    const MaterialProgram& p = s.programs[0];
    Tally own;
    if (!tally) tally = &own;
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    double width = 0.0;
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
        width += iv[0].hi - iv[0].lo;
        const bool inner_ok = program_bound(s, p, -1, c - h * 0.5f, c + h * 0.5f, inner);
        bool exceeded = false;
        for (int k = 0; k < samples; ++k) {
            Vec3 q = c - h + 2.0f * h * Vec3{u(rng), u(rng), u(rng)};
            if (k < 8)  // the corners too
                q = Vec3{k & 1 ? c.x + h.x : c.x - h.x, k & 2 ? c.y + h.y : c.y - h.y,
                         k & 4 ? c.z + h.z : c.z - h.z};
            const Vec3 v = program_run(s, p, medium_shade_point(-1, q, Vec3{1, 0, 0}));
            const float vv[3] = {v.x, v.y, v.z};
            tally->vmin = std::min(tally->vmin, vv[0]);
            tally->vmax = std::max(tally->vmax, vv[0]);
            for (int ch = 0; ch < 3; ++ch) {
                if (ch < tally->control_channels)
                    exceeded = exceeded ||
                               (inner_ok && !(vv[ch] >= inner[ch].lo && vv[ch] <= inner[ch].hi));
                if (!(vv[ch] >= iv[ch].lo && vv[ch] <= iv[ch].hi) && ++failures <= 3)
                    ADD_FAILURE() << t.name << " channel " << ch << ": " << vv[ch] << " outside ["
                                  << iv[ch].lo << ", " << iv[ch].hi << "] at (" << q.x << ", "
                                  << q.y << ", " << q.z << ")";
            }
        }
        ++tally->boxes;
        tally->exceeded += exceeded;
    }
    if (bounded == 2) EXPECT_GT(with_bound, 0) << t.name;
    return width / std::max(with_bound, 1);
}

}  // namespace pbc
}  // namespace lantern
