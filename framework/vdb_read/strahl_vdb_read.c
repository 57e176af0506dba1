// strahl-vdb-read: reads one float grid of the VDB file on stdin with
// OpenVDB and writes it to stdout (st_vdb_proto.h), for st_vdb_load. Not a
// command for users: strahl starts it with a fixed argv
//   strahl-vdb-read 1 PATH GRID MAX_VOXELS AS_BYTES CPU_SECONDS
// (1: the reply's version; PATH only names the file in messages; stdin is
// the descriptor strahl opened and checked). Its limits are set before a
// byte of the file is read, so a hostile file that OpenVDB mishandles ends
// this process (a crash, RLIMIT_AS, RLIMIT_CPU, strahl's wall-clock kill)
// and never strahl. Exit 0 once a reply is written, 3 on a bad argv or a
// failed write.
#define _GNU_SOURCE
#include "st_vdb_proto.h"

#include <errno.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

// ASan reserves terabytes of address space for its shadow: RLIMIT_AS would
// stop it at start-up, so a sanitized build keeps only the time limits.
#if defined(__SANITIZE_ADDRESS__)
#define ST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ST_ASAN 1
#endif
#endif

static bool parse_u64(const char *s, uint64_t *out) {
    if (!s || !*s) return false;
    char *end;
    errno = 0;
    const unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end || s[0] == '-') return false;
    *out = v;
    return true;
}

static bool set_limit(int what, uint64_t soft, uint64_t hard) {
    const struct rlimit r = {(rlim_t)soft, (rlim_t)hard};
    return setrlimit(what, &r) == 0;
}

static bool write_all(const void *buf, size_t n) {
    const char *p = buf;
    while (n) {
        const ssize_t w = write(1, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        p += w, n -= (size_t)w;
    }
    return true;
}

static int reply(const st_vdb_raw *g, const st_err *err) {
    st_vdb_head h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, ST_VDB_MAGIC, sizeof h.magic);
    if (!g) {
        size_t len = strlen(err->msg);
        len = len > ST_VDB_MSG_MAX ? ST_VDB_MSG_MAX : len;
        h.status = err->kind == ST_ERR_RUNTIME ? 2 : 1;
        h.msg_len = (uint32_t)(len ? len : 1);
        return write_all(&h, sizeof h) && write_all(len ? err->msg : "?", h.msg_len) ? 0 : 3;
    }
    memcpy(h.n, g->n, sizeof h.n);
    memcpy(h.lo, g->lo, sizeof h.lo);
    memcpy(h.map, g->map, sizeof h.map);
    const size_t bytes = (size_t)g->n[0] * g->n[1] * g->n[2] * sizeof(float);
    return write_all(&h, sizeof h) && write_all(g->values, bytes) ? 0 : 3;
}

int main(int argc, char **argv) {
    uint64_t cap, as, cpu;
    if (argc != 7 || strcmp(argv[1], "1") != 0 || !parse_u64(argv[4], &cap) ||
        !parse_u64(argv[5], &as) || !parse_u64(argv[6], &cpu) || cpu == 0) {
        fprintf(stderr,
                "usage: %s 1 PATH GRID MAX_VOXELS AS_BYTES CPU_SECONDS (started by "
                "strahl, not by hand)\n",
                argv[0]);
        return 3;
    }
    // One malloc arena: each thread's own would reserve 64 MB of address
    // space against RLIMIT_AS without using it.
    mallopt(M_ARENA_MAX, 1);
    bool ok = set_limit(RLIMIT_CPU, cpu, cpu + 1) && set_limit(RLIMIT_CORE, 0, 0);
#ifndef ST_ASAN
    ok = ok && set_limit(RLIMIT_AS, as, as);
#else
    (void)as;
#endif
    if (!ok) {
        fprintf(stderr, "%s: setrlimit: %s\n", argv[0], strerror(errno));
        return 3;
    }
    st_vdb_raw g;
    st_err err = {0};
    const bool ok_read = st_vdb_read_raw(0, argv[2], argv[3], cap, &g, &err);
    // _exit: the reply is all that counts. No static destructors (OpenVDB's
    // registries), and no leak check of a sanitizer build turning the exit
    // status of a reply already sent into a failure (OpenVDB leaks the node
    // it was reading when a corrupt file makes it throw).
    _exit(ok_read ? reply(&g, &err) : reply(NULL, &err));
}
