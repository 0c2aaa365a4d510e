// Reading the Python scene dict (docs/scene_format.md) into a SceneInput: the typed getters the
// binding files share (bindings.cpp, material_bindings.cpp). Errors name the key and the culprit.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "scene/scene.h"

namespace lantern {

namespace nb = nanobind;

inline bool has(const nb::dict& d, const char* k) { return d.contains(k) && !d[k].is_none(); }

template <typename T>
inline T get(const nb::dict& d, const char* k, T fallback) {
    return has(d, k) ? nb::cast<T>(d[k]) : fallback;
}

inline Vec3 get_vec3(const nb::dict& d, const char* k, Vec3 fallback) {
    if (!has(d, k)) return fallback;
    auto v = nb::cast<std::vector<float>>(d[k]);
    if (v.size() < 3) throw std::invalid_argument(std::string("'") + k + "' needs 3 values");
    return {v[0], v[1], v[2]};
}

template <typename T>
inline std::vector<T> get_array(const nb::dict& d, const char* k, size_t cols, const std::string& who) {
    if (!has(d, k)) return {};
    // strict: the contract says float32 / uint32 C-contiguous; a silent conversion would hide
    // an exporter bug (and copy a large mesh)
    const char* want = std::is_same<T, float>::value     ? "float32"
                       : std::is_same<T, uint8_t>::value ? "uint8"
                                                         : "uint32";
    nb::ndarray<nb::device::cpu> any;
    if (!nb::try_cast(d[k], any, false)) {
        throw std::invalid_argument(who + ": '" + k + "' must be a numpy " + want + " array");
    }
    if (any.dtype() != nb::dtype<T>()) {
        throw std::invalid_argument(who + ": '" + k + "' must have dtype " + want);
    }
    nb::ndarray<const T, nb::c_contig, nb::device::cpu> a;
    if (!nb::try_cast(d[k], a, false)) {
        throw std::invalid_argument(who + ": '" + k + "' must be C-contiguous");
    }
    size_t n = 1;
    for (size_t i = 0; i < a.ndim(); ++i) n *= a.shape(i);
    if (cols > 1 && (a.ndim() != 2 || a.shape(1) != cols)) {
        throw std::invalid_argument(who + ": '" + k + "' must have shape (N, " +
                                    std::to_string(cols) + ")");
    }
    return std::vector<T>(a.data(), a.data() + n);
}

inline void get_matrix(const nb::dict& d, const char* k, float out[16]) {
    if (!has(d, k)) return;
    auto a = nb::cast<nb::ndarray<const float, nb::shape<4, 4>, nb::c_contig, nb::device::cpu>>(d[k]);
    for (int i = 0; i < 16; ++i) out[i] = a.data()[i];
}

// A homogeneous medium (docs/volumes.md) appended to in.media, its index (bindings.cpp)
int get_medium(const nb::handle& h, const std::string& name, SceneInput& in);
// The scene's "materials" into in.materials (material_bindings.cpp)
void get_materials(const nb::dict& scene, SceneInput& in);

}  // namespace lantern
