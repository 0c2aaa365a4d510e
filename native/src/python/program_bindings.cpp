// lantern._core.evaluate_program(code, consts, num_const, result, points, normals) -> list of
// 3 floats per point (scene/material_program_host.h): a compiled node graph evaluated outside
// a scene, for the add-on's light and world node trees. bindings.cpp calls bind_programs().
#include <nanobind/nanobind.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>

#include "scene/material_program_host.h"

namespace nb = nanobind;

namespace lantern {

void bind_programs(nb::module_& m) {
    m.def(
        "evaluate_program",
        [](const std::vector<uint32_t>& code, const std::vector<float>& consts, int num_const,
           int result, const std::vector<float>& points, const std::vector<float>& normals) {
            try {
                nb::gil_scoped_release release;
                return evaluate_program(code, consts, num_const, result, points, normals);
            } catch (const std::invalid_argument& e) {
                throw nb::value_error(e.what());
            }
        },
        nb::arg("code"), nb::arg("consts"), nb::arg("num_const"), nb::arg("result"),
        nb::arg("points"), nb::arg("normals"));
}

}  // namespace lantern
