// `strahl plot` (and bench --plot): on a small bench CSV, the SVG names the
// curves by what varies between them, marks the Pareto front, the baseline
// and the plugin defaults, and labels both log axes with units. Bad input:
// exit 2, no file.
#include "st_test.h"
#include "st_base.h"

static char dir[4096];

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    char path[4200];
    snprintf(path, sizeof path, "%s/t.csv", dir);
    FILE *f = fopen(path, "w");
    fprintf(f, "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_ms_"
               "median,error_rmse,"
               "rmse\n");
    // toth defaults: samples 64, interleave 1, resolution half.
    const int samples[3] = {8, 64, 256};
    const char *res[2] = {"full", "half"};
    for (int r = 0; r < 2; r++)
        for (int il = 1; il <= 2; il++)
            for (int s = 0; s < 3; s++)
                fprintf(f,
                        "scenes/w.json,toth.samples=%d toth.interleave=%d "
                        "toth.resolution=%s,c,%d,1,%g,1,1,%g,0\n",
                        samples[s], il, res[r], samples[s], samples[s] * (r ? 0.3 : 1.0) / il,
                        0.1 / samples[s] + 0.001 * il);
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
    const char *want[] = {"interleave 1, full",
                          "interleave 2, half",
                          "Pareto front",
                          "baseline (toth.samples=256",
                          "plugin defaults",
                          "median frame time [ms]",
                          "W sr^-1 m^-2",
                          "log scale",
                          "along each curve: samples"};
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
    return st_test_summary("cli_plot");
}
