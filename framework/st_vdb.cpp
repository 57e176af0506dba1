// OpenVDB density grids behind the C API of st_scene.h (st_vdb_load): the
// scene's medium.density {"vdb": ...}. OpenVDB reads the file; everything the
// renderer relies on is checked here (a regular file of bounded size, the
// grid's name and value type, an affine transform, background 0, a bounded
// voxel count, finite non-negative values), and the grid is copied into a
// dense block that C code samples (st_physics.c). No exception leaves this
// file.
#include "st_file.h"
#include "st_scene.h"
#include "st_vdb_header.h"

#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

namespace {

// Inverts the 3x4 affine map m (row major, world = A p + b); false if singular.
bool invert_affine(const double m[12], double out[12]) {
    const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9],
                 i = m[10];
    const double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    const double det = a * A + b * B + c * C;
    double scale = 0;
    for (int k : {0, 1, 2, 4, 5, 6, 8, 9, 10})
        scale = std::fmax(scale, std::fabs(m[k]));
    if (!std::isfinite(det) || !(std::fabs(det) > 1e-12 * scale * scale * scale)) return false;
    const double inv[9] = {A / det, -(b * i - c * h) / det, (b * f - c * e) / det,
                           B / det, (a * i - c * g) / det,  -(a * f - c * d) / det,
                           C / det, -(a * h - b * g) / det, (a * e - b * d) / det};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            out[4 * r + k] = inv[3 * r + k];
        out[4 * r + 3] = -(inv[3 * r] * m[3] + inv[3 * r + 1] * m[7] + inv[3 * r + 2] * m[11]);
    }
    for (int k = 0; k < 12; k++)
        if (!std::isfinite(out[k])) return false;
    return true;
}

// `s` with control characters escaped (\xHH): grid names come from the file
// and reach the terminal in messages.
static std::string printable(const std::string &s) {
    std::string out;
    for (unsigned char c : s) {
        if (c < 0x20 || c == 0x7f) {
            char b[8];
            std::snprintf(b, sizeof b, "\\x%02x", c);
            out += b;
        } else {
            out += (char)c;
        }
    }
    return out;
}

// The voxel cap, checked on the grid's statistics metadata (which OpenVDB
// writes with every grid) before a single voxel is read.
static bool declared_bounds(const openvdb::GridBase &meta, const char *path, const char *name,
                            st_err *err) {
    const std::string q = printable(name);
    auto lo = meta.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
    auto hi = meta.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
    if (!lo || !hi)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' has no file_bbox_min/file_bbox_max metadata (OpenVDB "
                       "writes them by default), so its size cannot be checked before it is read",
                       path, q.c_str());
    unsigned long long total = 1;
    long long span[3];
    for (int k = 0; k < 3; k++) {
        span[k] = (long long)hi->value()[k] - (long long)lo->value()[k] + 1;
        if (span[k] < 1)
            return st_fail(err, ST_ERR_INPUT, "%s: grid '%s': file_bbox_max is below file_bbox_min",
                           path, q.c_str());
        const unsigned long long n = (unsigned long long)span[k] + 2;
        total = n > ST_VDB_MAX_VOXELS ? ST_VDB_MAX_VOXELS + 1 : total * n;
        if (total > ST_VDB_MAX_VOXELS) break;
    }
    if (total > ST_VDB_MAX_VOXELS)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' spans %lld x %lld x %lld voxels, more than the limit of %llu",
                       path, q.c_str(), span[0], span[1], span[2],
                       (unsigned long long)ST_VDB_MAX_VOXELS);
    return true;
}

