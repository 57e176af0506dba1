// `strahl bench --shard I/N`: the shards together run every setting of the
// sweep exactly once, only shard 1 writes the header, so their concatenation
// is the CSV of the unsharded run (same settings, same columns); bad --shard
// values are bad input. Also checks the error columns against a reference
// without standard-error channels: debiased = raw, reference noise 0; and
// against a far too noisy one: one warning for the run naming every setting,
// the CSV's ref_noise_warning column set, and the plot (errors of 0, a
// one-row sweep) drawn.
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"

static char dir[4096];

static int sh(const char *fmt, const char *arg) {
    char args[4096];
    snprintf(args, sizeof args, fmt, arg);
    return st_test_sh("cd '%s' && '%s' %s >/dev/null", dir, ST_TEST_STRAHL, args);
}

// Splits CSV text into lines (in place); returns the count.
static int lines_of(char *text, char **out, int max) {
    int n = 0;
    for (char *p = text; p && *p && n < max;) {
        char *e = strchr(p, '\n');
        if (e) *e = 0;
        out[n++] = p;
        p = e ? e + 1 : NULL;
    }
    return n;
}

// Field k (0-based) of a CSV line into buf.
static const char *field(const char *line, int k, char *buf, size_t n) {
    for (int i = 0; i < k && line; i++) {
        line = strchr(line, ',');
        if (line) line++;
    }
    if (!line) return "";
    snprintf(buf, n, "%.*s", (int)strcspn(line, ","), line);
    return buf;
}

// ref.exr with standard-error channels of 10 (far above any error) and spp 4.
static void write_noisy_reference(void) {
    char path[4200];
    snprintf(path, sizeof path, "%s/ref.exr", dir);
    st_image ref = {0}, noisy = {0};
    st_err err = {0};
    CHECK(st_image_read_exr(path, &ref, &err), "%s", err.msg);
    if (!ref.data || !st_image_alloc(&noisy, ref.width, ref.height, 6, &err)) return;
    for (int j = 0; j < ref.height; j++)
        for (int i = 0; i < ref.width; i++)
            for (int c = 0; c < 6; c++)
                st_image_px(&noisy, i, j)[c] = c < 3 ? st_image_px(&ref, i, j)[c] : 10.0f;
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_exr_meta meta = {.spp = 4, .filter = "point"};
    snprintf(path, sizeof path, "%s/noisy.exr", dir);
    CHECK(st_image_write_exr_meta(path, &noisy, names, &meta, &err), "%s", err.msg);
    st_image_free(&ref);
    st_image_free(&noisy);
}

