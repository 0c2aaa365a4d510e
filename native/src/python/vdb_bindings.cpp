// nanobind bindings of Volume objects' grids (docs/volumes.md): a scene dict's "grids" into
// SceneInput::grids, and OpenVDB files (scene/vdb_io.h): vdb_available, vdb_grids (metadata),
// vdb_read (a float grid as a dense block), vdb_write (tests). Errors surface as ValueError
// (bad input) or RuntimeError (a file that cannot be read, a grid too large).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>

#include "scene/scene.h"
#include "scene/vdb_io.h"

namespace nb = nanobind;

namespace lantern {

// scene["grids"]: [{"name": str, "voxels": float32 (nz, ny, nx), "index_to_world": float32
// (4, 4)}] (voxel (i, j, k) at index (i, j, k); voxel centres at integers)
void get_grids(const nb::dict& scene, SceneInput& in) {
    if (!scene.contains("grids") || scene["grids"].is_none()) return;
    for (nb::handle h : nb::cast<nb::list>(scene["grids"])) {
        nb::dict g = nb::cast<nb::dict>(h);
        GridInput gi;
        gi.name = g.contains("name") ? nb::cast<std::string>(g["name"]) : "grid";
        nb::ndarray<const float, nb::c_contig, nb::device::cpu> v;
        if (!g.contains("voxels") || !nb::try_cast(g["voxels"], v, false) ||
            !(v.ndim() == 3 || (v.ndim() == 4 && v.shape(3) == 3)))
            throw std::invalid_argument("grid '" + gi.name + "': 'voxels' must be a "
                                        "C-contiguous float32 array (nz, ny, nx), or (nz, ny, "
                                        "nx, 3) for a colour grid");
        gi.dims[0] = int32_t(v.shape(2));
        gi.dims[1] = int32_t(v.shape(1));
        gi.dims[2] = int32_t(v.shape(0));
        gi.channels = v.ndim() == 4 ? 3 : 1;
        if (v.size() > kMaxGridVoxels)
            throw std::invalid_argument("grid '" + gi.name + "': " + std::to_string(v.size()) +
                                        " voxels, above the limit of " +
                                        std::to_string(kMaxGridVoxels));
        gi.voxels.assign(v.data(), v.data() + v.size());
        nb::ndarray<const float, nb::shape<4, 4>, nb::c_contig, nb::device::cpu> m;
        if (!g.contains("index_to_world") || !nb::try_cast(g["index_to_world"], m, false))
            throw std::invalid_argument("grid '" + gi.name + "': 'index_to_world' must be a "
                                        "C-contiguous float32 (4, 4) array");
        for (int k = 0; k < 16; ++k) gi.index_to_world[k] = m.data()[k];
        in.grids.push_back(std::move(gi));
    }
}

void bind_vdb(nb::module_& m) {
    m.def("vdb_available", &vdb_available);
    m.def("vdb_max_voxels", []() { return kMaxGridVoxels; });
    m.def("vdb_grids", [](const std::string& path) {
        nb::list out;
        for (const VdbGridMeta& g : vdb_grids(path)) {
            nb::dict d;
            d["name"] = g.name;
            d["type"] = g.type;
            d["active_voxels"] = g.active_voxels;
            if (g.has_bbox) {
                d["bbox_min"] = nb::make_tuple(g.bbox_min[0], g.bbox_min[1], g.bbox_min[2]);
                d["bbox_max"] = nb::make_tuple(g.bbox_max[0], g.bbox_max[1], g.bbox_max[2]);
                d["dense_voxels"] = g.dense_voxels();
            }
            out.append(d);
        }
        return out;
    });
    // (voxels float32 (nz, ny, nx), index_to_object float64 (4, 4) of the block's voxel
    // indices, background); an empty grid gives voxels of shape (0, 0, 0)
    m.def("vdb_read", [](const std::string& path, const std::string& grid, uint64_t max_voxels) {
        VdbDense d;
        {
            nb::gil_scoped_release release;
            d = vdb_read_dense(path, grid, max_voxels);
        }
        auto* vox = new std::vector<float>(std::move(d.voxels));
        nb::capsule owner(vox,
                          [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
        // a vec3 grid: (nz, ny, nx, 3)
        const size_t shape[4] = {size_t(d.dims[2]), size_t(d.dims[1]), size_t(d.dims[0]), 3};
        nb::ndarray<nb::numpy, float> arr(vox->data(), d.channels == 3 ? 4 : 3, shape, owner);
        // the block's voxel (i, j, k) is the grid's origin + (i, j, k)
        auto* mat = new double[16];
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) mat[4 * r + c] = d.index_to_object[r][c];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) mat[4 * r + 3] += d.index_to_object[r][c] * d.origin[c];
        nb::capsule mowner(mat, [](void* p) noexcept { delete[] static_cast<double*>(p); });
        const size_t mshape[2] = {4, 4};
        nb::ndarray<nb::numpy, double, nb::ndim<2>> marr(mat, 2, mshape, mowner);
        return nb::make_tuple(arr, marr, d.background);
    }, nb::arg("path"), nb::arg("grid"), nb::arg("max_voxels") = kMaxGridVoxels);
    m.def("vdb_write", [](const std::string& path, const std::string& name,
                          nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu> v,
                          nb::ndarray<const double, nb::shape<4, 4>, nb::c_contig,
                                      nb::device::cpu> mat) {
        const int32_t dims[3] = {int32_t(v.shape(2)), int32_t(v.shape(1)), int32_t(v.shape(0))};
        double m4[4][4];
        for (int k = 0; k < 16; ++k) m4[k / 4][k % 4] = mat.data()[k];
        vdb_write_dense(path, name, v.data(), dims, m4);
    });
    // several grids of one shape and transform in one file (tests: a fire's density,
    // temperature and flame): grids is a list of (name, float32 (nz, ny, nx)) pairs
    m.def("vdb_write_grids", [](const std::string& path, const nb::list& grids,
                                nb::ndarray<const double, nb::shape<4, 4>, nb::c_contig,
                                            nb::device::cpu> mat) {
        std::vector<std::string> names;
        std::vector<const float*> data;
        int32_t dims[3] = {0, 0, 0};
        for (nb::handle h : grids) {
            auto pair = nb::cast<nb::tuple>(h);
            auto v = nb::cast<nb::ndarray<const float, nb::ndim<3>, nb::c_contig,
                                          nb::device::cpu>>(pair[1]);
            const int32_t d[3] = {int32_t(v.shape(2)), int32_t(v.shape(1)), int32_t(v.shape(0))};
            if (!names.empty() && (d[0] != dims[0] || d[1] != dims[1] || d[2] != dims[2]))
                throw std::invalid_argument("vdb_write_grids: the grids' shapes differ");
            std::copy(d, d + 3, dims);
            names.push_back(nb::cast<std::string>(pair[0]));
            data.push_back(v.data());
        }
        double m4[4][4];
        for (int k = 0; k < 16; ++k) m4[k / 4][k % 4] = mat.data()[k];
        vdb_write_dense_grids(path, names, data, dims, m4);
    });
    // grids of their own shapes and transforms in one file (tests: a smoke's density and
    // colour): a list of dicts {"name", "voxels": float32 (nz, ny, nx) or (nz, ny, nx, 3),
    // "index_to_object": float64 (4, 4), "double": bool (a vec3 grid written as Vec3D)}
    m.def("vdb_write_list", [](const std::string& path, const nb::list& grids) {
        std::vector<VdbWriteGrid> list;
        std::vector<nb::ndarray<const float, nb::c_contig, nb::device::cpu>> keep;
        for (nb::handle h : grids) {
            nb::dict g = nb::cast<nb::dict>(h);
            VdbWriteGrid w;
            w.name = nb::cast<std::string>(g["name"]);
            auto v = nb::cast<nb::ndarray<const float, nb::c_contig, nb::device::cpu>>(
                g["voxels"]);
            if (!(v.ndim() == 3 || (v.ndim() == 4 && v.shape(3) == 3)))
                throw std::invalid_argument("vdb_write_list: voxels (nz, ny, nx) or (.., 3)");
            w.channels = v.ndim() == 4 ? 3 : 1;
            for (int k = 0; k < 3; ++k) w.dims[k] = int32_t(v.shape(2 - k));
            w.voxels = v.data();
            auto mat = nb::cast<nb::ndarray<const double, nb::shape<4, 4>, nb::c_contig,
                                            nb::device::cpu>>(g["index_to_object"]);
            for (int k = 0; k < 16; ++k) w.index_to_object[k / 4][k % 4] = mat.data()[k];
            w.as_double = g.contains("double") && nb::cast<bool>(g["double"]);
            keep.push_back(v);
            list.push_back(w);
        }
        vdb_write_list(path, list);
    });
    m.def("vdb_write_sparse", [](const std::string& path, const std::string& name,
                                 nb::ndarray<const int32_t, nb::ndim<2>, nb::c_contig,
                                             nb::device::cpu> coords,
                                 nb::ndarray<const float, nb::ndim<1>, nb::c_contig,
                                             nb::device::cpu> values,
                                 nb::ndarray<const double, nb::shape<4, 4>, nb::c_contig,
                                             nb::device::cpu> mat) {
        if (coords.shape(1) != 3 || coords.shape(0) != values.shape(0))
            throw std::invalid_argument("vdb_write_sparse: coords (N, 3) and values (N,)");
        double m4[4][4];
        for (int k = 0; k < 16; ++k) m4[k / 4][k % 4] = mat.data()[k];
        vdb_write_sparse(path, name, coords.data(), values.data(), values.shape(0), m4);
    });
}

}  // namespace lantern
