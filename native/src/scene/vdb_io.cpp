// OpenVDB files (scene/vdb_io.h): metadata, a float grid into a dense block, a writer. The
// memory a grid would take is checked from the file's metadata (file_bbox_min / _max, written
// by OpenVDB with every grid) before its voxels are read.
#include "scene/vdb_io.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <type_traits>

#ifdef LANTERN_HAVE_OPENVDB
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#endif

namespace lantern {

uint64_t VdbGridMeta::dense_voxels() const {
    uint64_t n = 1;
    for (int k = 0; k < 3; ++k) {
        if (bbox_max[k] < bbox_min[k]) return 0;
        const uint64_t d = uint64_t(int64_t(bbox_max[k]) - int64_t(bbox_min[k]) + 1);
        if (n > UINT64_MAX / d) return UINT64_MAX;  // saturates: int32 bounds span up to 2^96
        n *= d;
    }
    return n;
}

#ifndef LANTERN_HAVE_OPENVDB

namespace {
[[noreturn]] void missing(const std::string& path) {
    throw std::runtime_error("'" + path + "': Lantern was built without OpenVDB; Volume objects "
                             "(OpenVDB files) are not rendered");
}
}  // namespace

bool vdb_available() { return false; }
std::vector<VdbGridMeta> vdb_grids(const std::string& path) { missing(path); }
VdbDense vdb_read_dense(const std::string& path, const std::string&, uint64_t) { missing(path); }
void vdb_write_dense(const std::string& path, const std::string&, const float*, const int32_t[3],
                     const double[4][4]) {
    missing(path);
}
void vdb_write_sparse(const std::string& path, const std::string&, const int32_t*, const float*,
                      size_t, const double[4][4]) {
    missing(path);
}
void vdb_write_list(const std::string& path, const std::vector<VdbWriteGrid>&) { missing(path); }
void vdb_write_dense_grids(const std::string& path, const std::vector<std::string>&,
                           const std::vector<const float*>&, const int32_t[3],
                           const double[4][4]) {
    missing(path);
}

#else

namespace {

void init() {
    static const bool once = [] {
        openvdb::initialize();
        return true;
    }();
    (void)once;
}

// The file opened for reading, with a clear message for what cannot be read.
openvdb::io::File open(const std::string& path) {
    init();
    openvdb::io::File f(path);
    try {
        f.open(false);  // no delayed loading: the file may change under a session
    } catch (const std::exception& e) {
        throw std::runtime_error("'" + path + "' cannot be read as an OpenVDB file (" +
                                 e.what() + ")");
    }
    return f;
}

VdbGridMeta meta_of(const openvdb::GridBase& g) {
    VdbGridMeta m;
    m.name = g.getName();
    m.type = g.valueType();
    auto mn = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
    auto mx = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
    if (mn && mx) {
        m.has_bbox = true;
        for (int k = 0; k < 3; ++k) {
            m.bbox_min[k] = mn->value()[k];
            m.bbox_max[k] = mx->value()[k];
        }
    }
    if (auto n = g.getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT))
        m.active_voxels = uint64_t(n->value());
    return m;
}

bool is_vec3(const std::string& type) { return type == "vec3s" || type == "vec3d"; }

std::string float_grids(const std::vector<VdbGridMeta>& all) {
    std::string s;
    for (const VdbGridMeta& m : all)
        if (m.type == "float" || is_vec3(m.type))
            s += (s.empty() ? "'" : ", '") + m.name + (m.type == "float" ? "'" : "' (vec3)");
    return s.empty() ? "none" : s;
}

// The grid's active bounds copied into out (channels floats per voxel, x fastest).
template <class GridT>
void copy_dense(const GridT& grid, const openvdb::CoordBBox& bb, int channels,
                std::vector<float>& out) {
    using V = typename GridT::ValueType;
    const openvdb::Coord dim = bb.dim();
    const size_t n = size_t(dim.x()) * size_t(dim.y()) * size_t(dim.z());
    if constexpr (std::is_same_v<V, float>) {
        out.assign(n, grid.background());
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bb, out.data());
        openvdb::tools::copyToDense(grid, dense);
    } else {
        std::vector<V> tmp(n, grid.background());
        openvdb::tools::Dense<V, openvdb::tools::LayoutXYZ> dense(bb, tmp.data());
        openvdb::tools::copyToDense(grid, dense);
        out.resize(n * size_t(channels));
        for (size_t k = 0; k < n; ++k)
            for (int c = 0; c < 3; ++c) out[3 * k + size_t(c)] = float(tmp[k][c]);
    }
}

