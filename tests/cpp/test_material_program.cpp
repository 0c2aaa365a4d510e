// Node-graph programs (scene/material_program.h): the arithmetic against Blender's documented
// conventions, the register machine, constant folding at load, bad programs rejected with a
// message, and material_at applying a program at a hit (and nothing for a plain material).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "bsdf/material.h"
#include "scene/material_program_host.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

uint32_t w0(int op, int mode = 0, int flags = 0, int dim = 0) {
    return uint32_t(op) | (uint32_t(mode) << 8) | (uint32_t(flags) << 16) | (uint32_t(dim) << 24);
}
uint32_t w1(int in, int out) { return uint32_t(in) | (uint32_t(out) << 16); }

// A plane (two triangles) of material 0 whose base colour is program `code` over `consts`.
SceneInput plane_with_program(std::vector<uint32_t> code, std::vector<float> consts,
                              int num_const, int result, int target = kTargetBaseColor) {
    SceneInput in;
    in.width = in.height = 4;
    MaterialInput m;
    m.name = "graph";
    m.program_first = 0;
    m.program_count = 1;
    in.materials.push_back(m);
    MeshInput mesh;
    mesh.name = "plane";
    mesh.positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    mesh.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    mesh.material_ids = {0, 0};
    in.meshes.push_back(mesh);
    in.program_code = std::move(code);
    in.program_consts = std::move(consts);
    in.programs = {0, uint32_t(in.program_code.size() / 4), 0, uint32_t(num_const),
                   uint32_t(target), uint32_t(result)};
    return in;
}

ShadePoint point_at(Vec3 p, Vec2 st) {
    ShadePoint sp{};
    sp.p = p;
    sp.n = sp.ng = sp.wo = Vec3{0, 0, 1};
    sp.st = st;
    sp.tri = 0;
    sp.bary = Vec2{0.25f, 0.25f};
    return sp;
}

}  // namespace

TEST(MaterialProgram, MathFollowsBlendersSafeConventions) {
    EXPECT_EQ(node_math(3, 1.0f, 0.0f, 0.0f), 0.0f);            // divide by 0
    EXPECT_EQ(node_math(5, -2.0f, 0.5f, 0.0f), 0.0f);           // pow of a negative, non-integer
    EXPECT_FLOAT_EQ(node_math(5, -2.0f, 3.0f, 0.0f), -8.0f);    // integer exponent is fine
    EXPECT_EQ(node_math(6, -1.0f, 2.0f, 0.0f), 0.0f);           // log of a negative
    EXPECT_EQ(node_math(7, -4.0f, 0.0f, 0.0f), 0.0f);           // sqrt of a negative
    EXPECT_FLOAT_EQ(node_math(25, -1.0f, 3.0f, 0.0f), 2.0f);    // floored modulo
    EXPECT_FLOAT_EQ(node_math(24, -1.0f, 3.0f, 0.0f), -1.0f);   // truncated modulo
    EXPECT_FLOAT_EQ(node_math(26, 5.5f, 2.0f, 0.0f), 1.5f);     // wrap into [0, 2)
    EXPECT_FLOAT_EQ(node_math(28, 3.0f, 2.0f, 0.0f), 1.0f);     // ping-pong
    EXPECT_FLOAT_EQ(node_math(27, 2.7f, 0.5f, 0.0f), 2.5f);     // snap
    EXPECT_FLOAT_EQ(node_math(16, 1.0f, 1.05f, 0.1f), 1.0f);    // compare within epsilon
    EXPECT_NEAR(node_math(17, 1.0f, 1.0f, 1.0f), 1.0f - 1.0f / 6.0f, 1e-6f);  // smooth min
    EXPECT_FLOAT_EQ(node_math(32, 2.0f, 0.0f, 0.0f), 0.5f * kPi);  // arcsine clamps
    for (int op = 0; op <= 40; ++op)
        EXPECT_FALSE(std::isnan(node_math(op, 0.3f, 0.7f, 0.2f))) << "op " << op;
}