// Opens `path` through the checked open (a regular file within the cap, no
// FIFO or device) and reads float grid `name`, after the voxel cap.
static openvdb::FloatGrid::Ptr read_grid(const char *path, const char *name, st_err *err) {
    const int fd = st_open_input(path, ST_VDB_MAX_FILE_BYTES, "VDB file", nullptr, err);
    if (fd < 0) return nullptr;
    // OpenVDB opens by name: it gets the descriptor that was checked, so
    // the file read is the one checked (no swap between check and open).
    char proc[64];
    std::snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
    struct FdCloser {
        int fd;
        ~FdCloser() { close(fd); }
    } closer{fd};
    struct stat st;
    if (fstat(fd, &st) != 0 || !st_vdb_check_header(fd, (uint64_t)st.st_size, path, err))
        return nullptr;
    openvdb::initialize();
    openvdb::io::File file(proc);
    file.open(false); // no delayed loading: the file may change after this call
    std::string names;
    bool found = false;
    for (auto it = file.beginName(); it != file.endName(); ++it) {
        names += (names.empty() ? "" : ", ") + printable(it.gridName());
        found = found || it.gridName() == name;
    }
    const std::string q = printable(name);
    if (!found) {
        file.close();
        return st_fail(err, ST_ERR_INPUT, "%s: no grid named '%s' (the file has: %s)", path,
                       q.c_str(), names.empty() ? "no grids" : names.c_str()),
               nullptr;
    }
    openvdb::GridBase::Ptr base = file.readGridMetadata(name);
    if (!base->isType<openvdb::FloatGrid>()) {
        file.close();
        return st_fail(err, ST_ERR_INPUT, "%s: grid '%s' holds %s values, expected float", path,
                       q.c_str(), printable(base->valueType()).c_str()),
               nullptr;
    }
    if (!declared_bounds(*base, path, name, err)) {
        file.close();
        return nullptr;
    }
    // The whole grid: a clipped read would skip leaves through OpenVDB's
    // delayed-load mask, which asserts on a corrupt file (found by fuzz_vdb).
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(name));
    file.close();
    if (!grid) st_fail(err, ST_ERR_INPUT, "%s: grid '%s' could not be read", path, q.c_str());
    return grid;
}

// The block the grid's active voxels need, with a ring of zero voxels
// around them: its size in n and voxel count in *total.
static bool grid_block(const openvdb::FloatGrid &grid, const char *path, const char *name,
                       openvdb::Coord *lo_out, unsigned long long n[3],
                       unsigned long long *total_out, st_err *err) {
    const float bg = grid.background();
    if (bg != 0.0f)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' has background value %g, expected 0 (density outside "
                       "its voxels)",
                       path, name, (double)bg);
    const openvdb::math::Transform &xf = grid.transform();
    if (!xf.isLinear())
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' has a non-affine (frustum) transform, expected an affine one",
                       path, name);
    openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty())
        return st_fail(err, ST_ERR_INPUT, "%s: grid '%s' has no active voxels", path, name);
    // The block: the active bounding box and a ring of zero voxels around it.
    const openvdb::Coord lo = box.min(), hi = box.max();
    unsigned long long total = 1;
    for (int k = 0; k < 3; k++) {
        n[k] = (unsigned long long)((long long)hi[k] - lo[k] + 3);
        total = n[k] > ST_VDB_MAX_VOXELS ? ST_VDB_MAX_VOXELS + 1 : total * n[k];
        if (total > ST_VDB_MAX_VOXELS) break;
    }
    if (total > ST_VDB_MAX_VOXELS)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' spans %lld x %lld x %lld voxels, more than the limit of %llu",
                       path, name, (long long)hi[0] - lo[0] + 1, (long long)hi[1] - lo[1] + 1,
                       (long long)hi[2] - lo[2] + 1, (unsigned long long)ST_VDB_MAX_VOXELS);
    *lo_out = lo;
    *total_out = total;
    return true;
}

// The grid's index-to-world map and its inverse, with the scene's transform.
static bool grid_map(const openvdb::math::Transform &xf, const double translate[3],
                     const double scale[3], const char *path, const char *name, st_density_grid &g,
                     st_err *err) {
    // The grid's own index-to-world map from the images of the basis, then
    // the scene's scale and translation.
    const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
    const openvdb::Vec3d ax[3] = {xf.indexToWorld(openvdb::Vec3d(1, 0, 0)) - o,
                                  xf.indexToWorld(openvdb::Vec3d(0, 1, 0)) - o,
                                  xf.indexToWorld(openvdb::Vec3d(0, 0, 1)) - o};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            g.to_world[4 * r + k] = scale[r] * ax[k][r];
        g.to_world[4 * r + 3] = scale[r] * o[r] + translate[r];
    }
    if (!invert_affine(g.to_world, g.to_index))
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s': its index-to-world map (with the scene's transform) is "
                       "singular or not finite",
                       path, name);
    return true;
}

