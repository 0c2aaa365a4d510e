// Thin-film interference (bsdf/thin_film.h) and the Principled specular layer that carries it:
// the three-order Airy series against an independent brute-force spectral integral of the exact
// (infinite-order) film reflectance, its limits, and the layer as a BSDF (chi-square, weights,
// energy, hostile inputs).
#include <complex>

#include <gtest/gtest.h>

#include "bsdf/material.h"
#include "test_material_helpers.h"

using namespace lantern;
using namespace lantern::test;

namespace {

// The film's reflectance integrated over the spectrum by brute force: the exact amplitude sum
// r = (r12 + r23 e^{i delta}) / (1 + r12 r23 e^{i delta}) per polarisation at each frequency,
// weighted by the matching functions whose Fourier transforms film_sensitivity evaluates
// (Gaussians in frequency nu = 1 / lambda), then the same XYZ -> Rec.709 step.
using cplx = std::complex<double>;

// Amplitude reflection coefficients from real index ei into (complex) index et.
void amplitudes(double ci, double ei, cplx et, cplx* rs, cplx* rp) {
    const cplx ct = std::sqrt(1.0 - (ei / et) * (ei / et) * (1.0 - ci * ci));
    *rs = (ei * ci - et * ct) / (ei * ci + et * ct);
    *rp = (et * ci - ei * ct) / (et * ci + ei * ct);
}

// XYZ of the film reflectance, brute force, on a substrate of complex index eta_s.
Vec3 brute_force_film_xyz(double cos_i, double eta_f, cplx eta_s, double d_nm) {
    const double s2 = (1.0 / eta_f) * (1.0 / eta_f) * (1.0 - cos_i * cos_i);
    const double c2 = std::sqrt(1.0 - s2);
    cplx r12s, r12p, r23s, r23p;
    amplitudes(cos_i, 1.0, eta_f, &r12s, &r12p);
    amplitudes(c2, eta_f, eta_s, &r23s, &r23p);
    const double opd_m = 2.0 * eta_f * d_nm * c2 * 1e-9;
    // densities over nu whose Fourier transforms are film_sensitivity's terms:
    // a sqrt(2 pi v) cos(mu w + s) exp(-v w^2) is the transform of a / sqrt(2) exp(-(nu-mu)^2/(4v))
    struct G { int c; double a, mu, v; } g[] = {{0, 5.4856e-13, 1.6810e+06, 4.3278e+09},
                                                {1, 4.4201e-13, 1.7953e+06, 9.3046e+09},
                                                {2, 5.2481e-13, 2.2084e+06, 6.6121e+09},
                                                {0, 1.64408e-8 / std::sqrt(2.0 * M_PI * 4.5282e+09),
                                                 2.2399e+06, 4.5282e+09}};
    double xyz[3] = {0, 0, 0};
    const int n = 200000;
    const double lo = 0.5e6, hi = 4.0e6, dnu = (hi - lo) / n;
    for (int i = 0; i < n; ++i) {
        const double nu = lo + (i + 0.5) * dnu;
        const std::complex<double> e = std::polar(1.0, 2.0 * M_PI * nu * opd_m);
        auto refl = [&](cplx r12, cplx r23) {
            return std::norm((r12 + r23 * e) / (1.0 + r12 * r23 * e));
        };
        const double r = 0.5 * (refl(r12s, r23s) + refl(r12p, r23p));
        for (const G& k : g)
            xyz[k.c] += r * k.a / std::sqrt(2.0) * std::exp(-(nu - k.mu) * (nu - k.mu) / (4 * k.v)) *
                        dnu;
    }
    for (double& v : xyz) v /= 1.0685e-7;
    return vec3(float(xyz[0]), float(xyz[1]), float(xyz[2]));
}

Vec3 xyz_to_rgb(Vec3 xyz) {
    const double w[3] = {xyz.x * 0.95047, double(xyz.y), xyz.z * 1.08883};
    auto c = [](double v) { return float(std::min(std::max(v, 0.0), 1.0)); };
    return vec3(c(3.2404542 * w[0] - 1.5371385 * w[1] - 0.4985314 * w[2]),
                c(-0.9692660 * w[0] + 1.8760108 * w[1] + 0.0415560 * w[2]),
                c(0.0556434 * w[0] - 0.2040259 * w[1] + 1.0572252 * w[2]));
}

Vec3 brute_force_film(double cos_i, double eta_f, double eta_s, double d_nm) {
    return xyz_to_rgb(brute_force_film_xyz(cos_i, eta_f, cplx(eta_s, 0.0), d_nm));
}

// On a metal: each channel from its own complex index.
Vec3 brute_force_film_metal(double cos_i, double eta_f, Vec3 n, Vec3 k, double d_nm) {
    float out[3];
    for (int c = 0; c < 3; ++c)
        out[c] = xyz_to_rgb(brute_force_film_xyz(cos_i, eta_f, cplx(n[c], k[c]), d_nm))[c];
    return vec3(out[0], out[1], out[2]);
}

Material filmed(Material m, float thickness, float ior) {
    m.film_thickness = thickness;
    m.film_ior = ior;
    principled_albedo_table(m, own_tables(m));
    return m;
}

}  // namespace