template <class GridT>
void read_into(const openvdb::GridBase::Ptr& base, const std::string& where, uint64_t max_floats,
               const std::function<std::runtime_error(uint64_t)>& too_big, VdbDense& out) {
    typename GridT::Ptr grid = openvdb::gridPtrCast<GridT>(base);
    if (!grid) throw std::runtime_error(where + " is not of the type its metadata says");
    const openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
    if (bb.empty()) return;
    const openvdb::Coord dim = bb.dim();
    const uint64_t n = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z());
    if (n > max_floats / uint64_t(out.channels)) throw too_big(n);
    copy_dense(*grid, bb, out.channels, out.voxels);
    for (int k = 0; k < 3; ++k) {
        out.dims[k] = dim[k];
        out.origin[k] = bb.min()[k];
    }
}

}  // namespace

bool vdb_available() { return true; }

std::vector<VdbGridMeta> vdb_grids(const std::string& path) {
    openvdb::io::File f = open(path);
    std::vector<VdbGridMeta> out;
    openvdb::GridPtrVecPtr grids = f.readAllGridMetadata();
    for (const openvdb::GridBase::Ptr& g : *grids) out.push_back(meta_of(*g));
    f.close();
    return out;
}

VdbDense vdb_read_dense(const std::string& path, const std::string& name, uint64_t max_voxels) {
    const std::vector<VdbGridMeta> all = vdb_grids(path);
    const VdbGridMeta* meta = nullptr;
    for (const VdbGridMeta& m : all)
        if (m.name == name) meta = &m;
    if (!meta)
        throw std::runtime_error("'" + path + "' has no grid named '" + name +
                                 "' (its float grids: " + float_grids(all) + ")");
    const bool vec3 = is_vec3(meta->type);
    if (meta->type != "float" && !vec3)
        throw std::runtime_error("'" + path + "': grid '" + name + "' holds " + meta->type +
                                 " values; only float grids (densities) and vec3 grids "
                                 "(colours) are read");
    const uint64_t channels = vec3 ? 3 : 1;
    auto too_big = [&](uint64_t n) {
        return std::runtime_error(
            "'" + path + "': grid '" + name + "' spans " + std::to_string(n) +
            " voxels over its active bounds (" + std::to_string(n * channels / (1u << 18)) +
            " MiB as a dense block" + (vec3 ? " of 3 floats each" : "") +
            "), above the limit of " + std::to_string(max_voxels) +
            (vec3 ? " floats" : " voxels") + "; it is not loaded");
    };
    if (meta->has_bbox && meta->dense_voxels() > max_voxels / channels)
        throw too_big(meta->dense_voxels());
    openvdb::io::File f = open(path);
    openvdb::GridBase::Ptr base = f.readGrid(name);
    f.close();
    const openvdb::math::Transform& xf = base->transform();
    if (!xf.isLinear())
        throw std::runtime_error("'" + path + "': grid '" + name + "' has a transform that is "
                                 "not affine (a frustum); not supported");
    VdbDense out;
    out.name = name;
    out.channels = int32_t(channels);
    const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out.index_to_object[r][c] = m(c, r);  // OpenVDB: row vectors
    const std::string where = "'" + path + "': grid '" + name + "'";
    if (meta->type == "float") {
        out.background = openvdb::gridPtrCast<openvdb::FloatGrid>(base)
                             ? openvdb::gridPtrCast<openvdb::FloatGrid>(base)->background()
                             : 0.0f;
        read_into<openvdb::FloatGrid>(base, where, max_voxels, too_big, out);
    } else if (meta->type == "vec3s") {
        if (auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base))
            out.background = float(g->background().lengthSqr() > 0 ? g->background().length() : 0);
        read_into<openvdb::Vec3SGrid>(base, where, max_voxels, too_big, out);
    } else {
        if (auto g = openvdb::gridPtrCast<openvdb::Vec3DGrid>(base))
            out.background = float(g->background().lengthSqr() > 0 ? g->background().length() : 0);
        read_into<openvdb::Vec3DGrid>(base, where, max_voxels, too_big, out);
    }
    return out;
}

