#include "integrator/pt.h"
#include "integrator/lt.h"
#include <cstdio>
#include <random>
using namespace lantern;
int main() {
    for (float rough : {0.5f, 1.0f}) for (int skin : {0, 1}) for (float dz : {0.9f, 0.5f, 0.15f}) {
        Material m{}; m.roughness = rough; m.ss_ior = 1.4f; m.ss_skin = skin;
        Vec3 d = normalize(Vec3{sqrtf(1 - dz * dz), 0.0f, dz});
        std::mt19937 g(1); std::uniform_real_distribution<float> U(0.f, 1.f);
        // MC: the estimator E[f(c)/pdf(c)] for f = indicator of a cap, vs the integral of pdf over the cap
        const int N = 2000000; double mass_mc = 0, mass_int = 0, ok = 0;
        Vec3 axis = normalize(Vec3{-0.3f, 0.2f, 0.8f});
        for (int k = 0; k < N; ++k) {
            Vec3 c; if (lt_sss_exit_sample(m, d, Vec3{U(g), U(g), U(g)}, &c)) { ok++; if (dot(c, axis) > 0.7f) mass_mc++; }
            // uniform hemisphere integration of the pdf over the cap and in all
            float z = U(g), ph = 6.2831853f * U(g), r = sqrtf(::fmaxf(0.f, 1 - z * z));
            Vec3 w{r * cosf(ph), r * sinf(ph), z};
            float p = lt_sss_exit_pdf(m, d, w) * 6.2831853f;
            if (dot(w, axis) > 0.7f) mass_int += p;
        }
        printf("rough %.1f skin %d dz %.2f: cap mass sampled %.4f integrated %.4f; success %.4f\n", rough, skin, dz, mass_mc / N, mass_int / N, ok / N);
    }
}
