// The out-of-process VDB reader (st_vdb.c, st_vdb_reply.c): whatever the
// helper does (crashes, hangs, burns CPU, exits, sends a malformed or lying
// reply), st_vdb_load_via returns one ST_ERR_INPUT message naming the file,
// within the wall-clock limit; fake helpers are shell scripts. The real
// helper reads the cross-check cloud into the same block as in process.
#include "st_test.h"
#include "st_vdb_proto.h"

#include <math.h>
#include <string.h>
#include <sys/stat.h>

// Sanitizer builds: the helper skips RLIMIT_AS.
#if defined(__SANITIZE_ADDRESS__)
#define ST_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ST_TEST_ASAN 1
#endif
#endif

static char vdb[1024];

static void script(const char *name, const char *body, char *path, size_t n) {
    char text[2048];
    snprintf(text, sizeof text, "#!/bin/sh\n%s\n", body);
    st_test_write_text(ST_TEST_SCRATCH, name, text);
    snprintf(path, n, "%s/%s", ST_TEST_SCRATCH, name);
    chmod(path, 0755);
}

// Runs fake helper `body` with a wall-clock limit of wall_s; the load must
// fail with ST_ERR_INPUT, name the file and say `want`, within `max_ms`.
static void refused(const char *name, const char *body, unsigned wall_s, const char *want,
                    double max_ms) {
    char exe[1200];
    script(name, body, exe, sizeof exe);
    st_vdb_limits l = st_vdb_limits_for(1u << 20);
    l.wall_s = wall_s;
    const double t[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    st_density_grid g;
    st_err e = {0};
    const double t0 = st_now_ms();
    const bool ok = st_vdb_load_via(exe, &l, vdb, "density", t, s, &g, &e);
    const double ms = st_now_ms() - t0;
    CHECK(!ok && e.kind == ST_ERR_INPUT, "%s: expected bad input, got ok=%d kind %d: %s", name, ok,
          (int)e.kind, e.msg);
    CHECK(strstr(e.msg, vdb) == e.msg, "%s: the message does not start with the file: %s", name,
          e.msg);
    CHECK(strstr(e.msg, want) != NULL, "%s: expected '%s' in: %s", name, want, e.msg);
    CHECK(ms < max_ms, "%s: took %.0f ms (limit %.0f)", name, ms, max_ms);
    if (ok) st_density_grid_free(&g);
}

// A reply file: head (status 0, n = n0 x 3 x 3) and `count` floats of `v`.
static void reply_file(const char *name, int n0, size_t count, float v, int tail) {
    st_vdb_head h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, ST_VDB_MAGIC, sizeof h.magic);
    h.n[0] = n0, h.n[1] = h.n[2] = 3;
    h.map[0] = h.map[5] = h.map[10] = 1;
    char p[1200];
    snprintf(p, sizeof p, "%s/%s", ST_TEST_SCRATCH, name);
    FILE *f = fopen(p, "wb");
    CHECK(f != NULL, "writing %s", p);
    if (!f) return;
    fwrite(&h, sizeof h, 1, f);
    for (size_t i = 0; i < count; i++)
        fwrite(&v, sizeof v, 1, f);
    for (int i = 0; i < tail; i++)
        fputc(0, f);
    fclose(f);
}

