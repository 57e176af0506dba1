// `strahl plot` (and bench --plot): on a small bench CSV, the SVG names the
// curves by what varies between them (parameter and value), labels each point
// with its swept value, marks the Pareto front, the baseline and the plugin
// defaults, and labels both log axes with units. Rows whose reference is too
// noisy are hollow, errors of 0 sit at the axis floor with a marker, one row
// plots, and a failing gnuplot's error (not its first warning) is shown. Bad
// input: exit 2, no file.
#include "st_test.h"
#include "st_base.h"

static char dir[4096];

#define HEADER                                                                                     \
    "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_ms_median,"      \
    "error_rmse,rmse,relmse,psnr,max_abs,scale,scaled_rmse,peak_rss_kb,gpu_bytes,pass_gpu_ms,"     \
    "error_raw,ref_noise_rms,ref_noise_warning\n"

// Plots text as a bench CSV into NAME.svg; returns the SVG (NULL on failure).
static char *plot_text(const char *name, const char *text) {
    char path[4200];
    snprintf(path, sizeof path, "%s/%s.csv", dir, name);
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
    int rc = st_test_sh("cd '%s' && '%s' plot %s.csv -o %s.svg", dir, ST_TEST_STRAHL, name, name);
    CHECK(rc == 0, "plot %s: exit %d", name, rc);
    snprintf(path, sizeof path, "%s/%s.svg", dir, name);
    st_err err = {0};
    return rc == 0 ? st_read_file(path, NULL, &err) : NULL;
}

// Points drawn with gnuplot point type pt (the SVG's gpPt{pt-1}).
static int points_of_type(const char *svg, int pt) {
    char key[64];
    snprintf(key, sizeof key, "href='#gpPt%d' transform", pt - 1);
    int n = 0;
    for (const char *p = svg; svg && (p = strstr(p, key)); p++)
        n++;
    return n;
}

