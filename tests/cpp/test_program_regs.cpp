// The device's register file for node programs, run on the CPU: program_step and program_run_on
// over a ProgramRegs (one thread's column of a buffer laid out [register][thread], as the CUDA
// renderer's SceneView::program_regs) give, bit for bit, what the host's float array gives, for
// every op in its modes, dims and flags, with several threads' programs interleaved instruction
// by instruction in one buffer, and no write outside a thread's own column.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "scene/material_program.h"
#include "scene/scene.h"

using namespace lantern;

namespace {

constexpr int kThreads = 5;  // programs interleaved in one buffer
constexpr int kStride = 8;   // columns in the buffer: 3 belong to no thread
constexpr int kTable = kProgramRegs;  // ramp and curve tables start after the preload

NodeInstr instr(int op, int mode, int flags, int dim, int in, int out, int aux = 0,
                int aux2 = 0) {
    NodeInstr n{};
    n.op = uint8_t(op);
    n.mode = uint8_t(mode);
    n.flags = uint8_t(flags);
    n.dim = uint8_t(dim);
    n.in = uint16_t(in);
    n.out = uint16_t(out);
    n.aux = aux;
    n.aux2 = aux2;
    return n;
}

// Every op of NodeOp, over its modes (and some past the last: the default cases), dims, flags
// and aux values, each reading registers at `in` and writing at `out` (callers pick them).
std::vector<NodeInstr> every_op(int in, int out) {
    std::vector<NodeInstr> v;
    auto add = [&](int op, int mode, int flags, int dim, int aux = 0, int aux2 = 0) {
        v.push_back(instr(op, mode, flags, dim, in, out, aux, aux2));
    };
    for (int dim = 1; dim <= 3; ++dim) add(kOpCopy, 0, 0, dim);
    for (int mode = 0; mode <= 10; ++mode) add(kOpInput, mode, 0, 0, mode == 4 ? 0 : 0);
    add(kOpInput, 4, 0, 0, 1);   // a second attribute channel
    add(kOpInput, 4, 0, 0, -1);  // none: zeros
    for (int mode = 0; mode <= 41; ++mode)
        for (int flags = 0; flags <= 1; ++flags) add(kOpMath, mode, flags, 0);
    for (int mode = 0; mode <= 30; ++mode) add(kOpVectorMath, mode, 0, 0);
    for (int mode = 0; mode <= 19; ++mode)
        for (int flags = 0; flags <= 7; ++flags) add(kOpMix, mode, flags, 0);
    for (int flags = 0; flags <= 7; ++flags) add(kOpMix, 255, flags, 0);
    for (int mode = 0; mode <= 4; ++mode)
        for (int flags = 0; flags <= 1; ++flags)
            for (int dim : {1, 3}) add(kOpMapRange, mode, flags, dim);
    for (int mode = 0; mode <= 2; ++mode) add(kOpClamp, mode, 0, 0);
    add(kOpInvert, 0, 0, 0);
    add(kOpGamma, 0, 0, 0);
    add(kOpBrightContrast, 0, 0, 0);
    add(kOpHsv, 0, 0, 0);
    for (int mode = 0; mode <= 2; ++mode) {
        add(kOpSeparate, mode, 0, 0);
        add(kOpCombine, mode, 0, 0);
    }
    add(kOpRgbToBw, 0, 0, 0);
    add(kOpChecker, 0, 0, 0);
    for (int mode = 0; mode <= 7; ++mode) add(kOpGradient, mode, 0, 0);
    for (int mode = 0; mode <= 5; ++mode)
        for (int dim = 1; dim <= 4; ++dim)
            for (int flags = 0; flags <= 3; ++flags) add(kOpNoise, mode, flags, dim);
    for (int dim = 1; dim <= 4; ++dim) add(kOpWhiteNoise, 0, 0, dim);
    for (int dim = 1; dim <= 4; ++dim)
        for (int mode = 0; mode <= 5; ++mode)
            for (int metric = 0; metric <= 3; ++metric) add(kOpVoronoi, mode, 0, dim, metric);
    for (int mode = 0; mode <= 1; ++mode)
        for (int dir = 0; dir <= 3; ++dir)
            for (int profile = 0; profile <= 2; ++profile)
                add(kOpWave, mode, 0, 0, dir, profile);
    for (int depth = 0; depth <= 4; ++depth) add(kOpMagic, 0, 0, 0, depth);
    for (int flags = 0; flags <= 1; ++flags) add(kOpRamp, 0, flags, 0, kTable, 4);
    for (int mode = 0; mode <= 1; ++mode) add(kOpCurves, mode, 0, 0, kTable, 4);
    add(kOpFresnel, 0, 0, 0);
    add(kOpLayerWeight, 0, 0, 0);
    for (int mode = 0; mode <= 3; ++mode) {
        add(kOpImage, mode, 0, 0, 0);   // the scene's texture
        add(kOpImage, mode, 0, 0, -1);  // missing: magenta
    }
    for (int mode = 0; mode <= 3; ++mode) add(kOpMapping, mode, 0, 0);
    add(kOpNormalize, 0, 0, 0);
    for (int aux = 1; aux <= 2; ++aux)
        for (int aux2 = 1; aux2 <= 2; ++aux2) add(kOpBrick, 0, 0, 0, aux, aux2);
    return v;
}

// A plane with a texture and two attribute channels: what kOpImage and kOpInput read.
SceneInput plane_scene() {
    SceneInput in;
    in.width = in.height = 4;
    MaterialInput m;
    m.name = "plain";
    in.materials.push_back(m);
    MeshInput mesh;
    mesh.name = "plane";
    mesh.positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    mesh.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    mesh.material_ids = {0, 0};
    mesh.attributes = {0.1f, 0.2f, 0.3f, 1, 2, 3,  0.4f, 0.5f, 0.6f, 4, 5, 6,
                       0.7f, 0.8f, 0.9f, 7, 8, 9,  1.0f, 1.1f, 1.2f, -1, -2, -3};
    in.meshes.push_back(mesh);
    in.num_attribute_channels = 2;
    TextureInput t;
    t.name = "tex";
    t.width = t.height = 2;
    t.bytes = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 255, 40, 90, 200, 10};
    in.textures.push_back(t);
    return in;
}