static void test_fake_helpers(void) {
    refused("crash.sh", "kill -SEGV $$", 30, "crashed (signal 11", 20000);
    refused("abort.sh", "kill -ABRT $$", 30, "crashed (signal 6", 20000);
    // The wall-clock limit: 1 s, then SIGKILL (a loaded machine: 10 s).
    refused("hang.sh", "exec sleep 60", 1, "took longer than 1 s and was killed", 10000);
    refused("cpu.sh", "ulimit -S -t 1; while :; do :; done", 60, "used up its", 60000);
    refused("exit.sh", "exit 7", 30, "failed (exit status 7)", 20000);
    refused("empty.sh", "exit 0", 30, "malformed reply (no complete head)", 20000);
    refused("junk.sh", "head -c 4000 /dev/zero", 30, "malformed reply (bad magic)", 20000);
    char body[1400];
    reply_file("big.bin", 1 << 20, 0, 0, 0); // n = 2^20 x 3 x 3, over the 2^20 cap
    snprintf(body, sizeof body, "exec cat %s/big.bin", ST_TEST_SCRATCH);
    refused("big.sh", body, 30, "block above the voxel cap", 20000);
    reply_file("short.bin", 3, 26, 0.5f, 0);
    snprintf(body, sizeof body, "exec cat %s/short.bin", ST_TEST_SCRATCH);
    refused("short.sh", body, 30, "shorter than its head says", 20000);
    reply_file("long.bin", 3, 27, 0.5f, 1);
    snprintf(body, sizeof body, "exec cat %s/long.bin", ST_TEST_SCRATCH);
    refused("long.sh", body, 30, "longer than its head says", 20000);
    reply_file("nan.bin", 3, 27, NAN, 0);
    snprintf(body, sizeof body, "exec cat %s/nan.bin", ST_TEST_SCRATCH);
    refused("nan.sh", body, 30, "not a finite value >= 0", 20000);
    // A helper that writes its reply and then crashes is still refused.
    snprintf(body, sizeof body, "head -c 244 %s/long.bin; kill -SEGV $$", ST_TEST_SCRATCH);
    refused("late.sh", body, 30, "crashed (signal 11", 20000);
}

// The real helper: the cloud's block, placed with the scene's transform.
static void test_real_helper(void) {
    char exe[4200];
    st_err e = {0};
    CHECK(st_vdb_reader_path(exe, sizeof exe, &e), "helper: %s", e.msg);
    st_density_grid g;
    const double t[3] = {0.1, 1.3, -0.3}, s[3] = {1, 1, 1};
    CHECK(st_vdb_load(vdb, "density", t, s, &g, &e), "cloud.vdb: %s", e.msg);
    if (e.kind) return;
    CHECK(g.n[0] == 26 && g.n[1] == 26 && g.n[2] == 26, "cloud block %dx%dx%d", g.n[0], g.n[1],
          g.n[2]);
    double vmax = 0;
    for (size_t i = 0; i < (size_t)g.n[0] * g.n[1] * g.n[2]; i++)
        vmax = fmax(vmax, g.values[i]);
    CHECK(vmax == g.max_value && vmax > 0, "max_value %g, values' max %g", g.max_value, vmax);
    CHECK(g.values[0] == 0, "the ring is zero");
    st_density_grid_free(&g);
    // A grid the file lacks: the helper's own message comes through.
    CHECK(!st_vdb_load(vdb, "nope", t, s, &g, &e) && e.kind == ST_ERR_INPUT &&
              strstr(e.msg, "no grid named 'nope'"),
          "missing grid: %s", e.msg);
    // The known OpenVDB overflow (docs/security.md, finding 6): the helper
    // dies; strahl reports the file.
    char bad[1200];
    snprintf(bad, sizeof bad, "%s/tests/fuzz/known_crashes/openvdb_blosc_overflow.vdb",
             ST_TEST_SOURCE_DIR);
    CHECK(!st_vdb_load(bad, "density", t, s, &g, &e) && e.kind == ST_ERR_INPUT &&
              strstr(e.msg, bad) == e.msg,
          "blosc overflow: %s", e.msg);
    // RLIMIT_AS: with 16 MB of address space the helper cannot read even
    // the small cloud (the same call succeeds with the default limits
    // above). Sanitizer builds skip RLIMIT_AS (ASan's shadow).
#ifndef ST_TEST_ASAN
    st_vdb_limits tight = st_vdb_limits_for(1u << 20);
    tight.as_bytes = 16u << 20;
    CHECK(!st_vdb_load_via(exe, &tight, vdb, "density", t, s, &g, &e) && e.kind == ST_ERR_INPUT &&
              strstr(e.msg, vdb) == e.msg,
          "16 MB address space: %s", e.msg);
#endif
    // A missing helper is an installation problem (exit 1), named.
    const st_vdb_limits l = st_vdb_limits_for(1u << 20);
    CHECK(!st_vdb_load_via("/nonexistent/strahl-vdb-read", &l, vdb, "density", t, s, &g, &e) &&
              strstr(e.msg, "/nonexistent/strahl-vdb-read"),
          "missing helper: %s", e.msg);
}

int main(void) {
    snprintf(vdb, sizeof vdb, "%s/tests/data/crosscheck/cloud.vdb", ST_TEST_SOURCE_DIR);
    test_fake_helpers();
    test_real_helper();
    return st_test_summary("test_vdb_reader");
}
