// Host-only entry to node programs outside a scene: one program evaluated at given points
// (the add-on folds light node trees and bakes world node trees through it,
// python/program_bindings.cpp). The same checks as a scene's programs (an error names the
// instruction); no textures, no attributes (they read magenta and 0).
#pragma once

#include <cstdint>
#include <vector>

namespace lantern {

// Result (3 floats) per point; points and normals: 3 floats each (the normal is also the
// direction towards the viewer). NaN and infinities read 0, as at hits.
std::vector<float> evaluate_program(const std::vector<uint32_t>& code,
                                    const std::vector<float>& consts, int num_const, int result,
                                    const std::vector<float>& points,
                                    const std::vector<float>& normals);

}  // namespace lantern
