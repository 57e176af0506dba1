// OpenVDB files are parsed out of process (docs/security.md, VDB files): the
// helper strahl-vdb-read (framework/vdb_read/) reads the grid with OpenVDB
// and sends it back through a pipe; st_vdb.c starts it, bounds it and
// validates what comes back. A crash inside OpenVDB on a hostile file then
// ends the helper, not strahl. This header is what both sides share: the
// grid as read (before the scene's transform), the reply's layout and the
// helper's limits. Internal (not installed).
#ifndef ST_VDB_PROTO_H
#define ST_VDB_PROTO_H
#include "st_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// The helper's file name and its folder relative to libstrahl's.
#define ST_VDB_READER_NAME "strahl-vdb-read"
#define ST_VDB_READER_REL "../libexec/strahl/" ST_VDB_READER_NAME

// A float grid as read: the active block with its ring of zero voxels
// (st_density_grid's n, lo, values) and the grid's own index-to-world map
// (3x4 row major: world = map (i, j, k, 1)), without the scene's transform.
typedef struct st_vdb_raw {
    int n[3], lo[3];
    double map[12];
    float *values; // malloc'd, n[0] n[1] n[2], x fastest
} st_vdb_raw;

// The reply on the helper's stdout: this head, then msg_len bytes of message
// (status 1: bad input, the helper's one-line message) or the n[0] n[1] n[2]
// floats of the block (status 0), then end of file. Native byte order: both
// sides are the same build.
#define ST_VDB_MAGIC "stvdb01\n"
#define ST_VDB_MSG_MAX 1000u
typedef struct st_vdb_head {
    char magic[8];
    uint32_t status; // 0: a grid follows; 1: msg_len bytes of message follow
    uint32_t msg_len;
    int32_t n[3], lo[3];
    double map[12];
} st_vdb_head;

// The helper's limits, from the voxel cap: address space (what OpenVDB's
// tree and the dense copy of max_voxels need, plus the libraries), CPU
// seconds, and the wall-clock time after which the parent kills it.
typedef struct st_vdb_limits {
    uint64_t max_voxels;
    uint64_t as_bytes;
    unsigned cpu_s, wall_s;
} st_vdb_limits;
st_vdb_limits st_vdb_limits_for(uint64_t max_voxels);

// In process (the helper, and the fuzz target fuzz_vdb): checks the header
// (st_vdb_check_header) and reads float grid `grid` of the open VDB file fd
// with OpenVDB into *out; `path` only names the file in messages. False with
// an ST_ERR_INPUT message (the file is corrupt, lacks the grid, breaks a rule
// of st_vdb_load) or ST_ERR_RUNTIME (out of memory for a block within the
// cap). Must not be called in strahl itself: OpenVDB 10.0 can overflow a
// heap buffer on a crafted file.
bool st_vdb_read_raw(int fd, const char *path, const char *grid, uint64_t max_voxels,
                     st_vdb_raw *out, st_err *err);

// Places a raw grid by the scene's transform (world = translate + scale * p
// after the grid's map) into *out, taking raw->values (raw is emptied),
// after checking what a compromised helper could send: n within the cap,
// a finite invertible map, every value finite and >= 0. Messages name path.
bool st_vdb_place(st_vdb_raw *raw, const char *path, const char *grid, uint64_t max_voxels,
                  const double translate[3], const double scale[3], st_density_grid *out,
                  st_err *err);

// Reads a reply from fd (a pipe, or any fd for the fuzz target) until end of
// file or `deadline_ms` (CLOCK_MONOTONIC, 0: none), the block bounded by
// max_voxels. Status 1 comes back as ST_ERR_INPUT with the helper's message
// (control characters escaped); a short, long or inconsistent reply as
// ST_ERR_INPUT "malformed"; *timed_out set when the deadline passed.
bool st_vdb_read_reply(int fd, const char *path, uint64_t max_voxels, uint64_t deadline_ms,
                       st_vdb_raw *out, bool *timed_out, st_err *err);

// The helper's path beside libstrahl (ST_VDB_READER_REL); false with an
// ST_ERR_RUNTIME message when it is missing.
bool st_vdb_reader_path(char *out, size_t n, st_err *err);
// st_vdb_load with helper `exe` and limits l (st_vdb_load: the installed
// helper, st_vdb_limits_for(ST_VDB_MAX_VOXELS); tests: fake helpers and a
// short wall-clock limit). Opens path through the checked open and hands
// the helper that descriptor.
bool st_vdb_load_via(const char *exe, const st_vdb_limits *l, const char *path, const char *grid,
                     const double translate[3], const double scale[3], st_density_grid *out,
                     st_err *err);

#ifdef __cplusplus
}
#endif
#endif
