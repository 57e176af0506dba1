// `strahl reference` as a command: output channels, determinism across runs
// and thread counts, exit codes, and no output file on failure.
#include "st_test.h"
#include "st_image.h"
#include <openexr.h>

static const char *plane_json =
    "{\"image\": {\"width\": 32, \"height\": 24},\n"
    " \"camera\": {\"position\": [0, 2.5, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "50,"
    " \"near\": 0.05, \"far\": 100},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0.3, 1, -0.2], \"intensity\": [2, 1, "
    "0.5]}],\n"
    " \"geometry\": [\n"
    "  {\"quad\": {\"corner\": [-5, 0, -5], \"u\": [0, 0, 10], \"v\": [10, 0, 0]}, \"albedo\": "
    "[0.6, 0.6, 0.6]},\n"
    "  {\"box\": {\"min\": [-0.5, 0, -0.5], \"max\": [0, 0.4, 0]}, \"albedo\": [0.7, 0.2, 0.2]}],\n"
    " \"medium\": {\"sigma_s\": [0.05, 0.05, 0.05], \"sigma_a\": [0.01, 0.01, 0.01], \"phase\": "
    "{\"hg\": 0.4}}\n"
    "}\n";

static char scene[2048], out[2048];

static void write_file(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    if (!f) exit(1);
    fputs(text, f);
    fclose(f);
}

static bool read_exr(const char *path, st_image *img) {
    st_err err = {0};
    if (st_image_read_exr(path, img, &err)) return true;
    fprintf(stderr, "%s\n", err.msg);
    return false;
}

static bool same(const st_image *a, const st_image *b) {
    return a->width == b->width && a->height == b->height && a->channels == b->channels &&
           !memcmp(a->data, b->data, sizeof(float) * a->width * a->height * a->channels);
}

static void channels(void) {
    exr_context_t ctx;
    CHECK(exr_start_read(&ctx, out, NULL) == EXR_ERR_SUCCESS, "open %s", out);
    const exr_attr_chlist_t *chl = NULL;
    if (exr_get_channels(ctx, 0, &chl) == EXR_ERR_SUCCESS && chl) {
        const char *want[] = {"B",        "G",        "R",
                              "stderr.B", "stderr.G", "stderr.R"}; // EXR sorts by name
        CHECK(chl->num_channels == 6, "%d channels", chl->num_channels);
        for (int i = 0; i < 6 && i < chl->num_channels; i++)
            CHECK(!strcmp(chl->entries[i].name.str, want[i]), "channel %d is %s", i,
                  chl->entries[i].name.str);
    }
    exr_finish(&ctx);
}

static void good_runs(void) {
    char cmd[8192];
    snprintf(cmd, sizeof cmd, "%s reference %s -o %s --spp 8 --seed 5", ST_TEST_STRAHL, scene, out);
    CHECK(st_test_sh("%s", cmd) == 0, "a good run exits 0");
    st_image a = {0}, b = {0}, c = {0};
    if (!read_exr(out, &a)) return;
    CHECK(a.width == 32 && a.height == 24, "size %dx%d", a.width, a.height);
    CHECK(st_image_count_nonfinite(&a) == 0, "NaN/Inf in the output");
    channels();
    // Same seed, one thread: bit-identical (per-pixel random streams).
    CHECK(st_test_sh("%s --threads 1", cmd) == 0, "--threads 1 exits 0");
    if (read_exr(out, &b)) CHECK(same(&a, &b), "the result depends on the thread count");
    st_image_free(&b);
    CHECK(st_test_sh("%s --threads 2", cmd) == 0, "rerun exits 0");
    if (read_exr(out, &b)) CHECK(same(&a, &b), "two runs with one seed differ");
    st_image_free(&b);
    CHECK(st_test_sh("%s reference %s -o %s --spp 8 --seed 6", ST_TEST_STRAHL, scene, out) == 0,
          "seed 6");
    if (read_exr(out, &c)) CHECK(!same(&a, &c), "another seed gives the same noise");
    st_image_free(&c);
    // --size overrides the scene's image; the AOVs and estimator options parse.
    CHECK(st_test_sh("%s reference %s -o %s --spp 2 --size 8x6 --aov inscatter --bounces 2 "
                     "--bounce-visibility off "
                     "--estimator thesis --steps 32",
                     ST_TEST_STRAHL, scene, out) == 0,
          "options exit 0");
    if (read_exr(out, &c)) CHECK(c.width == 8 && c.height == 6, "--size: %dx%d", c.width, c.height);
    st_image_free(&c);
    st_image_free(&a);
}

static void bad_runs(void) {
    char bad_scene[4200], fresh[4200];
    snprintf(bad_scene, sizeof bad_scene, "%s/broken.json", ST_TEST_SCRATCH);
    write_file(bad_scene, "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": ");
    snprintf(fresh, sizeof fresh, "%s/never.exr", ST_TEST_SCRATCH);
    const struct {
        const char *args;
        int code;
    } cases[] = {
        {"%s reference %s -o %s --bogus 1", 2},
        {"%s reference %s -o %s --spp 0", 2},
        {"%s reference %s -o %s --spp abc", 2},
        {"%s reference %s -o %s --aov everything", 2},
        {"%s reference %s -o %s --bounce-visibility maybe", 2},
        {"%s reference %s -o %s --estimator best", 2},
        {"%s reference %s -o %s --seed -3", 2},
        {"%s reference %s -o %s --size 0x9", 2},
        {"%s reference %s -o %s --set nomodule.x=1", 2},
        {"%s reference %s -o %s.png", 2},
        {"%s reference %s -o %s --spp", 2},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        unlink(fresh);
        int rc = st_test_sh(cases[k].args, ST_TEST_STRAHL, scene, fresh);
        CHECK(rc == cases[k].code, "'%s': exit %d, expected %d", cases[k].args, rc, cases[k].code);
        CHECK(!st_test_exists(fresh), "'%s' left an output file", cases[k].args);
    }
    unlink(fresh);
    CHECK(st_test_sh("%s reference %s -o %s", ST_TEST_STRAHL, bad_scene, fresh) == 2,
          "malformed scene exits 2");
    CHECK(st_test_sh("%s reference %s/missing.json -o %s", ST_TEST_STRAHL, ST_TEST_SCRATCH,
                     fresh) == 2,
          "missing scene exits 2");
    CHECK(st_test_sh("%s reference %s", ST_TEST_STRAHL, scene) == 2, "missing -o exits 2");
    CHECK(!st_test_exists(fresh), "a failed run left an output file");
    // An unwritable destination is bad input, found before rendering; nothing is left.
    CHECK(st_test_sh("%s reference %s -o %s/no-such-dir/x.exr --spp 1", ST_TEST_STRAHL, scene,
                     ST_TEST_SCRATCH) == 2,
          "unwritable output exits 2");
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/plane.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/plane.exr", ST_TEST_SCRATCH);
    write_file(scene, plane_json);
    good_runs();
    bad_runs();
    return st_test_summary("reference_cli");
}