TEST(ThinFilm, AirySeriesMatchesBruteForceSpectrum) {
    double worst = 0.0;
    bool colourful = false;
    for (float d : {40.0f, 120.0f, 250.0f, 500.0f, 800.0f, 1500.0f})
        for (float eta_f : {1.33f, 1.8f})
            for (float eta_s : {1.5f, 1.2f})
                for (float cos_i : {1.0f, 0.7f, 0.3f}) {
                    Vec3 a = thin_film_reflectance(cos_i, eta_f, eta_s, d);
                    Vec3 b = brute_force_film(cos_i, eta_f, eta_s, d);
                    for (int c = 0; c < 3; ++c) {
                        const float x = c == 0 ? a.x : c == 1 ? a.y : a.z;
                        const float y = c == 0 ? b.x : c == 1 ? b.y : b.z;
                        worst = std::max(worst, double(std::fabs(x - y)));
                        EXPECT_NEAR(x, y, 3e-3f) << d << " " << eta_f << " " << eta_s << " "
                                                 << cos_i << " channel " << c;
                    }
                    if (max_component(a) - std::min(a.x, std::min(a.y, a.z)) > 0.05f)
                        colourful = true;
                }
    EXPECT_TRUE(colourful);  // interference colours, not a grey Fresnel
    std::printf("thin film: worst |series - brute force| %.2e\n", worst);
}

TEST(ThinFilm, MetalSubstrateMatchesBruteForceSpectrum) {
    // gold-like and grey metals (complex phases at the bottom interface: the sign of the phase
    // relative to the path difference matters here, not for dielectrics)
    const Vec3 ns[] = {vec3(0.18f, 0.42f, 1.37f), vec3(2.0f, 1.9f, 1.8f)};
    const Vec3 ks[] = {vec3(3.4f, 2.35f, 1.77f), vec3(3.0f, 3.1f, 3.2f)};
    double worst = 0.0;
    for (int mtl = 0; mtl < 2; ++mtl)
        for (float d : {120.0f, 300.0f, 700.0f})
            for (float cos_i : {1.0f, 0.6f, 0.25f}) {
                Vec3 a = thin_film_reflectance_conductor(cos_i, 1.4f, ns[mtl], ks[mtl], d);
                Vec3 b = brute_force_film_metal(cos_i, 1.4, ns[mtl], ks[mtl], d);
                // the series stops after three orders (as Cycles'); at grazing angles on a metal
                // (R12 R23 up to 0.3) the orders left out reach a few percent
                const float tol = cos_i >= 0.5f ? 5e-3f : 3e-2f;
                for (int c = 0; c < 3; ++c) {
                    if (cos_i >= 0.5f) worst = std::max(worst, double(std::fabs(a[c] - b[c])));
                    EXPECT_NEAR(a[c], b[c], tol) << mtl << " " << d << " " << cos_i << " " << c;
                }
            }
    std::printf("thin film on metal: worst |series - brute force| %.2e (cos >= 0.6)\n", worst);
    // the F82 metal's estimated index reproduces its F0 at normal incidence
    Vec3 n, k;
    const Vec3 f0 = vec3(0.9f, 0.6f, 0.3f);
    f82_to_complex_ior(f0, vec3(1.0f), &n, &k);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(fresnel_conductor(1.0f, n[c], k[c]), f0[c], 2e-3f);
}