// Copies the block's voxels (checked: finite, >= 0) and its world bounds.
static bool grid_values(const openvdb::FloatGrid &grid, unsigned long long total, const char *path,
                        const char *name, st_density_grid &g, st_err *err) {
    g.values = (float *)std::calloc(total, sizeof(float));
    if (!g.values) return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
    double vmax = 0;
    for (int k = 1; k + 1 < g.n[2]; k++)
        for (int j = 1; j + 1 < g.n[1]; j++)
            for (int i = 1; i + 1 < g.n[0]; i++) {
                const openvdb::Coord c(g.lo[0] + i, g.lo[1] + j, g.lo[2] + k);
                const float v = acc.getValue(c);
                if (!std::isfinite(v) || v < 0.0f) {
                    std::free(g.values);
                    return st_fail(err, ST_ERR_INPUT,
                                   "%s: grid '%s': voxel (%d, %d, %d) has density %g, expected "
                                   "a finite value >= 0",
                                   path, name, c[0], c[1], c[2], (double)v);
                }
                g.values[((size_t)k * g.n[1] + j) * g.n[0] + i] = v;
                vmax = std::fmax(vmax, (double)v);
            }
    g.max_value = vmax;
    // World bounds: the images of the block's eight corners.
    for (int k = 0; k < 3; k++)
        g.bmin[k] = INFINITY, g.bmax[k] = -INFINITY;
    for (int c = 0; c < 8; c++) {
        const double p[3] = {(double)g.lo[0] + ((c & 1) ? g.n[0] - 1 : 0),
                             (double)g.lo[1] + ((c & 2) ? g.n[1] - 1 : 0),
                             (double)g.lo[2] + ((c & 4) ? g.n[2] - 1 : 0)};
        for (int r = 0; r < 3; r++) {
            const double w = g.to_world[4 * r] * p[0] + g.to_world[4 * r + 1] * p[1] +
                             g.to_world[4 * r + 2] * p[2] + g.to_world[4 * r + 3];
            g.bmin[r] = std::fmin(g.bmin[r], w);
            g.bmax[r] = std::fmax(g.bmax[r], w);
        }
    }
    return true;
}

bool load(const char *path, const char *name, const double translate[3], const double scale[3],
          st_density_grid *out, st_err *err) {
    openvdb::FloatGrid::Ptr grid = read_grid(path, name, err);
    if (!grid) return false;
    openvdb::Coord lo;
    unsigned long long n[3], total;
    const std::string q = printable(name); // for messages
    if (!grid_block(*grid, path, q.c_str(), &lo, n, &total, err)) return false;
    st_density_grid g;
    std::memset(&g, 0, sizeof g);
    for (int k = 0; k < 3; k++) {
        g.n[k] = (int)n[k];
        g.lo[k] = lo[k] - 1;
    }
    if (!grid_map(grid->transform(), translate, scale, path, q.c_str(), g, err) ||
        !grid_values(*grid, total, path, q.c_str(), g, err))
        return false;
    *out = g;
    return true;
}

} // namespace

extern "C" bool st_vdb_load(const char *path, const char *grid, const double translate[3],
                            const double scale[3], st_density_grid *out, st_err *err) {
    std::memset(out, 0, sizeof *out);
    try {
        return load(path, grid, translate, scale, out, err);
    } catch (const std::bad_alloc &) {
        // The voxel cap bounds what a valid file needs (its own allocation
        // reports itself): this is a size field read from a corrupt file.
        return st_fail(err, ST_ERR_INPUT,
                       "%s: not a readable OpenVDB file (corrupt or truncated: it asks for more "
                       "memory than is available)",
                       path);
    } catch (const std::exception &x) {
        return st_fail(err, ST_ERR_INPUT, "%s: not a readable OpenVDB file: %s", path,
                       printable(x.what()).c_str());
    } catch (...) {
        return st_fail(err, ST_ERR_INPUT, "%s: not a readable OpenVDB file", path);
    }
}

extern "C" void st_density_grid_free(st_density_grid *g) {
    if (!g) return;
    std::free(g->values);
    std::memset(g, 0, sizeof *g);
}