static void test_noisy_reference(const char *scene) {
    write_noisy_reference();
    char cmd[8192], out[16384], path[4200], f[64];
    const char *args = "--reference noisy.exr --size 32x32 --frames 1 --warmup 0";
    snprintf(cmd, sizeof cmd,
             "cd '%s' && '%s' bench '%s' %s --sweep toth.samples=8,16 --csv n.csv --plot n.svg",
             dir, ST_TEST_STRAHL, scene, args);
    CHECK(st_test_capture(out, sizeof out, cmd) == 0, "bench with a noisy reference");
    int warnings = 0;
    for (const char *p = out; (p = strstr(p, "warning:")); p++)
        warnings++;
    CHECK(warnings == 1 && strstr(out, "2 of 2 settings") && strstr(out, "toth.samples=8;") &&
              strstr(out, "toth.samples=16"),
          "one warning naming both settings: '%s'", out);
    snprintf(path, sizeof path, "%s/n.csv", dir);
    st_err err = {0};
    char *csv = st_read_file(path, NULL, &err), *lines[8];
    int n = csv ? lines_of(csv, lines, 8) : 0;
    CHECK(n == 3, "n.csv: %d lines", n);
    for (int k = 1; k < n; k++)
        CHECK(!strcmp(field(lines[k], 20, f, sizeof f), "1"), "row %d ref_noise_warning '%s'", k,
              f);
    free(csv);
    snprintf(path, sizeof path, "%s/n.svg", dir);
    CHECK(st_test_exists(path), "n.svg (errors of 0) not drawn");
    // Issue 36 item 8: one setting with --plot.
    snprintf(cmd, sizeof cmd,
             "cd '%s' && '%s' bench '%s' %s --sweep toth.samples=8 --csv one.csv --plot one.png",
             dir, ST_TEST_STRAHL, scene, args);
    CHECK(st_test_capture(out, sizeof out, cmd) == 0, "one-setting bench --plot: %s", out);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    const char *scene = ST_TEST_SOURCE_DIR "/scenes/godrays_window.json";
    // The point filter (recorded in ref.exr, so bench uses it too): one frame
    // per setting; the box filter would accumulate each setting to a converged
    // still, which the sharding checks below do not need.
    CHECK(sh("render '%s' -o ref.exr --size 32x32 --filter point", scene) == 0, "reference render");
    const char *sweep = "--reference ref.exr --size 32x32 --frames 1 --warmup 0 "
                        "--sweep toth.samples=8,16,32 --sweep toth.interleave=1,2";
    char fmt[1024];
    snprintf(fmt, sizeof fmt, "bench '%%s' %s --csv all.csv", sweep);
    CHECK(sh(fmt, scene) == 0, "unsharded bench");
    for (int i = 1; i <= 4; i++) {
        char f2[1200];
        snprintf(f2, sizeof f2, "bench '%%s' %s --csv shard%d.csv --shard %d/4", sweep, i, i);
        CHECK(sh(f2, scene) == 0, "shard %d/4", i);
    }
    CHECK(st_test_sh("cd '%s' && cat shard1.csv shard2.csv shard3.csv shard4.csv > cat.csv", dir) ==
              0,
          "cat");

    char path[4200];
    st_err err = {0};
    snprintf(path, sizeof path, "%s/all.csv", dir);
    char *all = st_read_file(path, NULL, &err);
    snprintf(path, sizeof path, "%s/cat.csv", dir);
    char *cat = st_read_file(path, NULL, &err);
    CHECK(all && cat, "%s", err.msg);
    if (all && cat) {
        char *la[64], *lc[64];
        int na = lines_of(all, la, 64), nc = lines_of(cat, lc, 64);
        CHECK(na == 7 && nc == 7, "lines: unsharded %d, shards %d (header + 6 settings)", na, nc);
        CHECK(!strcmp(la[0], lc[0]), "headers differ: '%s' / '%s'", la[0], lc[0]);
        CHECK(!strncmp(lc[0], "scene,setting,", 14), "first line of the shards is not the header");
        // Every setting of the unsharded run exactly once among the shards.
        for (int i = 1; i < na; i++) {
            char want[256], got[256];
            field(la[i], 1, want, sizeof want);
            int count = 0;
            for (int k = 1; k < nc; k++)
                count += !strcmp(field(lc[k], 1, got, sizeof got), want);
            CHECK(count == 1, "setting '%s' appears %d times in the shards", want, count);
        }
        for (int k = 1; k < nc; k++) {
            char a[64], b[64], noise[64];
            CHECK(strncmp(lc[k], "scene,", 6) != 0, "header repeated on line %d", k + 1);
            // No stderr channels in a rendered reference: debiased = raw.
            CHECK(!strcmp(field(lc[k], 8, a, sizeof a), field(lc[k], 18, b, sizeof b)),
                  "error %s vs raw %s", a, b);
            CHECK(atof(field(lc[k], 19, noise, sizeof noise)) == 0, "ref_noise_rms %s", noise);
        }
    }
    free(all);
    free(cat);
    // Progress: not a terminal -> one summary line on stderr and no bar; on a
    // terminal (script(1) gives it one) a bar with an ETA.
    snprintf(fmt, sizeof fmt, "bench '%%s' %s --csv p.csv 2>progress.txt", sweep);
    CHECK(sh(fmt, scene) == 0, "bench for progress");
    snprintf(path, sizeof path, "%s/progress.txt", dir);
    char *prog = st_read_file(path, NULL, &err);
    int summary = 0;
    for (const char *p = prog; p && (p = strstr(p, "strahl bench: ")); p++)
        summary++;
    CHECK(prog && summary == 1 && strstr(prog, "6 settings in") && !strchr(prog, '\r'),
          "non-terminal progress: '%s'", prog ? prog : "");
    free(prog);
    char cmd[8192], out[16384];
    snprintf(cmd, sizeof cmd, "cd '%s' && script -qec \"'%s' bench '%s' %s --csv q.csv\" /dev/null",
             dir, ST_TEST_STRAHL, scene, sweep);
    CHECK(st_test_capture(out, sizeof out, cmd) == 0, "bench under script(1)");
    CHECK(strstr(out, "bench [") && strstr(out, "s left") && strstr(out, "6/6 settings"),
          "terminal progress bar");

    const char *bad[] = {"0/4", "5/4", "2", "a/b", "1/0"};
    for (int i = 0; i < 5; i++) {
        char f2[1200];
        snprintf(f2, sizeof f2, "bench '%%s' %s --csv bad.csv --shard %s", sweep, bad[i]);
        CHECK(sh(f2, scene) == 2, "--shard %s accepted", bad[i]);
    }
    snprintf(path, sizeof path, "%s/bad.csv", dir);
    CHECK(!st_test_exists(path), "bad.csv written");
    test_noisy_reference(scene);
    return st_test_summary("cli_bench_shard");
}
