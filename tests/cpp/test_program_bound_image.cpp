// The Image Texture's interval rule (scene/program_bound_image.cpp; issue 29, volleft): the
// harness of program_bound_cases.h over every extension mode, both interpolations, the three
// texel formats (8-bit sRGB and linear, float with negative values), the four projections, a
// uv transform, a size of several texel blocks: no sample of the program outside the interval
// program_bound gives for its box. The controls: the bound over a box a tenth of the image
// wide is far narrower than the image's range (the rule reads the texels the box reaches, not
// all), and a box's inner half's bound is left by its samples in a share of the boxes. A mesh
// volume whose density is an image of thin bright columns between the old lattice's points
// gets a majorant at the columns' density (the lattice saw 0 there), and no warning.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "program_bound_cases.h"

using namespace lantern;

namespace {

// An image of w x h texels: random values (a few extremes), or a smooth ramp in x
TextureInput pbi_texture(const std::string& format, const std::string& wrap, bool closest, int w,
                         int h, std::mt19937& rng, bool ramp = false) {
    TextureInput t;
    t.name = format + " " + wrap;
    t.width = w;
    t.height = h;
    t.format = format;
    t.wrap = wrap;
    t.interpolation = closest ? "closest" : "linear";
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const size_t n = size_t(w) * size_t(h) * 4;
    for (size_t i = 0; i < n; ++i) {
        // smooth waves with a little noise (a box's inner half reads a narrower range), a few
        // extremes
        const size_t x = (i / 4) % size_t(w), y = i / 4 / size_t(w);
        float v = ramp ? (float(x) + 0.5f) / float(w)
                       : 0.5f +
                             0.35f * std::sin(0.9f * float(x) + 1.7f * float(i % 4)) *
                                 std::cos(1.3f * float(y)) +
                             0.1f * (u(rng) - 0.5f);
        if (!ramp && u(rng) < 0.005f) v = u(rng) < 0.5f ? 0.0f : 1.0f;
        if (format == "float")
            t.floats.push_back(ramp ? v : (u(rng) < 0.02f ? 12.0f * v : 3.0f * v - 1.0f));
        else
            t.bytes.push_back(uint8_t(std::lround(v * 255.0f)));
    }
    return t;
}

}  // namespace

// Flat, box, sphere and tube projections (in: vector(3), box also normal(3) blend) of every
// extension, interpolation and format; the colour and the alpha.
TEST(ProgramBoundImage, InsideRandomBoxes) {
    std::mt19937 rng(53);
    pbc::Tally tally;
    tally.control_channels = 3;
    int cases = 0;
    for (const char* format : {"srgb", "linear", "float"})
        for (const char* wrap : {"repeat", "extend", "clip", "mirror"})
            for (int closest = 0; closest < 2; ++closest)
                for (int projection = 0; projection < 4; ++projection) {
                    const bool big = (cases % 7) == 0;  // blocks of 4 x 4 texels
                    TextureInput tex =
                        pbi_texture(format, wrap, closest, big ? 520 : 13, big ? 9 : 7, rng);
                    const float uv[6] = {2.3f, 0.4f, 0.1f, -0.7f, 1.9f, 0.3f};
                    if (cases % 3 == 1) std::copy(uv, uv + 6, tex.uv);  // a uv transform
                    pbc::Case c{std::string("image ") + format + " " + wrap +
                                    (closest ? " closest" : " linear") + " projection " +
                                    std::to_string(projection),
                                kOpImage,
                                projection,
                                0,
                                0,
                                0,
                                0,
                                {0, 0, 0, 0.3f, -0.8f, 0.5f, 0.25f},
                                {{0, 0}, {1, 1}, {2, 2}},
                                {0, 1, 2},
                                -0.6f,
                                1.6f,
                                {tex}};
                    if (projection == 1 && cases % 2)
                        c.pos.insert(c.pos.end(), {{3, 1}, {4, 2}, {5, 0}});
                    pbc::check(c, rng, 12, 150, 0.3f, 1, &tally);
                    c.outs[0] = c.outs[1] = c.outs[2] = 3;  // the alpha
                    c.name += " alpha";
                    pbc::check(c, rng, 6, 100, 0.3f, 1, &tally);
                    ++cases;
                }
    // a missing image (texture -1): magenta
    pbc::check(
        {"image missing", kOpImage, 0, 0, 0, -1, 0, {0, 0, 0}, {{0, 0}, {1, 1}, {2, 2}}, {0, 1, 2}},
        rng, 3, 20, 0.3f, 1, &tally);
    std::printf("control: %d of %d boxes have samples outside the inner half's bound\n",
                tally.exceeded, tally.boxes);
    EXPECT_GT(tally.exceeded, tally.boxes / 20);  // 139 of 1731 measured
}