// Power and Logarithm at zero as Cycles gives them (bpy 5.0.1, difftest D35): 0 to a negative
// power is 0 at render time, +inf where Cycles folds constant inputs on the host (an
// instruction fold_program marks kInstrConstant); log base 1 is 0 (a safe division).
TEST(MaterialProgram, PowerOfZeroAsCyclesRendersAndFolds) {
    EXPECT_EQ(node_math(5, 0.0f, -1.0f, 0.0f), 0.0f);
    EXPECT_EQ(node_math(5, 0.0f, -0.5f, 0.0f), 0.0f);
    EXPECT_EQ(node_math(5, 0.0f, 0.0f, 0.0f), 1.0f);
    EXPECT_EQ(node_math(5, 0.0f, 2.0f, 0.0f), 0.0f);
    EXPECT_EQ(node_math(6, 0.5f, 1.0f, 0.0f), 0.0f);
    EXPECT_EQ(node_math(6, 1.0f, 1.0f, 0.0f), 0.0f);
    float v;
    const Vec3 r = node_vector_math(27, Vec3{0, 2, 0}, Vec3{-1, -1, 0}, Vec3{}, 0.0f, &v);
    EXPECT_EQ(r.x, 0.0f);
    EXPECT_FLOAT_EQ(r.y, 0.5f);
    EXPECT_EQ(r.z, 1.0f);
    SceneView view{};
    ShadePoint sp{};
    for (uint8_t flags : {uint8_t(0), kInstrConstant}) {
        float regs[16] = {0.0f, -1.0f, 0.0f};
        NodeInstr n{kOpMath, 5, flags, 1, 0, 4, 0, 0};
        program_step(view, sp, n, regs);
        EXPECT_EQ(regs[4], flags ? INFINITY : 0.0f);
        float vregs[16] = {0, 0, 3, -1, -2, -1};
        NodeInstr vn{kOpVectorMath, 27, flags, 3, 0, 10, 0, 0};
        program_step(view, sp, vn, vregs);
        EXPECT_EQ(vregs[10], flags ? INFINITY : 0.0f);
        EXPECT_EQ(vregs[11], flags ? INFINITY : 0.0f);
        EXPECT_FLOAT_EQ(vregs[12], 1.0f / 3.0f);
    }
}

TEST(MaterialProgram, VectorMathAndMapRange) {
    float v;
    Vec3 r = node_vector_math(6, Vec3{1, 1, 0}, Vec3{2, 0, 0}, Vec3{}, 0.0f, &v);  // project
    EXPECT_FLOAT_EQ(r.x, 1.0f);
    EXPECT_FLOAT_EQ(r.y, 0.0f);
    r = node_vector_math(7, Vec3{1, -1, 0}, Vec3{0, 2, 0}, Vec3{}, 0.0f, &v);      // reflect
    EXPECT_FLOAT_EQ(r.y, 1.0f);
    node_vector_math(11, Vec3{0, 0, 0}, Vec3{3, 4, 0}, Vec3{}, 0.0f, &v);          // distance
    EXPECT_FLOAT_EQ(v, 5.0f);
    r = node_vector_math(14, Vec3{}, Vec3{}, Vec3{}, 0.0f, &v);                    // normalize 0
    EXPECT_EQ(r.x + r.y + r.z, 0.0f);
    EXPECT_FLOAT_EQ(node_map_range(0, true, 2.0f, 0, 1, 0, 10, 0), 10.0f);         // clamped
    EXPECT_FLOAT_EQ(node_map_range(0, false, 2.0f, 0, 1, 0, 10, 0), 20.0f);
    EXPECT_FLOAT_EQ(node_map_range(1, false, 0.6f, 0, 1, 0, 1, 4), 0.75f);         // stepped
    EXPECT_FLOAT_EQ(node_map_range(2, false, 0.5f, 0, 1, 0, 1, 0), 0.5f);          // smoothstep
    EXPECT_FLOAT_EQ(node_map_range(0, false, 1.0f, 1, 1, 0, 1, 0), 0.0f);          // empty range
}

