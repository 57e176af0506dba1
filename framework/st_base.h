// strahl: common types. Errors are returned, never printed deep inside: a
// function that can fail fills an st_err and returns false (or NULL).
#ifndef ST_BASE_H
#define ST_BASE_H
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Exit codes of the command line (design contract).
enum { ST_EXIT_OK = 0, ST_EXIT_RUNTIME = 1, ST_EXIT_INPUT = 2 };

// Error classes map onto exit codes: bad input -> 2, GPU/runtime -> 1.
typedef enum { ST_ERR_NONE = 0, ST_ERR_INPUT, ST_ERR_RUNTIME } st_err_kind;

typedef struct st_err {
    st_err_kind kind;
    char msg[1024];
} st_err;

// Sets err (if not NULL) with a printf-style message; returns false so callers
// can write `return st_fail(err, ST_ERR_INPUT, "...")`.
bool st_fail(st_err *err, st_err_kind kind, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
// Prefixes an existing message ("scene.json: " + msg).
void st_err_prefix(st_err *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
int st_err_exit_code(const st_err *err);

// Zeroed memory for one object of `size` bytes, or NULL with "out of memory"
// in err (a plugin's create: `fog *f = st_calloc(sizeof *f, err);`).
void *st_calloc(size_t size, st_err *err);

// Whole-file read of a regular file of at most 256 MiB (st_read_input);
// NUL-terminated. Returns NULL and fills err on failure.
char *st_read_file(const char *path, size_t *len, st_err *err);
// Joins dir and rel unless rel is absolute. out must hold n bytes.
void st_path_join(char *out, size_t n, const char *dir, const char *rel);
// Directory part of path ("." when none).
void st_path_dir(char *out, size_t n, const char *path);

double st_now_ms(void); // monotonic clock in milliseconds
double st_cpu_ms(void); // CPU time of the whole process (all threads) in milliseconds
// The median of n values (0 for none), e.g. of timing samples; v is not modified.
double st_median_f(const float *v, int n);
double st_median_d(const double *v, int n);

// The prefix libstrahl was installed to, found from the library's own file
// (<prefix>/lib/libstrahl.so), so an installed tree works wherever it was
// copied; "" when that cannot be determined.
const char *st_install_prefix(void);

#ifdef __cplusplus
}
#endif
#endif