// The rule reads the texels the box reaches: over a ramp (0 .. 1 across x), a box a tenth of
// the image wide gets a bound about a tenth wide; the whole image's range is 1.
TEST(ProgramBoundImage, SmallBoxReadsFewTexels) {
    std::mt19937 rng(59);
    for (int closest = 0; closest < 2; ++closest) {
        pbc::Case c{"ramp",
                    kOpImage,
                    0,
                    0,
                    0,
                    0,
                    0,
                    {0, 0, 0},
                    {{0, 0}, {1, 1}, {2, 2}},
                    {0, 1, 2},
                    0.1f,
                    0.9f,
                    {pbi_texture("float", "repeat", closest, 640, 8, rng, true)}};
        HostScene scene(pbc::scene(c));
        const SceneView& s = scene.view();
        ASSERT_NE(s.programs, nullptr);
        ProgramBoundCache cache;
        for (float x0 : {0.1f, 0.45f, 0.8f}) {
            Interval iv[3];
            ASSERT_TRUE(program_bound(s, s.programs[0], -1, Vec3{x0, 0.2f, 0.0f},
                                      Vec3{x0 + 0.1f, 0.7f, 0.0f}, iv, 3, &cache));
            EXPECT_LE(iv[0].lo, x0 + 0.5f / 640.0f);
            EXPECT_GE(iv[0].hi, x0 + 0.1f - 0.5f / 640.0f);
            EXPECT_LT(iv[0].hi - iv[0].lo, 0.1f + 8.0f / 640.0f) << x0;  // blocks of 4 texels
        }
        // the whole image (and past it, repeating)
        Interval all[3];
        ASSERT_TRUE(program_bound(s, s.programs[0], -1, vec3(-0.3f), vec3(1.3f), all, 3, &cache));
        EXPECT_LT(all[0].lo, 1.0f / 640.0f);
        EXPECT_GT(all[0].hi, 1.0f - 1.0f / 640.0f);
    }
}

// A mesh volume (a unit cube) of density 40 x the image's red over Generated (x, y), the image
// 64 x 64 of bright columns (mod 8: 1, 3, 4, 6) that build_hetero's old 25^3 lattice never read
// with Closest (it read 0 everywhere: majorant 0, the smoke not rendered): the majorant's
// density is the columns' 40, no warning.
TEST(ProgramBoundImage, MeshVolumeMajorantHoldsThinColumns) {
    for (int closest = 0; closest < 2; ++closest) {
        SceneInput in;
        TextureInput t;
        t.name = "columns";
        t.width = t.height = 64;
        t.format = "linear";
        t.interpolation = closest ? "closest" : "linear";
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const int m = x % 8;
                const uint8_t v = (m == 1 || m == 3 || m == 4 || m == 6) ? 255 : 0;
                t.bytes.insert(t.bytes.end(), {v, v, v, 255});
            }
        in.textures.push_back(t);
        std::vector<float> c(12, 0.0f);
        c[11] = 40.0f;
        std::vector<uint32_t> code;
        pbc::instr(code, kOpInput, 0, 0, 0, 0, 0);     // the position (the cube [0, 1]^3)
        pbc::instr(code, kOpImage, 0, 0, 0, 0, 4, 0);  // colour 4..6, alpha 7
        pbc::instr(code, kOpCopy, 0, 0, 1, 11, 5);     // 40 (const 11) beside red
        pbc::instr(code, kOpMath, 2, 0, 0, 4, 10);     // red x 40
        in.program_code = code;
        in.program_consts = c;
        in.programs = {0u, uint32_t(code.size() / 4), 0u, 12u, uint32_t(kTargetDensity), 10u};
        MediumInput med;
        med.name = "columns";
        med.sigma_s = vec3(1.0f);
        in.media.push_back(med);
        MaterialInput mat;
        mat.name = "columns";
        mat.medium = 0;
        mat.volume_only = true;
        mat.program_first = 0;
        mat.program_count = 1;
        in.materials.push_back(mat);
        in.meshes.push_back(lantern::test::box_mesh(vec3(0.0f), vec3(1.0f), 0));
        HostScene scene(in);
        const SceneView& s = scene.view();
        const int32_t mi = s.material_medium[0];
        const Medium& m = s.media[mi];
        for (const std::string& w : scene.warnings())
            EXPECT_EQ(w.find("no bound"), std::string::npos) << w;
        // the lattice the old bound read: 0 everywhere
        float lattice = 0.0f, seen = 0.0f;
        for (int z = 0; z <= 24; ++z)
            for (int y = 0; y <= 24; ++y)
                for (int x = 0; x <= 24; ++x)
                    lattice = std::max(
                        lattice, medium_density(s, m, mi, Vec3{x / 24.0f, y / 24.0f, z / 24.0f},
                                                Vec3{0, 0, 1}));
        for (int x = 0; x < 640; ++x)
            seen = std::max(seen, medium_density(s, m, mi, Vec3{(x + 0.5f) / 640.0f, 0.5f, 0.5f},
                                                 Vec3{0, 0, 1}));
        std::printf("columns (%s): majorant's density %.3f, the old lattice's %.3f, samples %.3f\n",
                    closest ? "closest" : "linear", m.density_max, lattice, seen);
        if (closest) EXPECT_EQ(lattice, 0.0f);  // linear blends the columns into some points
        EXPECT_GE(m.density_max, seen);
        EXPECT_GT(seen, 39.0f);
        EXPECT_LT(m.density_max, 40.1f);
    }
}