TEST(MaterialProgram, ColourConversionsAndBlendModes) {
    const Vec3 c{0.2f, 0.6f, 0.4f};
    const Vec3 h = hsv_to_rgb(rgb_to_hsv(c));
    EXPECT_NEAR(h.x, c.x, 1e-6f);
    EXPECT_NEAR(h.y, c.y, 1e-6f);
    EXPECT_NEAR(h.z, c.z, 1e-6f);
    const Vec3 l = hsl_to_rgb(rgb_to_hsl(c));
    EXPECT_NEAR(l.x, c.x, 1e-6f);
    EXPECT_NEAR(l.z, c.z, 1e-6f);
    const Vec3 b{0.9f, 0.1f, 0.5f};
    for (int mode = 0; mode < 19; ++mode) {  // factor 0 leaves A (all modes but the HSV ones
        const Vec3 r = node_blend(mode, 0.0f, c, b);  // round-trip through HSV)
        EXPECT_NEAR(r.x, c.x, 1e-5f) << "mode " << mode;
        EXPECT_NEAR(r.y, c.y, 1e-5f) << "mode " << mode;
    }
    const Vec3 mul = node_blend(2, 1.0f, c, b);
    EXPECT_FLOAT_EQ(mul.x, c.x * b.x);
    const Vec3 scr = node_blend(5, 1.0f, c, b);
    EXPECT_FLOAT_EQ(scr.y, 1.0f - (1.0f - c.y) * (1.0f - b.y));
}

TEST(MaterialProgram, NoiseIsSmoothBoundedAndDeterministic) {
    NoiseParams n{2.0f, 0.5f, 2.0f, 0.0f, 1.0f, kNoiseFbm, 1};
    float lo = 1e9f, hi = -1e9f;
    for (int i = 0; i < 2000; ++i) {
        const float p[3] = {0.37f * float(i), 0.11f * float(i % 17), 1.3f};
        const float v = noise_fractal(p, 3, n);
        lo = ::fminf(lo, v);
        hi = ::fmaxf(hi, v);
        EXPECT_EQ(v, noise_fractal(p, 3, n));
    }
    EXPECT_GE(lo, 0.0f);
    EXPECT_LE(hi, 1.0f);
    EXPECT_LT(lo, 0.35f);   // it varies
    EXPECT_GT(hi, 0.65f);
    const float a[3] = {0.5f, 0.5f, 0.5f}, b[3] = {0.5001f, 0.5f, 0.5f};
    EXPECT_NEAR(noise_fractal(a, 3, n), noise_fractal(b, 3, n), 1e-3f);  // continuous
    const float huge[3] = {1e30f, -1e30f, 3e38f};
    EXPECT_TRUE(std::isfinite(noise_fractal(huge, 3, n)));
}

