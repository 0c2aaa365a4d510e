// Volume objects' majorant bricks and fire (scene/medium_majorant.h, scene/medium_fire.h,
// docs/volumes.md): every brick bounds every voxel a lookup inside it reads (the bricks without
// the trilinear neighbours as a negative control that must fail), every piece of the walk along
// random rays bounds the extinction at points inside it and the pieces tile the ray; ratio and
// spectral tracking through the bricks against Beer-Lambert of the exact integral of a sparse
// grid (a ray parallel to x: the trilinear lookup is piecewise linear there) and against the one
// majorant (fewer tentative collisions counted), each with a control 3 % off; the emission gathered
// at tentative collisions of a temperature and a flame grid against the emission integral by
// quadrature (a 3 % control).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/rng.h"
#include "integrator/session.h"
#include "scene/medium_hetero.h"
#include "scene/scene.h"
#include "test_scene_helpers.h"

using namespace lantern;
using lantern::test::box_mesh;

namespace {

constexpr int kFireNx = 37, kFireNy = 29, kFireNz = 23;  // not multiples of the brick

// A sparse grid: two blobs of random voxels in a large block, zero elsewhere.
std::vector<float> sparse_voxels(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> v(size_t(kFireNx) * kFireNy * kFireNz, 0.0f);
    for (int k = 0; k < kFireNz; ++k)
        for (int j = 0; j < kFireNy; ++j)
            for (int i = 0; i < kFireNx; ++i) {
                const bool a = i >= 4 && i < 13 && j >= 6 && j < 15 && k >= 3 && k < 12;
                const bool b = i >= 24 && i < 30 && j >= 17 && j < 26 && k >= 14 && k < 20;
                if (a || b) v[(size_t(k) * kFireNy + size_t(j)) * kFireNx + size_t(i)] = (a ? 8.0f : 3.0f) * u(rng);
            }
    return v;
}

// index -> world: `scale` metres per voxel, translated; rotated 90 degrees about z when `rotate`
SceneInput fire_scene(const float* m16, bool fire) {
    SceneInput in;
    GridInput gi;
    gi.name = "density";
    gi.dims[0] = kFireNx;
    gi.dims[1] = kFireNy;
    gi.dims[2] = kFireNz;
    std::copy(m16, m16 + 16, gi.index_to_world);
    gi.voxels = sparse_voxels(7);
    in.grids.push_back(gi);
    MediumInput med;
    med.name = "smoke";
    med.sigma_a = vec3(0.15f, 0.3f, 0.5f);
    med.sigma_s = vec3(0.25f, 0.2f, 0.1f);
    MaterialInput mat;
    mat.name = "smoke";
    mat.medium = 0;
    mat.volume_only = true;
    mat.density_grid = 0;
    if (fire) {
        // temperature: a ramp along x (0.2 .. 1.6 x 2000 K); flame: the density's second grid
        GridInput t = gi, f = gi;
        t.name = "temperature";
        f.name = "flame";
        for (int k = 0; k < kFireNz; ++k)
            for (int j = 0; j < kFireNy; ++j)
                for (int i = 0; i < kFireNx; ++i) {
                    const size_t n = (size_t(k) * kFireNy + size_t(j)) * kFireNx + size_t(i);
                    t.voxels[n] = 0.2f + 1.4f * float(i) / float(kFireNx - 1);
                    f.voxels[n] = 0.5f + 0.5f * std::sin(0.3f * float(i + j));
                }
        in.grids.push_back(t);
        in.grids.push_back(f);
        mat.temperature_grid = 1;
        mat.flame_grid = 2;
        med.blackbody_intensity = 0.8f;
        med.temperature = 2000.0f;
        med.blackbody_tint = Vec3{1.0f, 0.9f, 0.8f};
        med.flame_emission = Vec3{0.4f, 0.2f, 0.1f};
        med.emission = Vec3{0.01f, 0.02f, 0.03f};
    }
    in.media.push_back(med);
    in.materials.push_back(mat);
    const Transform tf{{{m16[0], m16[1], m16[2], m16[3]},
                        {m16[4], m16[5], m16[6], m16[7]},
                        {m16[8], m16[9], m16[10], m16[11]}}};
    Vec3 lo = vec3(kInf), hi = vec3(-kInf);
    for (int c = 0; c < 8; ++c) {
        const Vec3 p = tf.point(Vec3{c & 1 ? float(kFireNx) : -1.0f, c & 2 ? float(kFireNy) : -1.0f,
                                     c & 4 ? float(kFireNz) : -1.0f});
        lo = Vec3{std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = Vec3{std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    in.meshes.push_back(box_mesh(lo, hi, 0));
    return in;
}

const float kAxis[16] = {0.1f, 0, 0, -1, 0, 0.1f, 0, 0.5f, 0, 0, 0.1f, 2, 0, 0, 0, 1};
const float kRotated[16] = {0, -0.07f, 0, 1, 0.05f, 0, 0, 2, 0, 0, 0.09f, -3, 0, 0, 0, 1};

float extinction(const SceneView& s, const Medium& m, int32_t med, Vec3 p) {
    const MediumCoeffs c = medium_coeffs_at(s, m, med, p, Vec3{1, 0, 0});
    return max_component(c.sigma_a + c.sigma_s);
}

}  // namespace

TEST(MajorantGrid, EveryBrickBoundsTheVoxelsItsLookupsRead) {
    SceneInput in = fire_scene(kRotated, false);
    HostScene scene(in);
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    const Medium& m = s.media[med];
    ASSERT_GE(m.majorant_grid, 0);
    const MajorantGrid& g = s.majorant_grids[m.majorant_grid];
    const int B = kMajorantBrick;
    EXPECT_EQ(g.nx, (kFireNx + B) / B);
    EXPECT_EQ(g.ny, (kFireNy + B) / B);
    EXPECT_EQ(g.nz, (kFireNz + B) / B);
    const Vec3 unit = m.sigma_a + m.sigma_s;
    const std::vector<float>& v = in.grids[0].voxels;
    int naive_low = 0;
    for (int bk = 0; bk < g.nz; ++bk)
        for (int bj = 0; bj < g.ny; ++bj)
            for (int bi = 0; bi < g.nx; ++bi) {
                const float mu = s.majorant_values[g.offset + (size_t(bk) * g.ny + bj) * g.nx + bi];
                // lookups at q in [b B - 1, (b + 1) B - 1) read voxels b B - 1 .. (b + 1) B - 1
                float need = 0.0f, naive = 0.0f;
                for (int k = bk * B - 1; k <= (bk + 1) * B - 1; ++k)
                    for (int j = bj * B - 1; j <= (bj + 1) * B - 1; ++j)
                        for (int i = bi * B - 1; i <= (bi + 1) * B - 1; ++i) {
                            if (i < 0 || j < 0 || k < 0 || i >= kFireNx || j >= kFireNy || k >= kFireNz)
                                continue;
                            const float x = v[(size_t(k) * kFireNy + size_t(j)) * kFireNx + size_t(i)];
                            need = std::max(need, x);
                            // the control: the brick's own B^3 voxels, without the neighbours
                            if (i >= bi * B && j >= bj * B && k >= bk * B && i < (bi + 1) * B - 1 &&
                                j < (bj + 1) * B - 1 && k < (bk + 1) * B - 1)
                                naive = std::max(naive, x);
                        }
                EXPECT_GE(mu, max_component(unit * need)) << bi << " " << bj << " " << bk;
                naive_low += max_component(unit * naive) < max_component(unit * need);
            }
    EXPECT_GT(naive_low, 0) << "the control: bricks without their neighbours must miss some";
}

TEST(MajorantGrid, PiecesTileTheRayAndBoundTheExtinction) {
    for (const float* tf : {kAxis, kRotated}) {
        HostScene scene(fire_scene(tf, false));
        const SceneView& s = scene.view();
        const int32_t med = s.material_medium[0];
        const Medium& m = s.media[med];
        ASSERT_GE(m.majorant_grid, 0);
        const MajorantGrid& g = s.majorant_grids[m.majorant_grid];
        const Transform& w2i = s.grids[0].world_to_index;
        const Transform i2w{{{tf[0], tf[1], tf[2], tf[3]},
                             {tf[4], tf[5], tf[6], tf[7]},
                             {tf[8], tf[9], tf[10], tf[11]}}};
        (void)w2i;
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        int checked = 0, pieces_max = 0;
        for (int r = 0; r < 400; ++r) {
            // from a point around the block (index space -4 .. n + 4) in a random direction
            const Vec3 q{-4.0f + u(rng) * (kFireNx + 8), -4.0f + u(rng) * (kFireNy + 8),
                         -4.0f + u(rng) * (kFireNz + 8)};
            const Vec3 o = i2w.point(q);
            const float ct = 1.0f - 2.0f * u(rng), ph = 2.0f * kPi * u(rng);
            const float st = std::sqrt(std::max(0.0f, 1.0f - ct * ct));
            Vec3 d{st * std::cos(ph), st * std::sin(ph), ct};
            if (r % 7 == 0) d = Vec3{1, 0, 0};  // axis-aligned rays too
            const float t_end = 0.5f + 4.0f * u(rng);
            MajorantWalk walk = medium_majorant_walk(s, m, o, d, t_end);
            MajorantSeg seg;
            float t = 0.0f;
            int pieces = 0;
            while (majorant_next(walk, &seg)) {
                ASSERT_EQ(seg.t0, t) << "ray " << r;
                ASSERT_GE(seg.t1, seg.t0);
                for (int k = 0; k <= 16; ++k) {
                    const float x = seg.t0 + (seg.t1 - seg.t0) * (float(k) + 0.5f) / 17.0f;
                    const float e = extinction(s, m, med, o + d * x);
                    ASSERT_LE(e, seg.mu * (1.0f + 1e-5f) + 1e-6f)
                        << "ray " << r << " at " << x << " piece " << pieces;
                    ++checked;
                }
                t = seg.t1;
                ++pieces;
            }
            EXPECT_EQ(t, t_end) << "ray " << r;
            EXPECT_LE(pieces, g.nx + g.ny + g.nz + 3);
            pieces_max = std::max(pieces_max, pieces);
        }
        EXPECT_GT(checked, 10000);
        EXPECT_GT(pieces_max, 3);
    }
}

namespace {

// The exact optical depth per unit extinction along q(t) = (q0.x + t / h, q0.y, q0.z) in index
// space (h metres per voxel) over t in [0, L]: the lookup is, per corner of the (y, z) cell,
// linear in x between voxel centres, so a fine sum of trapezoids on the knots is exact.
double exact_depth(const std::vector<float>& v, Vec3 q0, float h, float L) {
    auto lookup = [&](double x) {
        DensityGrid g{};
        g.nx = kFireNx;
        g.ny = kFireNy;
        g.nz = kFireNz;
        return double(grid_lookup_index(g, v.data(), Vec3{float(x), q0.y, q0.z}));
    };
    // knots: the ends and every integer x between
    std::vector<double> xs = {q0.x, q0.x + L / h};
    for (int i = int(std::ceil(q0.x)); i < q0.x + L / h; ++i) xs.push_back(i);
    std::sort(xs.begin(), xs.end());
    double sum = 0.0;
    for (size_t k = 0; k + 1 < xs.size(); ++k)
        sum += 0.5 * (lookup(xs[k]) + lookup(xs[k + 1])) * (xs[k + 1] - xs[k]) * h;
    return sum;
}

}  // namespace

TEST(MajorantGrid, TrackingThroughBricksIsBeerLambertWithFewerCollisions) {
    HostScene scene(fire_scene(kAxis, false));
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    const Medium m = s.media[med];
    ASSERT_GE(m.majorant_grid, 0);
    Medium one = m;  // the same medium with the one majorant
    one.majorant_grid = -1;
    const std::vector<float> v = sparse_voxels(7);
    // a ray along +x through both blobs' rows: index (-1.5, 10.3, 7.6) .. x = 36.5
    const Vec3 q0{-1.5f, 10.3f, 7.6f};
    const float h = 0.1f, L = 3.8f;
    const Vec3 o{-1.0f + h * q0.x, 0.5f + h * q0.y, 2.0f + h * q0.z}, d{1, 0, 0};
    const double depth = exact_depth(v, q0, h, L);
    const double sa[3] = {0.15, 0.3, 0.5}, ss[3] = {0.25, 0.2, 0.1};
    ASSERT_GT(depth, 0.5);
    const int n = 200000;
    for (int variant = 0; variant < 2; ++variant) {
        const Medium& mm = variant == 0 ? m : one;
        double tr[3] = {}, tr2[3] = {}, pass[3] = {}, pass2[3] = {}, sc[3] = {}, sc2[3] = {};
        long collisions = 0;
        for (int k = 0; k < n; ++k) {
            Rng path = Rng::for_path(523 + variant, 0, uint64_t(k));
            Rng r1 = medium_tracking_rng(path, 1), r0 = medium_tracking_rng(path, 0);
            const Vec3 t = medium_ratio_tracking(s, mm, med, o, d, L, r1);
            const HeteroStep st = medium_track(
                s, mm, med, o, d, L, vec3(1.0f), r0,
                [&](float, Vec3, float) { ++collisions; }, [](float, float, Vec3) {});
            const double tv[3] = {t.x, t.y, t.z};
            const double wv[3] = {st.weight.x, st.weight.y, st.weight.z};
            for (int c = 0; c < 3; ++c) {
                tr[c] += tv[c];
                tr2[c] += tv[c] * tv[c];
                double& a = st.scattered ? sc[c] : pass[c];
                double& a2 = st.scattered ? sc2[c] : pass2[c];
                a += wv[c];
                a2 += wv[c] * wv[c];
            }
        }
        auto check = [&](double sum, double sum2, double want, double control, const char* what,
                         int c) {
            const double mean = sum / n;
            const double se = std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / (n - 1)) + 1e-9;
            std::printf("%s %s channel %d: %.5f want %.5f se %.2g\n",
                        variant ? "one majorant" : "bricks", what, c, mean, want, se);
            EXPECT_LT(std::fabs(mean - want), 4.5 * se) << what << " channel " << c;
            EXPECT_GT(std::fabs(mean - control), 4.5 * se) << what << " control channel " << c;
        };
        for (int c = 0; c < 3; ++c) {
            const double st = sa[c] + ss[c];
            const double T = std::exp(-st * depth), S = ss[c] / st * (1.0 - T);
            check(tr[c], tr2[c], T, 1.03 * T, "ratio", c);  // controls: 3 % off
            check(pass[c], pass2[c], T, 1.03 * T, "pass", c);
            check(sc[c], sc2[c], S, 1.03 * S, "scatter", c);
        }
        std::printf("%s: %.2f tentative collisions per tracking\n",
                    variant ? "one majorant" : "bricks", double(collisions) / n);
        static long bricks_collisions = 0;
        if (variant == 0) bricks_collisions = collisions;
        else EXPECT_LT(bricks_collisions, collisions * 8 / 10) << "the bricks skip the empty part";
    }
}

TEST(MediumFire, EmissionAtCollisionsIsTheEmissionIntegral) {
    SceneInput in = fire_scene(kAxis, true);
    HostScene scene(in);
    const SceneView& s = scene.view();
    const int32_t med = s.material_medium[0];
    const Medium& m = s.media[med];
    ASSERT_TRUE(m.emits);
    ASSERT_GE(m.temperature_grid, 0);
    ASSERT_GE(m.flame_grid, 0);
    ASSERT_NE(s.blackbody_table, nullptr);
    const Vec3 q0{-1.5f, 10.3f, 7.6f};
    const float h = 0.1f, L = 3.8f;
    const Vec3 o{-1.0f + h * q0.x, 0.5f + h * q0.y, 2.0f + h * q0.z}, d{1, 0, 0};
    // the integral of T(x) e(x) by quadrature (T from the trapezoids of the density, exact at
    // the knots; e from the grids by the formulas of docs/volumes.md, independently written:
    // the blackbody of each voxel's temperature, a grid per channel, read trilinearly)
    const int steps = 20000;
    const double sa[3] = {0.15, 0.3, 0.5}, ss[3] = {0.25, 0.2, 0.1};
    double want[3] = {}, depth = 0.0;
    const double sigma = 5.670373e-8 * 1e-6 / 3.14159265358979;
    const double tint[3] = {1.0, 0.9, 0.8};
    std::vector<float> bbv[3];
    for (float tv : in.grids[1].voxels) {
        const double temp = 2000.0 * tv;
        const Vec3 col = blackbody_color(s.blackbody_table, float(temp));
        const double cv[3] = {col.x, col.y, col.z};
        for (int c = 0; c < 3; ++c)
            bbv[c].push_back(float(tint[c] * sigma * (0.2 + 0.8 * temp * temp * temp * temp) * cv[c]));
    }
    DensityGrid bbg = s.grids[1];
    bbg.offset = 0;
    for (int k = 0; k < steps; ++k) {
        const float x = (float(k) + 0.5f) * L / float(steps);
        const Vec3 p = o + d * x;
        const double den = grid_lookup(s.grids[0], s.grid_voxels, p);
        const double flame = grid_lookup(s.grids[2], s.grid_voxels, p);
        const double fl[3] = {0.4, 0.2, 0.1}, e0[3] = {0.01, 0.02, 0.03};
        const double dd = den * L / steps;
        for (int c = 0; c < 3; ++c) {
            const double bb = grid_lookup(bbg, bbv[c].data(), p);
            const double tr = std::exp(-(sa[c] + ss[c]) * (depth + 0.5 * dd));
            want[c] += tr * (e0[c] + fl[c] * flame + bb) * L / steps;
        }
        depth += dd;
    }
    // E[sum over collisions of W e / mu] with scattering as absorption (the pass-only path):
    // use a medium that does not scatter so that the weight is the transmittance
    Medium ab = m;
    ab.sigma_a = m.sigma_a + m.sigma_s;
    ab.sigma_s = vec3(0.0f);
    const int n = 100000;
    double sum[3] = {}, sum2[3] = {};
    for (int k = 0; k < n; ++k) {
        Rng path = Rng::for_path(31, 0, uint64_t(k));
        Rng r = medium_tracking_rng(path, 0);
        Vec3 e = vec3(0.0f);
        medium_track(
            s, ab, med, o, d, L, vec3(1.0f), r,
            [&](float t, Vec3 w, float mu) {
                e = e + w * medium_emission_at(s, ab, med, o + d * t) / mu;
            },
            [](float, float, Vec3) {});
        const double ev[3] = {e.x, e.y, e.z};
        for (int c = 0; c < 3; ++c) {
            sum[c] += ev[c];
            sum2[c] += ev[c] * ev[c];
        }
    }
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / n;
        const double se = std::sqrt(std::max(sum2[c] / n - mean * mean, 0.0) / (n - 1));
        std::printf("fire emission channel %d: %.6g want %.6g se %.2g\n", c, mean, want[c], se);
        EXPECT_LT(std::fabs(mean - want[c]), 4.5 * se + 1e-3 * want[c]) << "channel " << c;
        EXPECT_GT(std::fabs(mean - 1.03 * want[c]), 4.5 * se + 1e-3 * want[c]) << "channel " << c;
    }
}

TEST(MediumFire, BadTemperaturesAreCleanedAndNamed) {
    SceneInput in = fire_scene(kAxis, true);
    in.grids[1].voxels[5] = NAN;
    in.grids[1].voxels[6] = -300.0f;
    in.media[0].temperature = NAN;
    HostScene scene(in);
    const SceneView& s = scene.view();
    EXPECT_EQ(s.grid_voxels[s.grids[1].offset + 5], 0.0f);
    EXPECT_EQ(s.grid_voxels[s.grids[1].offset + 6], 0.0f);
    int named = 0;
    for (const std::string& w : scene.warnings())
        named += w.find("temperature") != std::string::npos ||
                 w.find("Temperature") != std::string::npos;
    EXPECT_GE(named, 2);
    // a temperature of 0 emits only the (1 - intensity) part: finite everywhere
    const Medium& m = s.media[s.material_medium[0]];
    for (int k = 0; k < 50; ++k) {
        const Vec3 e =
            medium_emission_at(s, m, s.material_medium[0], Vec3{-1.0f + 0.07f * k, 1.5f, 2.8f});
        EXPECT_TRUE(std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z));
    }
    SceneInput bad = fire_scene(kAxis, true);
    bad.materials[0].flame_grid = 9;
    EXPECT_THROW(HostScene{bad}, std::invalid_argument);
}

TEST(MediumFire, LightTracingHandsAFireToPt) {
    // lt gathers no emission on camera paths: a fire's grids must make it render with pt and
    // say so; the same smoke without its fire keeps lt (control)
    for (bool fire : {true, false}) {
        SceneInput in = fire_scene(kAxis, fire);
        in.media[0].emission = vec3(0.0f);  // only the grids emit
        in.width = in.height = 4;
        SessionSettings st;
        st.integrator = "lt";
        st.spp_per_iteration = 1;
        st.max_depth = 2;
        st.threads = 1;
        Session s(in, st);
        bool said = false;
        for (const std::string& w : s.warnings())
            said = said || (w.find("temperature or flame grid") != std::string::npos &&
                            w.find("pt") != std::string::npos);
        EXPECT_EQ(said, fire);
    }
}
