#define _POSIX_C_SOURCE 200809L
#include "st_base.h"
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

bool st_fail(st_err *err, st_err_kind kind, const char *fmt, ...) {
    if (!err) return false;
    err->kind = kind;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return false;
}

void st_err_prefix(st_err *err, const char *fmt, ...) {
    if (!err) return;
    char pre[512], old[sizeof err->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(pre, sizeof pre, fmt, ap);
    va_end(ap);
    memcpy(old, err->msg, sizeof old);
    size_t n = strlen(pre), cap = sizeof err->msg - 1;
    if (n > cap) n = cap;
    memcpy(err->msg, pre, n);
    size_t m = strnlen(old, sizeof old);
    if (m > cap - n) m = cap - n;
    memcpy(err->msg + n, old, m);
    err->msg[n + m] = 0;
}

int st_err_exit_code(const st_err *err) {
    if (!err || err->kind == ST_ERR_NONE) return ST_EXIT_OK;
    return err->kind == ST_ERR_INPUT ? ST_EXIT_INPUT : ST_EXIT_RUNTIME;
}

void *st_calloc(size_t size, st_err *err) {
    void *p = calloc(1, size);
    if (!p) st_fail(err, ST_ERR_RUNTIME, "out of memory (%zu bytes)", size);
    return p;
}

void st_path_join(char *out, size_t n, const char *dir, const char *rel) {
    if (rel[0] == '/' || !dir || !dir[0])
        snprintf(out, n, "%s", rel);
    else
        snprintf(out, n, "%s/%s", dir, rel);
}

void st_path_dir(char *out, size_t n, const char *path) {
    const char *s = strrchr(path, '/');
    if (!s)
        snprintf(out, n, ".");
    else if (s == path)
        snprintf(out, n, "/");
    else
        snprintf(out, n, "%.*s", (int)(s - path), path);
}

double st_now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double st_cpu_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}
