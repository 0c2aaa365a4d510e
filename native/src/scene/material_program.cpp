// Host side of node-graph programs: the scene's programs, instructions and constants checked
// and attached to their materials (a bad program is an error naming its material, never a
// read out of range in a kernel), and the per-vertex attribute channels of each mesh.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bsdf/material.h"
#include "scene/material_program_host.h"
#include "scene/scene.h"

namespace lantern {

namespace {

// Floats an op reads from its input block and writes to its output block (at most).
struct OpSpan {
    int in, out;
};
OpSpan op_span(int op, int dim, int mode) {
    switch (op) {
    case kOpCopy: return {dim, dim};
    case kOpInput: return {0, 3};
    case kOpMath: return {3, 1};
    case kOpVectorMath: return {10, 4};
    case kOpMix: return {9, 3};
    case kOpMapRange: return {6 * dim, dim};
    case kOpClamp: return {3, 1};
    case kOpInvert: return {4, 3};
    case kOpGamma: return {4, 3};
    case kOpBrightContrast: return {5, 3};
    case kOpHsv: return {7, 3};
    case kOpSeparate: case kOpCombine: return {3, 3};
    case kOpRgbToBw: return {3, 1};
    case kOpChecker: return {10, 4};
    case kOpGradient: return {3, 4};
    case kOpNoise: return {11, 4};
    case kOpWhiteNoise: return {4, 4};
    case kOpVoronoi: return {8, 8};
    case kOpWave: return {9, 4};
    case kOpMagic: return {5, 4};
    case kOpRamp: return {1, 4};
    case kOpCurves: return {4, 3};
    case kOpFresnel: return {4, 1};
    case kOpLayerWeight: return {4, 2};
    case kOpImage: return {mode == 1 ? 7 : 3, 4};   // box: vector, normal, blend
    case kOpMapping: return {12, 3};
    case kOpNormalize: return {3, 3};
    case kOpBrick: return {20, 4};
    case kOpGrid: return {0, 4};
    default: return {-1, -1};
    }
}

// Instruction k of a program's code (4 words), checked: ops, dimensions, registers, tables
// (within nc constants) and textures; an error names the instruction.
NodeInstr decode_instr(const uint32_t* w, size_t k, size_t nc, size_t num_textures,
                       int num_channels) {
    NodeInstr n;
    n.op = uint8_t(w[0] & 0xFF);
    n.mode = uint8_t((w[0] >> 8) & 0xFF);
    n.flags = uint8_t((w[0] >> 16) & 0xFF);
    n.dim = uint8_t(w[0] >> 24);
    n.in = uint16_t(w[1] & 0xFFFF);
    n.out = uint16_t(w[1] >> 16);
    n.aux = int32_t(w[2]);
    n.aux2 = int32_t(w[3]);
    const std::string who = "node program instruction " + std::to_string(k);
    const OpSpan sp = op_span(n.op, n.dim, n.mode);
    if (sp.in < 0) throw std::invalid_argument(who + ": unknown op " + std::to_string(n.op));
    if (n.op == kOpCopy && (n.dim < 1 || n.dim > 3))
        throw std::invalid_argument(who + ": copy of " + std::to_string(n.dim) + " values");
    if ((n.op == kOpNoise || n.op == kOpWhiteNoise) && (n.dim < 1 || n.dim > 4))
        throw std::invalid_argument(who + ": noise of dimension " + std::to_string(n.dim));
    if (n.op == kOpVoronoi && (n.dim < 1 || n.dim > 4))
        throw std::invalid_argument(who + ": voronoi of dimension " + std::to_string(n.dim));
    if (n.op == kOpMapRange && n.dim != 1 && n.dim != 3)
        throw std::invalid_argument(who + ": map range of dimension " + std::to_string(n.dim));
    if (int(n.in) + sp.in > kProgramRegs || int(n.out) + sp.out > kProgramRegs)
        throw std::invalid_argument(who + ": registers out of range");
    if (n.op == kOpRamp || n.op == kOpCurves) {
        const size_t extra = n.op == kOpCurves ? 2 : 0;
        if (n.aux < 0 || n.aux2 < 2 || size_t(n.aux) + 4 * size_t(n.aux2) + extra > nc)
            throw std::invalid_argument(who + ": table out of range");
    }
    if (n.op == kOpImage && n.aux >= int32_t(num_textures))
        throw std::invalid_argument(who + ": texture " + std::to_string(n.aux) +
                                    " out of range");
    if (n.op == kOpInput && n.mode == 4 && n.aux >= num_channels) n.aux = -1;
    return n;
}

}  // namespace

std::vector<float> evaluate_program(const std::vector<uint32_t>& code,
                                    const std::vector<float>& consts, int num_const, int result,
                                    const std::vector<float>& points,
                                    const std::vector<float>& normals) {
    if (code.size() % 4 || num_const < 0 || num_const > kProgramRegs ||
        size_t(num_const) > consts.size() || result < 0 || result + 3 > kProgramRegs) {
        throw std::invalid_argument("node program: constants or result out of range");
    }
    if (points.size() % 3 || normals.size() != points.size())
        throw std::invalid_argument("node program: points and normals need 3 floats each");
    std::vector<NodeInstr> instrs;
    for (size_t k = 0; k < code.size() / 4; ++k)
        instrs.push_back(decode_instr(&code[4 * k], k, consts.size(), 0, 0));
    std::vector<float> c(consts.size());
    for (size_t i = 0; i < consts.size(); ++i) c[i] = std::isfinite(consts[i]) ? consts[i] : 0.0f;
    MaterialProgram p{0, int32_t(instrs.size()), 0, num_const, 0, result};
    SceneView view{};
    view.program_consts = c.data();
    view.program_code = instrs.data();
    std::vector<float> out(points.size());
    for (size_t i = 0; i < points.size() / 3; ++i) {
        ShadePoint sp{};
        sp.tri = -1;
        sp.p = Vec3{points[3 * i], points[3 * i + 1], points[3 * i + 2]};
        sp.n = sp.ng = sp.wo = Vec3{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
        const Vec3 v = program_run(view, p, sp);
        out[3 * i] = v.x;
        out[3 * i + 1] = v.y;
        out[3 * i + 2] = v.z;
    }
    return out;
}

namespace {

// Ops whose value depends on the shading point (or an image): never folded.
bool op_reads_hit(int op) {
    return op == kOpInput || op == kOpImage || op == kOpFresnel || op == kOpLayerWeight ||
           op == kOpGrid;
}

// Constant folding: every instruction whose inputs are all known (and whose outputs nothing
// else writes: the compiler reuses the registers of spent input blocks) is run here, once,
// and its outputs join the preloaded registers; what is left runs per hit. A program left
// without instructions is constant: folded into the material's own input by the caller.
void fold_program(MaterialProgram& p, std::vector<NodeInstr>& code, std::vector<float>& consts,
                  const SceneView& view) {
    float r[kProgramRegs] = {}, pre[kProgramRegs] = {};
    bool known[kProgramRegs] = {}, has_pre[kProgramRegs] = {};
    int writes[kProgramRegs] = {};  // preload counts as a write: only single writes fold
    for (int i = 0; i < p.num_const; ++i) {
        r[i] = pre[i] = consts[size_t(p.first_const) + size_t(i)];
        known[i] = has_pre[i] = true;
        writes[i] = 1;
    }
    for (int k = 0; k < p.num_instr; ++k) {
        const NodeInstr& n = code[size_t(p.first_instr) + size_t(k)];
        const OpSpan span = op_span(n.op, n.dim, n.mode);
        for (int i = 0; i < span.out; ++i) ++writes[n.out + i];
    }
    std::vector<NodeInstr> kept;
    ShadePoint sp{};
    sp.tri = -1;
    // constant[]: the register holds a value no hit changes, folded or not (a folded value's
    // register may be one the compiler reuses, so that the instruction stays): an instruction
    // of constant inputs is one Cycles folds on the host, kInstrConstant says so to the ops
    // whose folded value differs from their render-time one (material_program_ops.h)
    bool constant[kProgramRegs] = {};
    for (int i = 0; i < p.num_const; ++i) constant[i] = true;
    for (int k = 0; k < p.num_instr; ++k) {
        NodeInstr n = code[size_t(p.first_instr) + size_t(k)];
        const OpSpan span = op_span(n.op, n.dim, n.mode);
        bool inputs_constant = !op_reads_hit(n.op);
        for (int i = 0; inputs_constant && i < span.in; ++i) inputs_constant = constant[n.in + i];
        if (inputs_constant) n.flags |= kInstrConstant;
        for (int i = 0; i < span.out; ++i) constant[n.out + i] = inputs_constant;
        bool fold = !op_reads_hit(n.op);
        for (int i = 0; fold && i < span.in; ++i) fold = known[n.in + i];
        for (int i = 0; fold && i < span.out; ++i) fold = writes[n.out + i] == 1;
        if (fold) {  // run once here; its outputs start the program preloaded
            program_step(view, sp, n, r);
            for (int i = 0; i < span.out; ++i) {
                known[n.out + i] = has_pre[n.out + i] = true;
                pre[n.out + i] = r[n.out + i];
            }
        } else {
            kept.push_back(n);
            for (int i = 0; i < span.out; ++i) known[n.out + i] = false;
        }
    }
    int top = 0;
    for (int i = 0; i < kProgramRegs; ++i)
        if (has_pre[i]) top = i + 1;
    p.first_const = int32_t(consts.size());
    p.num_const = top;
    for (int i = 0; i < top; ++i)
        consts.push_back(has_pre[i] && std::isfinite(pre[i]) ? pre[i] : 0.0f);
    p.first_instr = int32_t(code.size());
    p.num_instr = int32_t(kept.size());
    code.insert(code.end(), kept.begin(), kept.end());
}

}  // namespace

void add_mesh_attributes(const MeshInput& m, size_t nv, size_t channels, std::vector<float>& out) {
    if (channels == 0) return;
    const size_t n = 3 * channels * nv;
    if (!m.attributes.empty() && m.attributes.size() != n) {
        throw std::invalid_argument("mesh '" + m.name + "': attributes need " +
                                    std::to_string(3 * channels) + " values per vertex");
    }
    for (size_t i = 0; i < n; ++i) {
        const float x = m.attributes.empty() ? 0.0f : m.attributes[i];
        out.push_back(std::isfinite(x) ? x : 0.0f);
    }
}

void HostScene::add_programs(const SceneInput& in) {
    num_attribute_channels_ = std::max(0, std::min(in.num_attribute_channels, 64));
    if (in.programs.size() % 6 || in.program_code.size() % 4) {
        throw std::invalid_argument("node programs: 6 values per program and 4 per instruction");
    }
    const size_t np = in.programs.size() / 6, ni = in.program_code.size() / 4;
    const size_t nc = in.program_consts.size();
    for (size_t k = 0; k < ni; ++k)
        program_code_.push_back(decode_instr(&in.program_code[4 * k], k, nc, in.textures.size(),
                                             num_attribute_channels_));
    for (size_t k = 0; k < np; ++k) {
        const uint32_t* w = &in.programs[6 * k];
        MaterialProgram p{int32_t(w[0]), int32_t(w[1]), int32_t(w[2]), int32_t(w[3]),
                          int32_t(w[4]), int32_t(w[5])};
        const std::string who = "node program " + std::to_string(k);
        if (size_t(w[0]) + size_t(w[1]) > ni || size_t(w[2]) + size_t(w[3]) > nc ||
            w[3] > uint32_t(kProgramRegs) || w[4] >= kTargetCount ||
            w[5] + 3 > uint32_t(kProgramRegs)) {
            throw std::invalid_argument(who + ": instructions, constants, target or result "
                                        "out of range");
        }
        programs_.push_back(p);
    }
    program_consts_.reserve(nc);
    for (float c : in.program_consts) program_consts_.push_back(std::isfinite(c) ? c : 0.0f);
    // fold each program; a constant one becomes the material's own input (no program runs)
    SceneView host{};
    host.program_consts = program_consts_.data();
    host.textures = nullptr;
    std::vector<MaterialProgram> kept;
    for (size_t k = 0; k < in.materials.size() && k < materials_.size(); ++k) {
        const MaterialInput& mi = in.materials[k];
        Material& m = materials_[k];
        m.prog_first = 0;
        m.prog_count = 0;
        if (mi.program_count <= 0) continue;
        if (mi.program_first < 0 || size_t(mi.program_first) + size_t(mi.program_count) > np) {
            throw std::invalid_argument("material " + std::to_string(k) + " ('" + mi.name +
                                        "'): node programs out of range");
        }
        m.prog_first = int32_t(kept.size());
        for (int i = 0; i < mi.program_count; ++i) {
            MaterialProgram p = programs_[size_t(mi.program_first) + size_t(i)];
            fold_program(p, program_code_, program_consts_, host);
            host.program_consts = program_consts_.data();
            if (p.target == kTargetTangent || p.target == kTargetDensity ||
                p.target == kTargetVolumeEmission || p.target == kTargetVolumeColor ||
                p.target == kTargetVolumeEmissionColor ||
                p.target == kTargetVolumeAbsorptionColor) {
                // kept: anisotropy_angle runs the tangent, medium_hetero.h the density
                kept.push_back(p);
                continue;
            }
            if (p.target == kTargetNormalMap || p.target == kTargetNormalMapWorld) {  // kept
                kept.push_back(p);
                m.tex_flags |= kTexNormal;
                m.tex_normal = -1;
                if (m.type == kMaterialPrincipled && m.coat_weight > 0.0f)
                    m.tex_flags |= kCoatNormal;  // the coat keeps the unmapped normal
                continue;
            }
            if (p.num_instr > 0) {
                kept.push_back(p);
                if (p.target == kTargetBump || p.target == kTargetDisplacement)
                    m.tex_flags |= kTexBump;
                continue;
            }
            if (p.target == kTargetBump || p.target == kTargetDisplacement)
                continue;  // a constant height bends nothing
            // constant: apply it to m as a hit would (the same clamps)
            std::vector<MaterialProgram> one{p};
            host.programs = one.data();
            Material tmp = m;
            tmp.prog_first = 0;
            tmp.prog_count = 1;
            ShadePoint sp{};
            sp.tri = -1;
            if (p.target == kTargetAlpha) {
                const Vec3 a = program_run(host, p, sp);
                m.transparency = 1.0f - (a.x >= 0.0f ? std::min(a.x, 1.0f) : 0.0f);
            } else {
                MaterialInputs inputs = material_inputs(m);
                material_apply_programs(host, tmp, sp, inputs);
                material_set_inputs(m, inputs);
            }
            host.programs = nullptr;
        }
        m.prog_count = int32_t(kept.size()) - m.prog_first;
        if (m.prog_count > 0) m.tex_flags |= kTexProgram;
        else m.prog_first = 0;
    }
    programs_ = std::move(kept);
}

}  // namespace lantern