TEST(MaterialProgram, ProgramDrivesBaseColourAtTheHit) {
    // base colour = checker(uv * 1, white, black, scale 2)
    // registers: 0..2 color1, 3..5 color2, 6 scale; then input uv -> 8, checker block 12..
    std::vector<float> consts(7, 0.0f);
    consts[0] = consts[1] = consts[2] = 1.0f;
    consts[6] = 2.0f;
    std::vector<uint32_t> code = {
        w0(kOpInput, 2), w1(0, 8), 0, 0,               // uv -> r8
        w0(kOpCopy, 0, 0, 3), w1(8, 12), 0, 0,         // vector into the checker block
        w0(kOpCopy, 0, 0, 3), w1(0, 15), 0, 0,         // color1
        w0(kOpCopy, 0, 0, 3), w1(3, 18), 0, 0,         // color2
        w0(kOpCopy, 0, 0, 1), w1(6, 21), 0, 0,         // scale
        w0(kOpChecker), w1(12, 24), 0, 0,
    };
    HostScene hs(plane_with_program(code, consts, 7, 24));
    const SceneView& s = hs.view();
    EXPECT_TRUE(s.material_bits & kScenePrograms);
    EXPECT_TRUE(s.materials[0].tex_flags & kTexProgram);
    EXPECT_GT(s.programs[0].num_instr, 0);
    EXPECT_LT(s.programs[0].num_instr, 6);  // the copies of constants were folded
    MaterialScratch scratch;
    // Blender's checker: the cell at the origin takes Color2, its x neighbour Color1
    const Material& a = material_at(s, 0, point_at(Vec3{}, Vec2{0.25f, 0.25f}), scratch);
    EXPECT_FLOAT_EQ(a.base_color.x, 0.0f);
    MaterialScratch scratch2;
    const Material& b = material_at(s, 0, point_at(Vec3{}, Vec2{0.75f, 0.25f}), scratch2);
    EXPECT_FLOAT_EQ(b.base_color.x, 1.0f);
}

// A mix keeps its textured leaves' resolved inputs, not copies of them (MaterialScratch);
// mix_leaf_at must give, byte for byte, the copy that resolving the leaf alone gives, and the
// scene's own leaf (no copy) for an untextured one.
TEST(MaterialProgram, MixLeavesResolveAsTheLeafAlone) {
    std::vector<float> consts(7, 0.0f);
    consts[0] = consts[1] = consts[2] = 1.0f;
    consts[6] = 2.0f;
    std::vector<uint32_t> code = {
        w0(kOpInput, 2), w1(0, 8), 0, 0,               // uv -> r8
        w0(kOpCopy, 0, 0, 3), w1(8, 12), 0, 0,         // vector into the checker block
        w0(kOpCopy, 0, 0, 3), w1(0, 15), 0, 0,         // color1
        w0(kOpCopy, 0, 0, 3), w1(3, 18), 0, 0,         // color2
        w0(kOpCopy, 0, 0, 1), w1(6, 21), 0, 0,         // scale
        w0(kOpChecker), w1(12, 24), 0, 0,
    };
    SceneInput in = plane_with_program(code, consts, 7, 24);
    in.materials[0].type = "principled";
    in.materials[0].metallic = 0.5f;
    MaterialInput plain;
    plain.name = "plain";
    plain.type = "conductor";
    MaterialInput mix;
    mix.name = "mix";
    mix.type = "mix";
    mix.mix_children = {1, 0};
    mix.mix_weights = {0.25f, 0.75f};
    in.materials.push_back(plain);
    in.materials.push_back(mix);
    in.meshes[0].material_ids = {2, 2};
    HostScene hs(in);
    const SceneView& s = hs.view();
    for (Vec2 st : {Vec2{0.25f, 0.25f}, Vec2{0.75f, 0.25f}}) {
        const ShadePoint sp = point_at(Vec3{}, st);
        MaterialScratch scratch, alone;
        const Material& m = material_at(s, 2, sp, scratch);
        ASSERT_EQ(m.type, uint32_t(kMaterialMix));
        ASSERT_EQ(m.mix_count, 2);
        Material tmp;
        EXPECT_EQ(&mix_leaf_at(m, 0, tmp), &s.materials[1]);  // untextured: the scene's
        const Material& leaf = mix_leaf_at(m, 1, tmp);
        EXPECT_EQ(&leaf, &tmp);
        const Material& ref = material_resolve_leaf(s, s.materials[0], sp, alone.m);
        ASSERT_EQ(&ref, &alone.m);
        // field by field, not memcmp over the struct: its padding bytes are whatever the stack
        // held (under ctest they differed); programs write only the inputs, the rest is a copy
        auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; };
        EXPECT_TRUE(same(leaf.base_color, ref.base_color));
        EXPECT_TRUE(same(leaf.emission, ref.emission));
        EXPECT_TRUE(same(leaf.fms_metal, ref.fms_metal));
        EXPECT_TRUE(same(leaf.roughness, ref.roughness));
        EXPECT_TRUE(same(leaf.metallic, ref.metallic));
        EXPECT_TRUE(same(leaf.mix_weight, ref.mix_weight));
        EXPECT_EQ(leaf.type, ref.type);
        EXPECT_EQ(leaf.tex_flags, ref.tex_flags);
        EXPECT_TRUE(same(leaf.metal_favg0, ref.metal_favg0));
        EXPECT_EQ(leaf.tables, ref.tables);
        // the checker's cells: Color2 (0) at the origin's, Color1 (1) at its x neighbour's
        EXPECT_FLOAT_EQ(leaf.base_color.x, st.x < 0.5f ? 0.0f : 1.0f);
        EXPECT_FLOAT_EQ(s.materials[0].base_color.x, 0.8f);  // the scene's leaf unchanged
    }
}

