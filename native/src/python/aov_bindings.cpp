// lantern._core.render_aovs(scene, settings) -> dict of numpy arrays (integrator/aov.h): the
// first-hit data passes, with the GIL released while they render. bindings.cpp calls
// bind_aovs() once and lends its scene converter.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>

#include "integrator/aov.h"

namespace nb = nanobind;

namespace lantern {

namespace {

nb::object to_numpy(const std::vector<float>& v, int height, int width, int channels) {
    auto* data = new float[v.size()];
    std::copy(v.begin(), v.end(), data);
    nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<float*>(p); });
    if (channels == 1)
        return nb::cast(nb::ndarray<nb::numpy, float, nb::ndim<2>>(
            data, {size_t(height), size_t(width)}, owner));
    return nb::cast(nb::ndarray<nb::numpy, float, nb::ndim<3>>(
        data, {size_t(height), size_t(width), size_t(channels)}, owner));
}

}  // namespace

void bind_aovs(nb::module_& m, SceneInput (*to_input)(const nb::dict&)) {
    m.def("render_aovs", [to_input](const nb::dict& scene, const nb::dict& settings) {
        AovSettings st;
        SceneInput in;
        try {
            in = to_input(scene);
            if (settings.contains("spp")) st.spp = nb::cast<int>(settings["spp"]);
            if (settings.contains("seed")) st.seed = nb::cast<uint64_t>(settings["seed"]);
            if (settings.contains("threads")) st.threads = nb::cast<int>(settings["threads"]);
        } catch (const nb::cast_error& e) {
            const std::string what = std::string("invalid scene or AOV settings: ") + e.what();
            throw nb::value_error(what.c_str());
        }
        AovImages img;
        try {
            nb::gil_scoped_release release;
            img = render_aovs(in, st);
        } catch (const std::invalid_argument& e) {
            throw nb::value_error(e.what());
        }
        const int h = img.height, w = img.width;
        nb::dict d;
        d["Depth"] = to_numpy(img.depth, h, w, 1);
        d["Normal"] = to_numpy(img.normal, h, w, 3);
        d["Diffuse Color"] = to_numpy(img.diffuse_color, h, w, 3);
        d["Emission"] = to_numpy(img.emission, h, w, 3);
        d["Denoising Albedo"] = to_numpy(img.denoising_albedo, h, w, 3);
        d["Denoising Normal"] = to_numpy(img.denoising_normal, h, w, 3);
        d["Denoising Depth"] = to_numpy(img.denoising_depth, h, w, 1);
        d["warnings"] = img.warnings;
        return d;
    }, nb::arg("scene"), nb::arg("settings"));
}

}  // namespace lantern