TEST(ThinFilm, Limits) {
    for (float c : {1.0f, 0.6f, 0.2f}) {
        // vanishing film: the bare interface
        Vec3 r = thin_film_reflectance(c, 1.6f, 1.5f, 1e-3f);
        const float f = fresnel_dielectric(c, 1.5f);
        EXPECT_NEAR(r.x, f, 2e-3f);
        EXPECT_NEAR(r.y, f, 2e-3f);
        EXPECT_NEAR(r.z, f, 2e-3f);
        // a film of the substrate's index: its top interface only, at any thickness
        for (float d : {100.0f, 600.0f}) {
            Vec3 q = thin_film_reflectance(c, 1.5f, 1.5f, d);
            EXPECT_NEAR(q.y, f, 2e-3f) << d;
        }
    }
    // no film (thickness 0) leaves the Principled specular Fresnel untouched
    Material m = principled(vec3(0.5f), 0.0f, 0.0f, 0.4f);
    Material f0 = filmed(m, 0.0f, 1.33f);
    for (float c : {0.1f, 0.5f, 1.0f}) {
        EXPECT_EQ(principled_spec_fresnel(m, c).y, principled_spec_fresnel(f0, c).y);
    }
    // and a thick film washes out to a colourless reflectance
    Vec3 thick = thin_film_reflectance(0.8f, 1.33f, 1.5f, 50000.0f);
    EXPECT_NEAR(thick.x, thick.z, 1e-3f);
}

TEST(ThinFilm, PrincipledLayerSamplesAndConserves) {
    const Material m = filmed(principled(vec3(0.3f, 0.2f, 0.6f), 0.0f, 0.0f, 0.3f), 500.0f, 1.33f);
    expect_material_samples_its_pdf(m, "thin film over plastic");
    Pcg32 rng = Pcg32::for_path(31, 0, 0);
    for (Transport mode : {Transport::Radiance, Transport::Importance})
        for (float theta_o : {0.3f, 1.1f}) {
            Vec3 wo = dir_from_angles(theta_o, 1.0f);
            for (int i = 0; i < 2000; ++i) {
                BsdfSample s = material_sample(
                    m, true, wo, vec3(rng.uniform(), rng.uniform(), rng.uniform()), mode);
                if (!s.valid || s.delta) continue;
                BsdfEval e = material_eval(m, true, wo, s.wi, mode);
                EXPECT_NEAR(s.weight.z, e.f.z * std::fabs(s.wi.z) / e.pdf_fwd_w,
                            1e-4f * (1.0f + s.weight.z));
            }
        }
    // a white base under an iridescent layer reflects at most 1 (radiance transport), per
    // channel, within a stated cap of 0.5 % + z se (Bonferroni over the 27); a 1 % gain must
    // fail where it nearly reaches 1. The cap: 500 nm at normal incidence reads 1.00266 +-
    // 0.00017 in red (z 15.7): the base is weighted by 1 - the film's Fresnel at the view
    // cosine (principled.h, the smooth-surface estimate Cycles layers iridescence with), not by
    // the rough layer's albedo, whose microfacets see the film at other angles (was 3 %).
    constexpr double kFilmLayeringCap = 5e-3;
    const double z = z_bonferroni(27);
    int caught = 0;
    for (float d : {250.0f, 500.0f, 800.0f})
        for (float theta_o : {0.0f, 0.9f, 1.4f}) {
            Material w = filmed(principled(vec3(1.0f), 0.0f, 0.0f, 0.4f), d, 1.33f);
            Vec3 wo = dir_from_angles(theta_o, 0.3f);
            Pcg32 r2 = Pcg32::for_path(32, 0, 0);
            MeanSe sum[3];
            const int n = 40000;
            for (int i = 0; i < n; ++i) {
                BsdfSample s = material_sample(
                    w, true, wo, vec3(r2.uniform(), r2.uniform(), r2.uniform()),
                    Transport::Radiance);
                for (int c = 0; c < 3; ++c) sum[c].add(s.valid ? s.weight[c] : 0.0);
            }
            for (int c = 0; c < 3; ++c)
                EXPECT_TRUE(mean_at_most(sum[c], 1.0, z, kFilmLayeringCap, &caught))
                    << d << " " << theta_o << " channel " << c;
        }
    EXPECT_GE(caught, 1) << "no case within 1 % of 1: a 1 % energy gain would pass";
}