TEST(MaterialProgram, ConstantProgramFoldsIntoTheMaterial) {
    // roughness = 0.2 + 0.3: no instruction left, no program at hits
    std::vector<float> consts = {0.2f, 0.3f, 0.0f};
    std::vector<uint32_t> code = {w0(kOpMath, 0), w1(0, 4), 0, 0,
                                  w0(kOpCopy, 0, 0, 1), w1(4, 5), 0, 0,
                                  w0(kOpCopy, 0, 0, 1), w1(4, 6), 0, 0};
    HostScene hs(plane_with_program(code, consts, 3, 4, kTargetRoughness));
    const Material& m = hs.view().materials[0];
    EXPECT_FALSE(m.tex_flags & kTexProgram);
    EXPECT_EQ(m.prog_count, 0);
    EXPECT_FLOAT_EQ(m.roughness, 0.5f);
}

TEST(MaterialProgram, NaNAndHugeValuesStayFinite) {
    // base colour = uv / 0 * inf: every register non-finite, the material's inputs finite
    std::vector<float> consts = {0.0f, 0.0f, 0.0f, 3e38f};
    std::vector<uint32_t> code = {
        w0(kOpInput, 2), w1(0, 8), 0, 0,
        w0(kOpCopy, 0, 0, 3), w1(8, 12), 0, 0,
        w0(kOpCopy, 0, 0, 3), w1(0, 15), 0, 0,
        w0(kOpVectorMath, 3), w1(12, 24), 0, 0,      // uv / 0 -> 0 (safe divide)
        w0(kOpCopy, 0, 0, 1), w1(3, 40), 0, 0,
        w0(kOpCopy, 0, 0, 1), w1(3, 41), 0, 0,
        w0(kOpMath, 2), w1(40, 44), 0, 0,            // 3e38 * 3e38 = inf
        w0(kOpCopy, 0, 0, 1), w1(44, 50), 0, 0,
        w0(kOpCopy, 0, 0, 1), w1(44, 51), 0, 0,
        w0(kOpCopy, 0, 0, 1), w1(44, 52), 0, 0,
    };
    HostScene hs(plane_with_program(code, consts, 4, 50));
    MaterialScratch scratch;
    const Material& m = material_at(hs.view(), 0, point_at(Vec3{}, Vec2{0.5f, 0.5f}), scratch);
    EXPECT_TRUE(is_finite(m.base_color));
    EXPECT_LE(max_component(m.base_color), 1.0f);
    EXPECT_GE(m.base_color.x, 0.0f);
}