namespace {
openvdb::FloatGrid::Ptr new_grid(const std::string& name, const double index_to_object[4][4]) {
    init();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    openvdb::Mat4d m;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m(c, r) = index_to_object[r][c];
    grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
    return grid;
}

void write_grid(const std::string& path, const openvdb::FloatGrid::Ptr& grid) {
    openvdb::io::File f(path);
    f.write({grid});
    f.close();
}

openvdb::FloatGrid::Ptr dense_grid(const std::string& name, const float* voxels,
                                   const int32_t dims[3], const double index_to_object[4][4]) {
    openvdb::FloatGrid::Ptr grid = new_grid(name, index_to_object);
    if (dims[0] > 0 && dims[1] > 0 && dims[2] > 0) {
        const openvdb::CoordBBox bb(openvdb::Coord(0, 0, 0),
                                    openvdb::Coord(dims[0] - 1, dims[1] - 1, dims[2] - 1));
        float* data = const_cast<float*>(voxels);  // read only: copyFromDense
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bb, data);
        openvdb::tools::copyFromDense(dense, *grid, 0.0f);
    }
    return grid;
}
}  // namespace

void vdb_write_dense_grids(const std::string& path, const std::vector<std::string>& names,
                           const std::vector<const float*>& voxels, const int32_t dims[3],
                           const double index_to_object[4][4]) {
    openvdb::GridPtrVec grids;
    for (size_t k = 0; k < names.size(); ++k)
        grids.push_back(dense_grid(names[k], voxels[k], dims, index_to_object));
    openvdb::io::File f(path);
    f.write(grids);
    f.close();
}

namespace {
template <class GridT>
openvdb::GridBase::Ptr vec3_grid(const VdbWriteGrid& w) {
    using V = typename GridT::ValueType;
    typename GridT::Ptr grid = GridT::create(V(0));
    grid->setName(w.name);
    openvdb::Mat4d m;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m(c, r) = w.index_to_object[r][c];
    grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
    typename GridT::Accessor acc = grid->getAccessor();
    for (int k = 0; k < w.dims[2]; ++k)
        for (int j = 0; j < w.dims[1]; ++j)
            for (int i = 0; i < w.dims[0]; ++i) {
                const float* x =
                    w.voxels + 3 * ((size_t(k) * size_t(w.dims[1]) + size_t(j)) * w.dims[0] + i);
                if (x[0] != 0.0f || x[1] != 0.0f || x[2] != 0.0f || std::isnan(x[0]) ||
                    std::isnan(x[1]) || std::isnan(x[2]))
                    acc.setValue(openvdb::Coord(i, j, k), V(x[0], x[1], x[2]));
            }
    return grid;
}
}  // namespace

void vdb_write_list(const std::string& path, const std::vector<VdbWriteGrid>& list) {
    init();
    openvdb::GridPtrVec grids;
    for (const VdbWriteGrid& w : list) {
        if (w.channels == 1)
            grids.push_back(dense_grid(w.name, w.voxels, w.dims, w.index_to_object));
        else if (w.channels == 3 && w.as_double)
            grids.push_back(vec3_grid<openvdb::Vec3DGrid>(w));
        else if (w.channels == 3)
            grids.push_back(vec3_grid<openvdb::Vec3SGrid>(w));
        else
            throw std::invalid_argument("grid '" + w.name + "': 1 or 3 channels");
    }
    openvdb::io::File f(path);
    f.write(grids);
    f.close();
}

void vdb_write_sparse(const std::string& path, const std::string& name, const int32_t* coords,
                      const float* values, size_t n, const double index_to_object[4][4]) {
    openvdb::FloatGrid::Ptr grid = new_grid(name, index_to_object);
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    for (size_t k = 0; k < n; ++k)
        acc.setValue(openvdb::Coord(coords[3 * k], coords[3 * k + 1], coords[3 * k + 2]),
                     values[k]);
    write_grid(path, grid);
}

void vdb_write_dense(const std::string& path, const std::string& name, const float* voxels,
                     const int32_t dims[3], const double index_to_object[4][4]) {
    write_grid(path, dense_grid(name, voxels, dims, index_to_object));
}

#endif

}  // namespace lantern
