// strahl bench's argument checks that need no rendering: --append onto a CSV
// whose first line is not this run's header is refused (exit 2, naming the
// file and the line) and leaves the file as it was; a swept value given twice
// is refused. Each is decided before the reference is read.
#include "st_test.h"
#include "st_base.h"

static char dir[4096];

static int bench(char *out, size_t n, const char *args) {
    char cmd[8192];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && '%s' bench '%s/scenes/cornell.json' --reference ref.exr %s", dir,
             ST_TEST_STRAHL, ST_TEST_SOURCE_DIR, args);
    return st_test_capture(out, n, cmd);
}

static void write_text(const char *name, const char *text) {
    st_test_write_text(dir, name, text);
}

static char *read_text(const char *name) {
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    st_err err = {0};
    return st_read_file(path, NULL, &err);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    char out[8192];
    // No ref.exr here: a run that passes the header check fails on it instead.
    const char *foreign[] = {"a,b,c\n1,2,3\n", "scene,setting\nx,y\n",
                             "s.json,toth.samples=8,toth,8,10,1,1,1,0.1\n",
                             "x\033[2J,y\n"}; // an escape must not reach the terminal
    for (size_t i = 0; i < sizeof foreign / sizeof foreign[0]; i++) {
        write_text("o.csv", foreign[i]);
        int rc = bench(out, sizeof out, "--sweep toth.samples=8 --csv o.csv --append");
        char line1[64];
        snprintf(line1, sizeof line1, "%.*s", (int)strcspn(foreign[i], "\n\033"), foreign[i]);
        CHECK(rc == 2 && strstr(out, "o.csv") && strstr(out, line1) && strstr(out, "header") &&
                  !strstr(out, "ref.exr"),
              "--append onto '%s': exit %d, %s", line1, rc, out);
        CHECK(!strchr(out, '\033'), "a raw escape printed");
        char *now = read_text("o.csv");
        CHECK(now && !strcmp(now, foreign[i]), "o.csv changed: %s", now);
        free(now);
    }
    // This run's header (metric rmse) passes: the next error is the reference.
    write_text("ok.csv",
               "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_ms_"
               "median,error_rmse,rmse,relmse,psnr,max_abs,scale,scaled_rmse,peak_rss_kb,gpu_"
               "bytes,pass_gpu_ms,error_raw,ref_noise_rms,ref_noise_warning\n");
    int rc = bench(out, sizeof out, "--sweep toth.samples=8 --csv ok.csv --append");
    CHECK(rc == 2 && strstr(out, "ref.exr") && !strstr(out, "header"),
          "--append onto this run's header: exit %d, %s", rc, out);
    // The same header under another --metric is foreign too.
    rc = bench(out, sizeof out, "--sweep toth.samples=8 --csv ok.csv --append --metric relmse");
    CHECK(rc == 2 && strstr(out, "header") && strstr(out, "--metric"),
          "--append with another metric: exit %d, %s", rc, out);
    // A swept value twice, as text or as a number.
    const char *dups[] = {"toth.samples=8,8", "toth.samples=8,16,8.0", "toth.resolution=half,half"};
    for (size_t i = 0; i < sizeof dups / sizeof dups[0]; i++) {
        char args[256];
        snprintf(args, sizeof args, "--sweep %s --csv d.csv", dups[i]);
        rc = bench(out, sizeof out, args);
        CHECK(rc == 2 && strstr(out, "twice") && strstr(out, dups[i]), "--sweep %s: exit %d, %s",
              dups[i], rc, out);
    }
    rc = bench(out, sizeof out, "--sweep toth.samples=8,16 --csv d.csv");
    CHECK(rc == 2 && strstr(out, "ref.exr"), "distinct values: exit %d, %s", rc, out);
    char path[4200];
    snprintf(path, sizeof path, "%s/d.csv", dir);
    CHECK(!st_test_exists(path), "d.csv written");
    return st_test_summary("cli_bench_args");
}
