// strahl: the one way files given by a user are read and written.
// Inputs are regular files only, opened without blocking (a FIFO or device
// never stalls the open) and bounded by a size cap. Outputs are checked
// before any work and written to a fresh temporary file (mkstemp: O_EXCL, so
// a planted symlink is never followed) in the target's folder, renamed over
// the target only when complete.
#ifndef ST_FILE_H
#define ST_FILE_H
#include "st_base.h"
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

// Size caps of what strahl reads (bytes). A file above its cap is refused
// with a message naming the file and the cap.
#define ST_CAP_SCENE (64ull << 20)   // scene JSON
#define ST_CAP_ASSET (2047ull << 20) // glTF, GLB and their buffers (tinygltf: 32-bit sizes)
#define ST_CAP_EXR (4ull << 30)      // EXR inputs of compare, merge, bench
#define ST_CAP_TEXT (64ull << 20)    // CSV of plot and bench --append, viewer scripts

// Opens path for reading: open(O_RDONLY | O_NONBLOCK | O_CLOEXEC), fstat on
// that descriptor, only a regular file of at most cap bytes (what: "scene
// file", named in the cap message). Returns the descriptor (blocking again)
// or -1 with an ST_ERR_INPUT message naming path; *size (may be NULL) gets
// the size fstat reports.
int st_open_input(const char *path, uint64_t cap, const char *what, uint64_t *size, st_err *err);
// The whole file through st_open_input, NUL-terminated; reading stops with an
// error past cap bytes even where fstat reports less (files of /proc).
char *st_read_input(const char *path, uint64_t cap, const char *what, size_t *len, st_err *err);
// Same as a stdio stream (line readers).
FILE *st_fopen_input(const char *path, uint64_t cap, const char *what, st_err *err);

// Resolves `rel`, a path written in an input file, against the folder `dir`
// into `out` and keeps it inside dir's folder tree: an absolute path, a ".."
// above dir, or a file that resolves (symlinks, realpath) outside
// realpath(dir) is refused (ST_ERR_INPUT naming rel; `what` says whose rule
// it is). A file that does not exist is left to the open to report.
// anywhere: no confinement (--allow-outside-assets).
bool st_path_confined(const char *dir, const char *rel, bool anywhere, char *out, size_t n,
                      st_err *err);

// Checks an output path before any work (ST_ERR_INPUT, exit 2): not empty;
// the extension is one of exts (e.g. {"exr", "png", NULL}, case-insensitive;
// NULL: any); the name fits NAME_MAX; it is not a directory or other
// non-regular file; its folder exists and a new file can be created there
// (probed with a temporary file that is removed at once); and it is not the
// same file (st_dev, st_ino) as any path of `inputs` (NULL-terminated, may be
// NULL). `flag` ("-o", "--csv") starts every message.
bool st_check_output(const char *flag, const char *path, const char *const *exts,
                     const char *const *inputs, st_err *err);
// Whether two paths name the same existing file (st_dev and st_ino).
bool st_same_file(const char *a, const char *b);

// An output being written: a temporary file beside `path`, renamed over it
// by st_out_commit; st_out_abort removes it. Neither follows a symlink
// planted at the temporary name; a symlink at `path` itself is replaced, its
// target is left alone.
typedef struct st_outfile {
    int fd;  // the temporary file (-1: none)
    FILE *f; // a stream on fd, from st_out_stream (NULL: none)
    char path[4096], tmp[4096 + 32];
} st_outfile;
bool st_out_begin(st_outfile *o, const char *path, st_err *err);
// A stdio stream on the temporary file (owned by o; st_out_commit closes it).
FILE *st_out_stream(st_outfile *o, st_err *err);
// Flushes, closes and renames; on any failure removes the temporary file.
bool st_out_commit(st_outfile *o, st_err *err);
void st_out_abort(st_outfile *o);

#ifdef __cplusplus
}
#endif
#endif