static void test_markers(void) {
    // Row 2's reference is too noisy; row 3 has error 0 (and is noisy too).
    char *svg = plot_text("noisy", HEADER "w.json,toth.samples=8,toth,8,10,2,1,1,0.01,0,0,0,0,0,0,"
                                          "0,0,,0,0,0\n"
                                          "w.json,toth.samples=32,toth,32,10,6,1,1,0.004,0,0,0,0,0,"
                                          "0,0,0,,0,0,1\n"
                                          "w.json,toth.samples=128,toth,128,10,20,1,1,0,0,0,0,0,0,"
                                          "0,0,0,,0,0,1\n");
    // pt 7 filled, 6 hollow (+ its legend key), 10 hollow triangle, 11 the key of error 0.
    CHECK(points_of_type(svg, 7) == 1 && points_of_type(svg, 6) == 2 &&
              points_of_type(svg, 10) == 1 && points_of_type(svg, 11) == 1,
          "markers: filled %d hollow %d zero-hollow %d zero-key %d", points_of_type(svg, 7),
          points_of_type(svg, 6), points_of_type(svg, 10), points_of_type(svg, 11));
    CHECK(svg && strstr(svg, "reference is too noisy") &&
              strstr(svg, "error 0, drawn at the axis "
                          "floor 0.001"),
          "legend of the markers");
    CHECK(svg && strstr(svg, ">toth.samples<") && strstr(svg, ">32<"), "one curve's name, labels");
    free(svg);
    // One row; rows all with error 0 (the failures of issue 36 item 8).
    svg = plot_text("one", HEADER "w.json,toth.samples=8,toth,8,10,2,1,1,0.01,0,0,0,0,0,0,0,0,,0,0,"
                                  "0\n");
    CHECK(svg && points_of_type(svg, 7) == 1, "one row: one point");
    free(svg);
    svg =
        plot_text("zero", HEADER "w.json,toth.samples=8,toth,8,10,2,1,1,0,0,0,0,0,0,0,0,0,,0,0,0\n"
                                 "w.json,toth.samples=16,toth,16,10,3,1,1,0,0,0,0,0,0,0,0,0,,0,"
                                 "0,0\n");
    CHECK(svg && points_of_type(svg, 11) == 3, "all errors 0: two triangles and the key");
    free(svg);
    // A gnuplot that warns, then fails: its error is the message.
    char bin[4200];
    snprintf(bin, sizeof bin, "%s/fakebin", dir);
    CHECK(st_test_sh("mkdir -p '%s' && printf '#!/bin/sh\\ncat >/dev/null\\necho \"Warning: empty "
                     "x range\" >&2\\necho \"line 9: fake failure\" >&2\\nexit 1\\n' > "
                     "'%s/gnuplot' && chmod +x '%s/gnuplot'",
                     bin, bin, bin) == 0,
          "fake gnuplot");
    char out[4096], cmd[8192];
    snprintf(cmd, sizeof cmd,
             "cd '%.2000s' && PATH='%.2000s':\"$PATH\" '%s' plot one.csv -o fail.svg", dir, bin,
             ST_TEST_STRAHL);
    int rc = st_test_capture(out, sizeof out, cmd);
    CHECK(rc == 1 && strstr(out, "line 9: fake failure") && !strstr(out, "empty x range"),
          "gnuplot's error: exit %d, %s", rc, out);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    char path[4200];
    snprintf(path, sizeof path, "%s/t.csv", dir);
    FILE *f = fopen(path, "w");
    fprintf(f, "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_ms_"
               "median,error_rmse,"
               "rmse\n");
    // toth defaults: samples 0 (32 equi-angular steps: x = 32), interleave 1,
    // resolution third.
    const int samples[3] = {8, 0, 256}, steps[3] = {8, 32, 256};
    const char *res[2] = {"full", "third"};
    for (int r = 0; r < 2; r++)
        for (int il = 1; il <= 2; il++)
            for (int s = 0; s < 3; s++)
                fprintf(f,
                        "scenes/w.json,toth.samples=%d toth.interleave=%d "
                        "toth.resolution=%s,c,%d,1,%g,1,1,%g,0\n",
                        samples[s], il, res[r], steps[s], steps[s] * (r ? 0.3 : 1.0) / il,
                        0.1 / steps[s] + 0.001 * il);
    fclose(f);
    CHECK(
        st_test_sh(
            "cd '%s' && '%s' plot t.csv -o t.svg --baseline toth.samples=256,toth.resolution=full,"
            "toth.interleave=1",
            dir, ST_TEST_STRAHL) == 0,
        "plot");
    snprintf(path, sizeof path, "%s/t.svg", dir);
    st_err err = {0};
    char *svg = st_read_file(path, NULL, &err);
    CHECK(svg != NULL, "%s", err.msg);
    const char *want[] = {"interleave 1, resolution full",
                          "interleave 2, resolution third",
                          "Pareto front",
                          "baseline (toth.samples=256",
                          "plugin defaults",
                          "median frame time [ms]",
                          "W sr^-1 m^-2",
                          "log scale",
                          "along each curve: samples",
                          ">256<"}; // a point labelled with its swept value
    for (size_t i = 0; svg && i < sizeof want / sizeof want[0]; i++)
        CHECK(strstr(svg, want[i]) != NULL, "the plot has no '%s'", want[i]);
    // The module is not repeated in the curve names.
    CHECK(svg && !strstr(svg, "toth_toth") && !strstr(svg, "interleave=1_"),
          "curve names repeat the module");
    free(svg);
    CHECK(st_test_sh("cd '%s' && '%s' plot missing.csv -o m.svg", dir, ST_TEST_STRAHL) == 2,
          "missing CSV");
    CHECK(st_test_sh("cd '%s' && '%s' plot t.csv -o m.jpg", dir, ST_TEST_STRAHL) == 2,
          "bad extension");
    snprintf(path, sizeof path, "%s/m.svg", dir);
    CHECK(!st_test_exists(path), "m.svg written");
    test_markers();
    return st_test_summary("cli_plot");
}
