// Minimal test harness: CHECK macros that count failures, helpers to run the
// strahl command and read images. Each test program prints
// "N passed, N failed" and exits non-zero on any failure.
#ifndef ST_TEST_H
#define ST_TEST_H
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static int st_t_pass, st_t_fail;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (cond) {                                                                                \
            st_t_pass++;                                                                           \
        } else {                                                                                   \
            st_t_fail++;                                                                           \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);               \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
        }                                                                                          \
    } while (0)

// |a - b| <= rel * |b| (+ abs_tol)
#define CHECK_REL(a, b, rel, abs_tol)                                                              \
    do {                                                                                           \
        double _a = (a), _b = (b);                                                                 \
        CHECK(fabs(_a - _b) <= (rel)*fabs(_b) + (abs_tol), "%s = %.9g, expected %.9g (rel %g)",    \
              #a, _a, _b, (double)(rel));                                                          \
    } while (0)

// A test that checked nothing has not shown anything: it fails.
static inline int st_test_summary(const char *name) {
    printf("%s: %d passed, %d failed\n", name, st_t_pass, st_t_fail);
    if (st_t_pass + st_t_fail == 0) fprintf(stderr, "%s: no checks ran\n", name);
    return (st_t_fail || st_t_pass == 0) ? 1 : 0;
}

// Runs a shell command; returns its exit code (or -1). Output goes to the
// test log.
static inline int st_test_sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
#include <stdarg.h>
static inline int st_test_sh(const char *fmt, ...) {
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    fprintf(stderr, "+ %s\n", cmd);
    fflush(stderr);
    int rc = system(cmd);
    if (rc == -1) return -1;
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
}

// Runs a shell command and captures stdout+stderr into buf.
static inline int st_test_capture(char *buf, size_t n, const char *cmd) {
    fprintf(stderr, "+ %s\n", cmd);
    char full[8300];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p) return -1;
    size_t got = fread(buf, 1, n - 1, p);
    buf[got] = 0;
    int rc = pclose(p);
    fprintf(stderr, "%s", buf);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
}

#ifdef ST_TEST_STRAHL
// "cd DIR && timeout T WRAP'strahl' ARGS" (ARGS from fmt, ap), captured
// into out like st_test_capture; WRAP: "" or a launcher such as xvfb-run.
static inline int st_test_strahl_v(char *out, size_t n, const char *dir, int timeout_s,
                                   const char *wrap, const char *fmt, va_list ap) {
    char args[4000], cmd[8000];
    vsnprintf(args, sizeof args, fmt, ap);
    snprintf(cmd, sizeof cmd, "cd '%s' && timeout %d %s'%s' %s", dir, timeout_s, wrap,
             ST_TEST_STRAHL, args);
    return st_test_capture(out, n, cmd);
}
#endif

// Writes text to DIR/NAME (a test's input file).
static inline void st_test_write_text(const char *dir, const char *name, const char *text) {
    char p[4200];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    if (f) fputs(text, f), fclose(f);
}

static inline int st_test_exists(const char *path) {
    struct stat st;
    return stat(path, &st) == 0;
}

#endif