struct Threads {
    std::vector<ShadePoint> sp;
    std::vector<std::vector<float>> regs;  // each thread's registers at the start
};

Threads make_threads(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f), b(0.05f, 0.45f);
    Threads t;
    for (int k = 0; k < kThreads; ++k) {
        ShadePoint sp{};
        sp.p = Vec3{u(rng), u(rng), u(rng)};
        sp.n = normalize(Vec3{u(rng), u(rng), 1.0f});
        sp.ng = Vec3{0, 0, 1};
        sp.wo = normalize(Vec3{u(rng), u(rng), 1.5f});
        sp.st = Vec2{u(rng), u(rng)};
        sp.tri = k % 3 == 2 ? -1 : k % 2;
        sp.bary = Vec2{b(rng), b(rng)};
        sp.backfacing = k % 2 == 1;
        t.sp.push_back(sp);
        std::vector<float> r(kProgramRegs);
        for (float& x : r) x = u(rng);
        t.regs.push_back(r);
    }
    return t;
}

// The ramp's and the curves' tables (4 entries of r g b c; the curves' then lo hi).
std::vector<float> tables() {
    return {0.0f, 0.1f, 0.2f, 0.0f,  0.3f, 0.9f, 0.1f, 0.3f,  0.8f, 0.4f, 0.6f, 0.7f,
            1.0f, 1.0f, 0.5f, 1.0f,  -1.0f, 2.0f};
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// The same bits, where any NaN matches any NaN: a NaN's sign and payload are not specified
// (IEEE 754 leaves them to the implementation) and differ between two compilations of one
// expression (gcc's two instantiations of hsl_to_rgb give -nan and nan here).
bool same_value(float a, float b) { return (std::isnan(a) && std::isnan(b)) || same_bits(a, b); }

// Runs `code` on every thread twice: on its own float array (the host's register file) and on
// its column of one strided buffer, the threads taking turns instruction by instruction; every
// register of every thread must hold the same bits (NaN: same_value), the spare columns their
// sentinel. After each instruction both files' NaNs become one NaN, so that an op that hashes
// its inputs' bits (white noise) later reads the same bits in both.
void expect_same_registers(const SceneView& v, const std::vector<NodeInstr>& code,
                           const Threads& th, const char* what) {
    std::vector<float> buf(size_t(kProgramRegs) * kStride, -7.5f);
    std::vector<std::vector<float>> host = th.regs;
    for (int t = 0; t < kThreads; ++t)
        for (int j = 0; j < kProgramRegs; ++j) buf[size_t(j) * kStride + t] = th.regs[t][j];
    for (size_t i = 0; i < code.size(); ++i) {
        for (int t = 0; t < kThreads; ++t) {
            program_step(v, th.sp[t], code[i], host[t].data());
            program_step(v, th.sp[t], code[i], ProgramRegs{buf.data() + t, uint32_t(kStride)});
        }
        for (int t = 0; t < kThreads; ++t)
            for (int j = 0; j < kProgramRegs; ++j) {
                float& x = host[t][j];
                float& y = buf[size_t(j) * kStride + t];
                ASSERT_TRUE(same_value(x, y))
                    << what << ": instruction " << i << " (op " << int(code[i].op) << " mode "
                    << int(code[i].mode) << " flags " << int(code[i].flags) << " dim "
                    << int(code[i].dim) << "), thread " << t << ", register " << j << ": "
                    << x << " against " << y;
                if (std::isnan(x)) x = y = std::numeric_limits<float>::quiet_NaN();
            }
    }
    for (int j = 0; j < kProgramRegs; ++j)
        for (int t = kThreads; t < kStride; ++t)
            ASSERT_EQ(buf[size_t(j) * kStride + t], -7.5f) << "column " << t << " written";
}

}  // namespace

