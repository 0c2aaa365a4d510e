// Scene parts the C++ volume tests build (test_volume.cpp, test_volume_nested.cpp,
// test_volume_vdb.cpp, test_volume_fire.cpp, test_bdpt_medium.cpp).
#pragma once

#include <cstdint>

#include "scene/scene.h"

namespace lantern::test {

// An axis-aligned box from lo to hi with outward-facing (counter-clockwise) triangles, two a
// face, all of material mat.
inline MeshInput box_mesh(Vec3 lo, Vec3 hi, uint32_t mat, const char* name = "box") {
    MeshInput m;
    m.name = name;
    const Vec3 c = (lo + hi) * 0.5f;
    auto quad = [&](Vec3 a, Vec3 b, Vec3 cc, Vec3 d) {
        const uint32_t base = uint32_t(m.positions.size() / 3);
        for (Vec3 p : {a, b, cc, d}) m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
        const Vec3 n = cross(b - a, cc - a), out = (a + cc) * 0.5f - c;
        if (dot(n, out) >= 0.0f)
            m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        else
            m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
        m.material_ids.insert(m.material_ids.end(), {mat, mat});
    };
    const float x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
    quad({x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0});
    quad({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});
    quad({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});
    quad({x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1});
    quad({x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, {x0, y0, z1});
    quad({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});
    return m;
}

}  // namespace lantern::test
