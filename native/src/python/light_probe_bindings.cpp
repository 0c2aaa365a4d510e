// lantern._core.light_selection_probe(scene, settings) -> dict of numpy arrays: what the light
// pick (scene/light_tree.h) does at each pixel's first hit (the ray through the pixel centre),
// beside what each light gives there, for bench/light_selection_probe.py. Per pixel and light:
// "pmf" (light_pick_pmf at the hit, with the normal next-event estimation passes it) and the
// next-event estimate of the light's irradiance on the shading normal's side, without shadows
// ("unoccluded") and with them ("visible"), over `samples` light samples. A diagnostic: it
// renders nothing, and the GIL is released while it runs.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <stdexcept>
#include <vector>

#include "backend/backend.h"
#include "core/rng.h"
#include "integrator/camera.h"
#include "integrator/pt.h"
#include "scene/light_tree.h"
#include "scene/scene.h"

namespace nb = nanobind;

namespace lantern {

namespace {

struct Probe {
    int width = 0, height = 0, lights = 0;
    std::vector<float> pmf, unoccluded, visible, position, normal;
};

Probe run_probe(const SceneInput& in, int samples, uint64_t seed, int threads) {
    HostScene scene(in);
    const SceneView& s = scene.view();
    std::vector<std::string> warnings;
    CpuBackend accel(s, threads, warnings);
    Probe out;
    out.width = s.camera.width;
    out.height = s.camera.height;
    out.lights = s.num_lights;
    const size_t n = size_t(out.width) * size_t(out.height), nl = size_t(s.num_lights);
    out.pmf.assign(n * nl, 0.0f);
    out.unoccluded.assign(n * nl, 0.0f);
    out.visible.assign(n * nl, 0.0f);
    out.position.assign(3 * n, 0.0f);
    out.normal.assign(3 * n, 0.0f);
    accel.for_all(int(n), [&](int px) {
        const Ray ray = camera_ray(s.camera, float(px % out.width) + 0.5f,
                                   float(px / out.width) + 0.5f, Vec2{});
        const HitRecord hit = accel.intersect(ray, RayKind::kCamera);
        if (hit.prim < 0) return;
        const SurfaceHit h = surface_of_hit(s, hit.prim, hit.uv, ray.o, ray.d, hit.t,
                                               ray.time);
        const Vec3 n_pick = light_pick_normal(s, hit.prim, h.ng);
        for (int c = 0; c < 3; ++c) {
            out.position[3 * px + c] = (&h.p.x)[c];
            out.normal[3 * px + c] = (&h.ns.x)[c];
        }
        for (int k = 0; k < s.num_lights; ++k) {
            const size_t o = size_t(px) * nl + size_t(k);
            out.pmf[o] = light_pick_pmf(s, k, h.p, n_pick);
            Rng rng = Rng::for_pixel(seed, uint64_t(px), uint64_t(k));
            double free_sum = 0.0, seen_sum = 0.0;
            for (int j = 0; j < samples; ++j) {
                const LightSample ls = sample_light(s, s.lights[k], h.p, rng.uniform2(), ray.time);
                if (!ls.valid || !(ls.pdf_w > 0.0f)) continue;
                const float cos_i = dot(ls.wi, h.ns);
                if (!(cos_i > 0.0f) || !sides_agree(ls.wi, h.ng, h.ns)) continue;
                const double e = double(luminance(ls.le)) * cos_i / ls.pdf_w;
                free_sum += e;
                const Vec3 so = offset_ray_origin(h.p, h.ng, ls.wi, s.offset_scale);
                Vec3 sd = ls.wi;
                float tmax = kInf;
                if (ls.dist < kInf) {
                    Vec3 target = ls.p_light;
                    if (!is_black(ls.n_light))
                        target = offset_ray_origin(target, ls.n_light, -ls.wi, s.offset_scale);
                    const Vec3 seg = target - so;
                    const float len = length(seg);
                    if (len > 0.0f) sd = seg / len;
                    tmax = len * (1.0f - 1e-4f);
                }
                if (!accel.occluded(Ray{so, sd, 0.0f, tmax})) seen_sum += e;
            }
            out.unoccluded[o] = float(free_sum / samples);
            out.visible[o] = float(seen_sum / samples);
        }
    }, 16);
    return out;
}

nb::object to_numpy(const std::vector<float>& v, size_t h, size_t w, size_t c) {
    auto* data = new float[v.size()];
    std::copy(v.begin(), v.end(), data);
    nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<float*>(p); });
    return nb::cast(nb::ndarray<nb::numpy, float, nb::ndim<3>>(data, {h, w, c}, owner));
}

}  // namespace

void bind_light_probe(nb::module_& m, SceneInput (*to_input)(const nb::dict&)) {
    m.def("light_selection_probe", [to_input](const nb::dict& scene, const nb::dict& settings) {
        SceneInput in;
        int samples = 64, threads = 1;
        uint64_t seed = 0;
        try {
            in = to_input(scene);
            if (settings.contains("samples")) samples = nb::cast<int>(settings["samples"]);
            if (settings.contains("seed")) seed = nb::cast<uint64_t>(settings["seed"]);
            if (settings.contains("threads")) threads = nb::cast<int>(settings["threads"]);
        } catch (const nb::cast_error& e) {
            const std::string what = std::string("invalid scene or probe settings: ") + e.what();
            throw nb::value_error(what.c_str());
        }
        if (samples < 1) throw nb::value_error("samples must be at least 1");
        Probe p;
        try {
            nb::gil_scoped_release release;
            p = run_probe(in, samples, seed, threads);
        } catch (const std::invalid_argument& e) {
            throw nb::value_error(e.what());
        }
        const size_t h = size_t(p.height), w = size_t(p.width), l = size_t(p.lights);
        nb::dict d;
        d["pmf"] = to_numpy(p.pmf, h, w, l);
        d["unoccluded"] = to_numpy(p.unoccluded, h, w, l);
        d["visible"] = to_numpy(p.visible, h, w, l);
        d["position"] = to_numpy(p.position, h, w, 3);
        d["normal"] = to_numpy(p.normal, h, w, 3);
        return d;
    }, nb::arg("scene"), nb::arg("settings"));
}

}  // namespace lantern