TEST(ProgramRegs, IndexesOneThreadsColumn) {
    float buf[4 * 3] = {};  // 4 registers of 3 threads; this is thread 1
    const ProgramRegs r{buf + 1, 3};
    r[0] = 5.0f;
    set3(r + 1, 0, Vec3{1, 2, 3});  // registers 1, 2, 3
    EXPECT_EQ(buf[0 * 3 + 1], 5.0f);
    EXPECT_EQ(buf[1 * 3 + 1], 1.0f);
    EXPECT_EQ(buf[2 * 3 + 1], 2.0f);
    EXPECT_EQ(buf[3 * 3 + 1], 3.0f);
    const Vec3 back = reg3(r, 1);
    EXPECT_EQ(back.x, 1.0f);
    EXPECT_EQ(back.z, 3.0f);
    EXPECT_EQ((r + 2)[1], 3.0f);
    for (int k : {0, 2, 3, 5, 6, 8, 9, 11}) EXPECT_EQ(buf[k], 0.0f) << k;  // other columns
}

// Each op alone, reading and writing blocks that overlap nowhere (in 0.., out 100..) and,
// again, where its output block starts inside its input block (in 0, out 2: the compiler
// reuses spent registers).
TEST(ProgramRegs, EveryOpGivesTheHostsBitsOnAStridedRegisterFile) {
    HostScene hs(plane_scene());
    SceneView v = hs.view();
    ASSERT_EQ(v.num_textures, 1);
    ASSERT_EQ(v.num_attribute_channels, 2);
    std::vector<float> consts(size_t(kProgramRegs), 0.0f);
    const std::vector<float> tab = tables();
    consts.insert(consts.end(), tab.begin(), tab.end());
    v.program_consts = consts.data();
    const Threads th = make_threads(13);
    const std::vector<NodeInstr> apart = every_op(0, 100);
    EXPECT_GT(apart.size(), 500u);
    for (const NodeInstr& n : apart) expect_same_registers(v, {n}, th, "apart");
    for (const NodeInstr& n : every_op(0, 2)) expect_same_registers(v, {n}, th, "overlapping");
}

// All ops in one program whose blocks move through the register file, so that each reads what
// earlier ones wrote; then program_run_on (the device's program_run body) over ProgramRegs
// against program_run (the host's) for whole programs' results.
TEST(ProgramRegs, ChainedProgramGivesTheHostsBits) {
    HostScene hs(plane_scene());
    SceneView v = hs.view();
    std::vector<NodeInstr> code;
    const std::vector<NodeInstr> ops = every_op(0, 0);
    for (size_t k = 0; k < ops.size(); ++k) {
        NodeInstr n = ops[k];
        n.in = uint16_t((k * 37) % 170);  // at most 20 inputs and 8 outputs: in range
        n.out = uint16_t((k * 53) % 184);
        code.push_back(n);
    }
    const Threads th = make_threads(29);
    std::vector<float> consts = th.regs[0];
    const std::vector<float> tab = tables();
    consts.insert(consts.end(), tab.begin(), tab.end());
    v.program_consts = consts.data();
    expect_same_registers(v, code, th, "chained");

    // the whole program through program_run_on: ops reading the preload only (their outputs
    // feed no later op, so no NaN's bits reach a hash), results from several blocks
    const std::vector<NodeInstr> apart = every_op(0, 100);
    v.program_code = apart.data();
    for (int result : {0, 100, 101, 104, kProgramRegs - 3}) {
        const MaterialProgram p{0, int32_t(apart.size()), 0, kProgramRegs, kTargetBaseColor,
                                result};
        std::vector<float> buf(size_t(kProgramRegs) * kStride, -7.5f);
        for (int t = 0; t < kThreads; ++t) {
            const Vec3 want = program_run(v, p, th.sp[t]);
            const Vec3 got =
                program_run_on(v, p, th.sp[t], ProgramRegs{buf.data() + t, uint32_t(kStride)});
            EXPECT_TRUE(same_bits(want.x, got.x) && same_bits(want.y, got.y) &&
                        same_bits(want.z, got.z))
                << "result " << result << ", thread " << t;
        }
    }
}
