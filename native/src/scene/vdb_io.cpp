// OpenVDB files (scene/vdb_io.h): metadata, a float grid into a dense block, a writer. The
// memory a grid would take is checked from the file's metadata (file_bbox_min / _max, written
// by OpenVDB with every grid) before its voxels are read.
#include "scene/vdb_io.h"

#include <cstdint>
#include <stdexcept>

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

std::string float_grids(const std::vector<VdbGridMeta>& all) {
    std::string s;
    for (const VdbGridMeta& m : all)
        if (m.type == "float") s += (s.empty() ? "'" : ", '") + m.name + "'";
    return s.empty() ? "none" : s;
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
    if (meta->type != "float")
        throw std::runtime_error("'" + path + "': grid '" + name + "' holds " + meta->type +
                                 " values; only float grids are read as densities");
    auto too_big = [&](uint64_t n) {
        return std::runtime_error(
            "'" + path + "': grid '" + name + "' spans " + std::to_string(n) +
            " voxels over its active bounds (" + std::to_string(n / (1u << 18)) +
            " MiB as a dense block), above the limit of " + std::to_string(max_voxels) +
            " voxels; it is not loaded");
    };
    if (meta->has_bbox && meta->dense_voxels() > max_voxels) throw too_big(meta->dense_voxels());
    openvdb::io::File f = open(path);
    openvdb::GridBase::Ptr base = f.readGrid(name);
    f.close();
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) throw std::runtime_error("'" + path + "': grid '" + name + "' is not a float grid");
    const openvdb::math::Transform& xf = grid->transform();
    if (!xf.isLinear())
        throw std::runtime_error("'" + path + "': grid '" + name + "' has a transform that is "
                                 "not affine (a frustum); not supported");
    VdbDense out;
    out.name = name;
    out.background = grid->background();
    const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out.index_to_object[r][c] = m(c, r);  // OpenVDB: row vectors
    const openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
    if (bb.empty()) return out;
    const openvdb::Coord dim = bb.dim();
    const uint64_t n = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z());
    if (n > max_voxels) throw too_big(n);
    out.voxels.assign(n, out.background);
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bb, out.voxels.data());
    openvdb::tools::copyToDense(*grid, dense);
    for (int k = 0; k < 3; ++k) {
        out.dims[k] = dim[k];
        out.origin[k] = bb.min()[k];
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