TEST(ThinFilm, HostileInputsStayFinite) {
    for (float d : {0.0f, 1e-20f, 0.999f, 1.0f, 1e5f, NAN, -5.0f, INFINITY})
        for (float eta_f : {1.0f, 1.0001f, 3.0f, 100.0f, NAN})
            for (float c : {0.0f, 1e-7f, 0.5f, 1.0f, -0.3f, NAN}) {
                Vec3 r = thin_film_reflectance(c, eta_f, 1.5f, d);
                EXPECT_TRUE(is_finite(r));
                EXPECT_GE(r.x, 0.0f);
                EXPECT_LE(max_component(r), 1.0f);
            }
    for (float d : {0.5f, 300.0f, NAN, INFINITY})
        for (float bad : {NAN, -1.0f, 0.0f, 1e6f}) {
            Vec3 r = thin_film_reflectance_conductor(0.5f, 1.5f, vec3(bad, 1.0f, 0.2f),
                                                     vec3(3.0f, bad, 0.0f), d);
            EXPECT_TRUE(is_finite(r));
            EXPECT_LE(max_component(r), 1.0f);
            Vec3 n, k;
            f82_to_complex_ior(vec3(bad, 1.0f, 0.0f), vec3(0.5f, bad, 1.0f), &n, &k);
            EXPECT_TRUE(is_finite(thin_film_reflectance_conductor(0.3f, 1.33f, n, k, d)));
        }
    // a filmed metal (principled Metallic 0.5 and a conductor of the same film) samples finitely
    Material metal{};
    metal.type = kMaterialConductor;
    metal.base_color = vec3(0.9f, 0.6f, 0.3f);
    metal.specular_tint = vec3(1.0f);
    metal.roughness = 0.2f;
    metal.film_thickness = 400.0f;
    metal.film_ior = 1.5f;
    Material m = filmed(principled(vec3(0.5f), 0.5f, 0.0f, 0.0f, 1.0f), 300.0f, 2.0f);
    Pcg32 rng = Pcg32::for_path(33, 0, 0);
    for (const Material& mm : {m, metal})
        for (int i = 0; i < 300; ++i) {
            Vec3 wo = dir_from_angles(rng.uniform() * 1.5707f, rng.uniform() * 6.28f);
            BsdfSample s = material_sample(
                mm, true, wo, vec3(rng.uniform(), rng.uniform(), rng.uniform()),
                Transport::Radiance);
            if (s.valid) EXPECT_TRUE(is_finite(s.weight));
            BsdfEval e = material_eval(mm, true, wo, s.valid ? s.wi : wo, Transport::Radiance);
            EXPECT_TRUE(finite_eval(e.f, e.pdf_fwd_w, e.pdf_rev_w));
        }
}