TEST(MaterialProgram, BadProgramsAreErrorsNamingTheProblem) {
    auto expect_error = [](SceneInput in, const char* what) {
        try {
            HostScene hs(in);
            FAIL() << "accepted: " << what;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    expect_error(plane_with_program({250, 0, 0, 0}, {}, 0, 0), "unknown op");
    expect_error(plane_with_program({w0(kOpMath), w1(190, 0), 0, 0}, {}, 0, 0), "registers");
    expect_error(plane_with_program({w0(kOpRamp), w1(0, 4), 0, 256}, {0, 0, 0}, 3, 4), "table");
    SceneInput in = plane_with_program({}, {}, 0, 0);
    in.programs[4] = 99;  // target
    expect_error(in, "out of range");
    in = plane_with_program({}, {}, 0, 0);
    in.materials[0].program_count = 5;
    expect_error(in, "node programs out of range");
}

TEST(MaterialProgram, PlainMaterialsRunNoProgram) {
    SceneInput in = plane_with_program({}, {}, 0, 0);
    in.materials[0].program_count = 0;
    in.programs.clear();
    HostScene hs(in);
    EXPECT_FALSE(hs.view().material_bits & kScenePrograms);
    MaterialScratch scratch;
    const Material& m = material_at(hs.view(), 0, point_at(Vec3{}, Vec2{}), scratch);
    EXPECT_EQ(&m, &hs.view().materials[0]);   // no copy, no evaluation
}

namespace {

// A bump program on the plane: height = dot(position, (k, 0, 0)), result (height, strength,
// distance).
SceneInput plane_with_bump(float k, float strength, float distance) {
    std::vector<float> consts = {k, 0, 0, 0, 0, 0, 0, strength, distance};
    std::vector<uint32_t> code = {
        w0(kOpInput, 0), w1(0, 10), 0, 0,               // position -> r10
        w0(kOpCopy, 0, 0, 3), w1(10, 20), 0, 0,
        w0(kOpCopy, 0, 0, 3), w1(0, 23), 0, 0,
        w0(kOpCopy, 0, 0, 3), w1(3, 26), 0, 0,
        w0(kOpCopy, 0, 0, 1), w1(6, 29), 0, 0,
        w0(kOpVectorMath, 10), w1(20, 32), 0, 0,       // dot -> r35
        w0(kOpCopy, 0, 0, 1), w1(35, 40), 0, 0,
        w0(kOpCopy, 0, 0, 1), w1(7, 41), 0, 0,
        w0(kOpCopy, 0, 0, 1), w1(8, 42), 0, 0,
    };
    return plane_with_program(code, consts, 9, 40, kTargetBump);
}

Vec3 bumped(const SceneInput& in) {
    HostScene hs(in);
    const SceneView& s = hs.view();
    return program_bump(s, s.materials[0], 0, Vec2{0.25f, 0.25f}, Vec3{0, 0, 1},
                        Vec3{0, 0, 1});
}

}  // namespace

TEST(MaterialProgram, BumpBendsTheNormalAgainstTheHeightGradient) {
    {
        HostScene hs(plane_with_bump(0.5f, 1.0f, 1.0f));
        const SceneView& s = hs.view();
        EXPECT_TRUE(s.materials[0].tex_flags & kTexBump);
        EXPECT_TRUE(s.material_bits & kSceneFrames);   // pt_surface_frames runs it
    }
    // n' = normalize(n - distance * grad h): grad h = (0.5, 0, 0)
    const Vec3 want = normalize(Vec3{-0.5f, 0.0f, 1.0f});
    const Vec3 n = bumped(plane_with_bump(0.5f, 1.0f, 1.0f));
    EXPECT_NEAR(n.x, want.x, 1e-3f);
    EXPECT_NEAR(n.y, 0.0f, 1e-3f);
    EXPECT_NEAR(n.z, want.z, 1e-3f);
    const Vec3 inv = bumped(plane_with_bump(0.5f, 1.0f, -1.0f));   // Invert: the other way
    EXPECT_NEAR(inv.x, -want.x, 1e-3f);
    const Vec3 none = bumped(plane_with_bump(0.5f, 0.0f, 1.0f));   // strength 0: unchanged
    EXPECT_NEAR(none.z, 1.0f, 1e-6f);
    const Vec3 half = bumped(plane_with_bump(0.5f, 0.5f, 1.0f));   // a blend of the two
    EXPECT_NEAR(half.x, normalize(want * 0.5f + Vec3{0, 0, 0.5f}).x, 1e-3f);
    // a height too steep to face the viewer's side keeps the normal (as normal maps do)
    const Vec3 steep = bumped(plane_with_bump(1e6f, 1.0f, 1.0f));
    EXPECT_TRUE(is_finite(steep));
    EXPECT_GT(steep.z, 0.0f);
}

TEST(MaterialProgram, ConstantHeightBendsNothingAndRunsNoProgram) {
    HostScene hs(plane_with_bump(0.0f, 1.0f, 1.0f));   // dot with 0: folds to a constant?
    // (position is read per hit, so only the value is constant: the program stays, and the
    // normal does not move)
    const SceneView& s = hs.view();
    const Vec3 n = program_bump(s, s.materials[0], 0, Vec2{0.25f, 0.25f}, Vec3{0, 0, 1},
                                Vec3{0, 0, 1});
    EXPECT_NEAR(n.z, 1.0f, 1e-6f);
    std::vector<float> consts = {0.3f, 1.0f, 1.0f};   // height, strength, distance constants
    HostScene hc(plane_with_program({}, consts, 3, 0, kTargetBump));
    EXPECT_FALSE(hc.view().materials[0].tex_flags & kTexBump);
    EXPECT_FALSE(hc.view().material_bits & kSceneFrames);
}

TEST(MaterialProgram, BrickFollowsItsDefinition) {
    float tint = -1.0f;
    // inside a brick, far from its edges: no mortar; on an edge: all mortar
    EXPECT_EQ(node_brick(Vec3{0.2f, 0.1f, 0}, 0.02f, 0.1f, 0, 0.5f, 0.25f, 0.5f, 2, 1, 2, &tint),
              0.0f);
    EXPECT_GE(tint, 0.0f);
    EXPECT_LE(tint, 1.0f);
    EXPECT_EQ(node_brick(Vec3{0.2f, 0.001f, 0}, 0.02f, 0.0f, 0, 0.5f, 0.25f, 0.5f, 2, 1, 2, &tint),
              1.0f);
    // every other row (row 0, 2, ...) is shifted by offset x width = 0.25: its bricks end at
    // x = 0.25, where row 1's bricks are whole
    const float a = node_brick(Vec3{0.24f, 0.1f, 0}, 0.02f, 0.0f, 0, 0.5f, 0.25f, 0.5f, 2, 1, 2,
                               &tint);
    const float b = node_brick(Vec3{0.24f, 0.35f, 0}, 0.02f, 0.0f, 0, 0.5f, 0.25f, 0.5f, 2, 1,
                               2, &tint);
    EXPECT_EQ(a, 1.0f);
    EXPECT_EQ(b, 0.0f);
    // bricks of no or negative width or height: all mortar wherever mortar_size > 0, as
    // Cycles' arithmetic gives (difftest D36; was all brick); huge coordinates: finite
    EXPECT_EQ(node_brick(Vec3{1, 1, 0}, 0.02f, 0.1f, 0, 0.0f, 0.25f, 0.5f, 2, 1, 2, &tint), 1.0f);
    EXPECT_TRUE(std::isfinite(tint));
    EXPECT_EQ(node_brick(Vec3{0, 0, 0}, 0.02f, 0.1f, 0, 0.0f, 0.25f, 0.5f, 2, 1, 2, &tint), 1.0f);
    EXPECT_EQ(node_brick(Vec3{0.3f, 1, 0}, 0.02f, 0.0f, 0, 0.5f, 0.0f, 0.5f, 2, 1, 2, &tint),
              1.0f);
    EXPECT_EQ(node_brick(Vec3{0.3f, 1, 0}, 0.02f, 0.0f, 0, -0.4f, 0.25f, 0.5f, 2, 1, 2, &tint),
              1.0f);
    const float h = node_brick(Vec3{3e30f, -3e30f, 0}, 0.02f, 0.1f, 0, 0.5f, 0.25f, 0.5f, 2, 1, 2,
                               &tint);
    EXPECT_TRUE(std::isfinite(h) && std::isfinite(tint));
}

TEST(MaterialProgram, EvaluatesOutsideAScene) {
    // position.x * 2 at two points; a bad op is an error naming the instruction
    std::vector<float> consts = {2.0f, 0.0f};
    std::vector<uint32_t> code = {w0(kOpInput, 0), w1(0, 4), 0, 0,
                                  w0(kOpCopy, 0, 0, 1), w1(4, 8), 0, 0,
                                  w0(kOpCopy, 0, 0, 1), w1(0, 9), 0, 0,
                                  w0(kOpCopy, 0, 0, 1), w1(1, 10), 0, 0,
                                  w0(kOpMath, 2), w1(8, 12), 0, 0};
    const std::vector<float> out =
        evaluate_program(code, consts, 2, 12, {1, 0, 0, -3, 0, 0}, {0, 0, 1, 0, 0, 1});
    ASSERT_EQ(out.size(), 6u);
    EXPECT_FLOAT_EQ(out[0], 2.0f);
    EXPECT_FLOAT_EQ(out[3], -6.0f);
    EXPECT_THROW(evaluate_program({250, 0, 0, 0}, {}, 0, 0, {0, 0, 0}, {0, 0, 1}),
                 std::invalid_argument);
    EXPECT_THROW(evaluate_program(code, consts, 2, 12, {0, 0}, {0, 0}), std::invalid_argument);
}

// Box projection (Image Texture, Box): the side weights partition 1, blend 0 picks one side,
// and with a blend they change continuously over the sphere of normals (no seam).
TEST(MaterialProgram, BoxProjectionWeightsPartitionAndBlendWithoutSeams) {
    EXPECT_EQ(image_box_weights(Vec3{-1.0f, 0.0f, 0.0f}, 0.3f).x, 1.0f);
    EXPECT_EQ(image_box_weights(Vec3{0.1f, -0.9f, 0.2f}, 0.0f).y, 1.0f);
    EXPECT_EQ(image_box_weights(Vec3{0.0f, 0.0f, 0.0f}, 0.3f).z, 1.0f);  // degenerate: a side
    for (float blend : {0.0f, 0.15f, 0.5f, 1.0f}) {
        Vec3 prev{};
        for (int i = 0; i <= 4000; ++i) {  // a path over the sphere through every region
            const float t = float(i) / 4000.0f * 6.2831853f;
            const Vec3 n{cosf(t) * cosf(0.4f * t), sinf(t) * cosf(0.4f * t), sinf(0.4f * t)};
            const Vec3 w = image_box_weights(n, blend);
            EXPECT_GE(::fminf(w.x, ::fminf(w.y, w.z)), 0.0f);
            EXPECT_NEAR(w.x + w.y + w.z, 1.0f, 1e-5f);
            if (blend == 0.0f) EXPECT_EQ(::fmaxf(w.x, ::fmaxf(w.y, w.z)), 1.0f);
            if (blend > 0.0f && i > 0) {  // steps of 1.6e-3 rad move a weight by far less than 0.05
                EXPECT_LT(fabsf(w.x - prev.x) + fabsf(w.y - prev.y) + fabsf(w.z - prev.z),
                          0.05f)
                    << "blend " << blend << " at t " << t;
            }
            prev = w;
        }
    }
    // the side facing -x reads its image mirrored, so that it reads the same way round the box
    const Vec3 co{0.2f, 0.3f, 0.7f};
    EXPECT_FLOAT_EQ(image_box_uv(0, co, Vec3{1.0f, 0.0f, 0.0f}).x, 0.3f);
    EXPECT_FLOAT_EQ(image_box_uv(0, co, Vec3{-1.0f, 0.0f, 0.0f}).x, 0.7f);
}
