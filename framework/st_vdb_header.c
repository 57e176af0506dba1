// Bounds of an OpenVDB file's header, metadata and grid descriptors
// (st_vdb_header.h), after OpenVDB's io/Archive.cc, GridDescriptor.cc,
// MetaMap.cc and math/Transform.cc (file versions 220 to 224).
#define _GNU_SOURCE
#include "st_vdb_header.h"
#include <string.h>
#include <unistd.h>

typedef struct cursor {
    int fd;
    uint64_t at, size;
    const char *why; // the first problem met (NULL: none)
} cursor;

static bool take(cursor *c, void *out, uint64_t n, const char *what) {
    if (c->why) return false;
    if (n > c->size - c->at) return c->why = what, false;
    if (out && pread(c->fd, out, (size_t)n, (off_t)c->at) != (ssize_t)n)
        return c->why = "read error", false;
    c->at += n;
    return true;
}

static uint32_t u32(cursor *c, const char *what) {
    unsigned char b[4] = {0};
    take(c, b, 4, what);
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static uint64_t u64(cursor *c, const char *what) {
    uint64_t lo = u32(c, what);
    return lo | (uint64_t)u32(c, what) << 32;
}

// A length-prefixed string (io::readString), its first bytes into out.
static void string(cursor *c, char *out, size_t n, const char *what) {
    uint32_t len = u32(c, what);
    uint64_t keep = len < n - 1 ? len : n - 1;
    if (!take(c, out, keep, what)) return;
    out[keep] = 0;
    take(c, NULL, len - keep, what);
}

// Bytes of the fixed-size metadata types (TypedMetadata<T>::readValue reads
// sizeof(T) whatever the size field says); 0: read as the size field says.
static uint32_t fixed_size(const char *type) {
    static const struct {
        const char *name;
        uint32_t bytes;
    } t[] = {{"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},
             {"double", 8}, {"vec2i", 8},  {"vec2s", 8},  {"vec2d", 16},
             {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
             {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        if (!strcmp(type, t[i].name)) return t[i].bytes;
    return 0;
}

// MetaMap::readMeta: a count, then name, type name and sized value each.
static void meta_map(cursor *c) {
    uint32_t n = u32(c, "metadata count past the end");
    for (uint32_t i = 0; i < n && !c->why; i++) {
        char name[64], type[64];
        string(c, name, sizeof name, "metadata name past the end");
        string(c, type, sizeof type, "metadata type past the end");
        uint32_t bytes = u32(c, "metadata value past the end"), want = fixed_size(type);
        if (!c->why && want && bytes != want) c->why = "metadata value of the wrong size";
        take(c, NULL, bytes, "metadata value past the end");
    }
}

// Bytes of a map's data after its type name (math/Maps.h, each map's
// read()); 0: a map strahl refuses (frustum) or does not know.
static uint64_t map_bytes(const char *map) {
    if (!strcmp(map, "UniformScaleMap") || !strcmp(map, "ScaleMap")) return 5 * 24;
    if (!strcmp(map, "UniformScaleTranslateMap") || !strcmp(map, "ScaleTranslateMap"))
        return 6 * 24;
    if (!strcmp(map, "TranslationMap")) return 24;
    if (!strcmp(map, "AffineMap") || !strcmp(map, "UnitaryMap")) return 128;
    return 0;
}

// A float tree's root (tree/RootNode.h readTopology): a buffer count, the
// background, then tile and child counts that OpenVDB loops over; each
// tile takes 12 + 4 + 1 bytes, each child at least its coordinates and two
// 4096-byte masks. Counts beyond the grid's bytes would spin for minutes.
static void float_root(cursor *c, uint64_t end) {
    u32(c, "grid topology past the end");
    u32(c, "grid topology past the end"); // background
    uint64_t tiles = u32(c, "grid topology past the end");
    uint64_t children = u32(c, "grid topology past the end");
    if (!c->why && tiles * 17 + children * (12 + 8192) > end - c->at)
        c->why = "more root tiles or children than the grid's bytes hold";
}

bool st_vdb_check_header(int fd, uint64_t size, const char *path, st_err *err) {
    cursor c = {fd, 0, size, NULL};
    uint64_t magic = u64(&c, "shorter than a VDB header");
    if (!c.why && magic != 0x56444220ull) c.why = "not an OpenVDB file (bad magic number)";
    uint32_t version = u32(&c, "shorter than a VDB header");
    if (!c.why && (version < 220 || version > 224))
        return st_fail(err, ST_ERR_INPUT, "%s: OpenVDB file version %u, expected 220 to 224", path,
                       version);
    u32(&c, "shorter than a VDB header"), u32(&c, "shorter than a VDB header"); // library
    unsigned char offsets = 0;
    take(&c, &offsets, 1, "shorter than a VDB header");
    take(&c, NULL, 36, "shorter than a VDB header"); // UUID
    if (!c.why && !offsets) c.why = "a file without grid offsets (not supported)";
    meta_map(&c);
    uint32_t grids = u32(&c, "grid count past the end");
    for (uint32_t g = 0; g < grids && !c.why; g++) {
        char name[64], type[64];
        string(&c, name, sizeof name, "grid name past the end");
        string(&c, type, sizeof type, "grid type past the end");
        string(&c, name, sizeof name, "grid instance parent past the end");
        uint64_t grid_pos = u64(&c, "grid offsets past the end");
        uint64_t block_pos = u64(&c, "grid offsets past the end");
        uint64_t end_pos = u64(&c, "grid offsets past the end");
        if (c.why) break;
        if (!(grid_pos <= block_pos && block_pos <= end_pos && end_pos <= size)) {
            c.why = "grid offsets past the end";
            break;
        }
        // A grid follows its descriptor (io::Archive::writeGrid), so every
        // descriptor moves forward: an offset pointing back would make this
        // loop, and OpenVDB's, read the same descriptor up to 2^32 times
        // (found by fuzz_vdb_guard: a hang).
        if (grid_pos < c.at) {
            c.why = "grid offsets point back before the grid's descriptor";
            break;
        }
        // The grid itself: compression flags, metadata, transform's map name.
        cursor at = {fd, grid_pos, size, NULL};
        if (version >= 222) u32(&at, "grid compression past the end");
        meta_map(&at);
        char map[64];
        string(&at, map, sizeof map, "grid transform past the end");
        if (!at.why && !strcmp(map, "NonlinearFrustumMap"))
            at.why = "a frustum transform (expected an affine one)";
        uint64_t mb = map_bytes(map);
        if (!at.why && mb && take(&at, NULL, mb, "grid transform past the end") &&
            !strcmp(type, "Tree_float_5_4_3"))
            float_root(&at, block_pos); // the topology precedes the data blocks
        c.why = at.why;
        if (!c.why && at.at > block_pos) c.why = "grid metadata past its data";
        c.at = end_pos; // the next descriptor follows this grid's data
    }
    if (c.why)
        return st_fail(err, ST_ERR_INPUT, "%s: not a readable OpenVDB file: %s", path, c.why);
    return true;
}
