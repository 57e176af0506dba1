// OpenVDB density grids, read in process (st_vdb_read_raw, st_vdb_proto.h):
// run only inside the helper strahl-vdb-read and the fuzz target, never in
// strahl itself, because OpenVDB 10.0 overflows a heap buffer on a crafted
// file (docs/security.md). Everything the renderer relies on that needs
// OpenVDB is checked here (the grid's name and value type, an affine
// transform, background 0, a bounded voxel count, finite non-negative
// values); the block goes back with the grid's own index-to-world map, and
// st_vdb_place (st_vdb.c) checks and places it. No exception leaves this file.
#include "st_vdb_header.h"
#include "st_vdb_proto.h"

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
                            uint64_t cap, st_err *err) {
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
        total = n > cap ? cap + 1 : total * n;
        if (total > cap) break;
    }
    if (total > cap)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' spans %lld x %lld x %lld voxels, more than the limit of %llu",
                       path, q.c_str(), span[0], span[1], span[2], (unsigned long long)cap);
    return true;
}

// Reads float grid `name` of the open file fd, after the header check and
// the voxel cap on the grid's declared box.
static openvdb::FloatGrid::Ptr read_grid(int fd, const char *path, const char *name, uint64_t cap,
                                         st_err *err) {
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        return st_fail(err, ST_ERR_INPUT, "%s: not a regular file", path), nullptr;
    if (!st_vdb_check_header(fd, (uint64_t)st.st_size, path, err)) return nullptr;
    // OpenVDB opens by name: it gets the descriptor that was checked, so the
    // file read is the one checked (no swap between check and open).
    char proc[64];
    std::snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
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
    if (!declared_bounds(*base, path, name, cap, err)) {
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
                       uint64_t cap, openvdb::Coord *lo_out, unsigned long long n[3],
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
        total = n[k] > cap ? cap + 1 : total * n[k];
        if (total > cap) break;
    }
    if (total > cap)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' spans %lld x %lld x %lld voxels, more than the limit of %llu",
                       path, name, (long long)hi[0] - lo[0] + 1, (long long)hi[1] - lo[1] + 1,
                       (long long)hi[2] - lo[2] + 1, (unsigned long long)cap);
    *lo_out = lo;
    *total_out = total;
    return true;
}

// The grid's own index-to-world map, from the images of the basis.
static void grid_map(const openvdb::math::Transform &xf, double map[12]) {
    const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
    const openvdb::Vec3d ax[3] = {xf.indexToWorld(openvdb::Vec3d(1, 0, 0)) - o,
                                  xf.indexToWorld(openvdb::Vec3d(0, 1, 0)) - o,
                                  xf.indexToWorld(openvdb::Vec3d(0, 0, 1)) - o};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++)
            map[4 * r + k] = ax[k][r];
        map[4 * r + 3] = o[r];
    }
}

// Copies the block's voxels (checked: finite, >= 0); the ring stays 0.
static bool grid_values(const openvdb::FloatGrid &grid, unsigned long long total, const char *path,
                        const char *name, st_vdb_raw &g, st_err *err) {
    g.values = (float *)std::calloc(total, sizeof(float));
    // Within the voxel cap, so in the helper this is its RLIMIT_AS, which
    // the file's own tree has used up: the file's doing, not the machine's.
    if (!g.values)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: grid '%s' needs more memory than the VDB reader's limit allows", path,
                       name);
    openvdb::FloatGrid::ConstAccessor acc = grid.getConstAccessor();
    for (int k = 1; k + 1 < g.n[2]; k++)
        for (int j = 1; j + 1 < g.n[1]; j++)
            for (int i = 1; i + 1 < g.n[0]; i++) {
                const openvdb::Coord c(g.lo[0] + i, g.lo[1] + j, g.lo[2] + k);
                const float v = acc.getValue(c);
                if (!std::isfinite(v) || v < 0.0f) {
                    std::free(g.values);
                    g.values = nullptr;
                    return st_fail(err, ST_ERR_INPUT,
                                   "%s: grid '%s': voxel (%d, %d, %d) has density %g, expected "
                                   "a finite value >= 0",
                                   path, name, c[0], c[1], c[2], (double)v);
                }
                g.values[((size_t)k * g.n[1] + j) * g.n[0] + i] = v;
            }
    return true;
}

bool read_raw(int fd, const char *path, const char *name, uint64_t cap, st_vdb_raw *out,
              st_err *err) {
    openvdb::FloatGrid::Ptr grid = read_grid(fd, path, name, cap, err);
    if (!grid) return false;
    openvdb::Coord lo;
    unsigned long long n[3], total;
    const std::string q = printable(name); // for messages
    if (!grid_block(*grid, path, q.c_str(), cap, &lo, n, &total, err)) return false;
    st_vdb_raw g;
    std::memset(&g, 0, sizeof g);
    for (int k = 0; k < 3; k++) {
        g.n[k] = (int)n[k];
        g.lo[k] = lo[k] - 1;
    }
    grid_map(grid->transform(), g.map);
    if (!grid_values(*grid, total, path, q.c_str(), g, err)) return false;
    *out = g;
    return true;
}

} // namespace

extern "C" bool st_vdb_read_raw(int fd, const char *path, const char *grid, uint64_t max_voxels,
                                st_vdb_raw *out, st_err *err) {
    std::memset(out, 0, sizeof *out);
    try {
        return read_raw(fd, path, grid, max_voxels, out, err);
    } catch (const std::bad_alloc &) {
        // The voxel cap bounds what a valid file needs (its own allocation
        // reports itself): this is a size field read from a corrupt file.
        return st_fail(err, ST_ERR_INPUT,
                       "%s: not a readable OpenVDB file (corrupt or truncated: it asks for more "
                       "memory than the VDB reader may use)",
                       path);
    } catch (const std::exception &x) {
        return st_fail(err, ST_ERR_INPUT, "%s: not a readable OpenVDB file: %s", path,
                       printable(x.what()).c_str());
    } catch (...) {
        return st_fail(err, ST_ERR_INPUT, "%s: not a readable OpenVDB file", path);
    }
}
