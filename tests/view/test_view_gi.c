// strahl view GI display cycle under Xvfb: the I key goes off > direct >
// indirect > combined > atlas > off, switching atlas_gi on and setting its
// display switch (found from the descriptor). The modes must differ as the
// physics says (combined = direct + indirect, indirect light where direct
// light is shadowed), the viewer's combined image must equal the headless
// render, and neither a display switch nor a camera-only move may run an
// atlas pass.
#include "view_test.h"
#include "st_test_support.h"

enum { N = 96 };
static const char *GI = "\"atlas_size\": 128, \"samples\": 64, \"progressive\": false";

static void write_scene(const char *path, const char *modules) {
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [0, 1, 3.2], \"target\": [0, 0.9, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 45},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0.4, 1.6, 0.3], \"intensity\": "
             "[3, 3, 3]}],\n"
             " \"geometry\": [\n" ST_TEST_CORNELL_WALLS
             "  {\"box\": {\"min\": [-0.6, 0, -0.6], \"max\": [-0.1, 1.1, -0.1]}, \"albedo\": "
             "[0.75, 0.75, 0.75]}],\n"
             " \"modules\": [%s]}\n",
             N, N, modules);
    st_test_write(path, json);
}

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], script[512], path[1024], tmp[1024], mods[512];
    CHECK(st_view_installed("atlas_gi"), "atlas_gi must be installed for this test");
    if (!st_view_installed("atlas_gi")) return st_test_summary("test_view_gi");
    snprintf(scene, sizeof scene, "%s/gi.json", D);
    snprintf(script, sizeof script, "%s/gi.script", D);
    write_scene(scene, "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}}");
    snprintf(tmp, sizeof tmp, "%s/gi_ref.json", D);
    snprintf(mods, sizeof mods,
             "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}}, {\"name\": "
             "\"atlas_gi\", \"params\": {%s}}",
             GI);
    write_scene(tmp, mods);
    snprintf(path, sizeof path, "%s/ref_combined.exr", D);
    CHECK(st_test_render(tmp, path, NULL) == 0, "render atlas_gi combined");

    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_view_gi");
    fprintf(f,
            "frames 1\nscreenshot %s/none\n"
            "key I\nexpect-module atlas_gi on\nexpect-message GI display: direct\n"
            "set atlas_gi.atlas_size 128\nset atlas_gi.samples 64\nset atlas_gi.progressive false\n"
            "frames 1\nstats %s/s_direct.json\nscreenshot %s/direct\n"
            "frames 1\nstats %s/s_static.json\n"
            "key I\nexpect-message GI display: indirect\nframes 1\nstats "
            "%s/s_indirect.json\nscreenshot %s/indirect\n"
            "key I\nexpect-message GI display: combined\nframes 1\nscreenshot %s/combined\n"
            "orbit 20 5\nframes 1\nstats %s/s_cam.json\nscreenshot %s/cam\nkey R\n"
            "key I\nexpect-message GI display: atlas\nframes 1\nscreenshot %s/atlas\nstats "
            "%s/s_atlas.json\n"
            "key I\nexpect-message GI display: off\nexpect-module atlas_gi off\nframes "
            "1\nscreenshot %s/off\n"
            "# back on: the parameters set before come back\n"
            "key I\nexpect-param atlas_gi.samples 64\nexpect-param atlas_gi.progressive 0\n",
            D, D, D, D, D, D, D, D, D, D, D, D);
    fclose(f);
    static char log[65536];
    int rc = st_view_run(scene, script, NULL, log, sizeof log);
    CHECK(rc == 0, "strahl view --script exit code %d", rc);

    st_image none = {0}, direct = {0}, indirect = {0}, combined = {0}, atlas = {0}, off = {0},
             ref = {0};
    st_view_read(D, "none", &none), st_view_read(D, "direct", &direct),
        st_view_read(D, "indirect", &indirect);
    st_view_read(D, "combined", &combined), st_view_read(D, "atlas", &atlas),
        st_view_read(D, "off", &off);
    st_view_read(D, "ref_combined", &ref);

    CHECK(st_view_max_diff(&combined, &ref) <= 1e-4, "viewer vs render, combined: %g",
          st_view_max_diff(&combined, &ref));
    CHECK(st_view_max_diff(&direct, &none) <= 1e-4, "direct display = the image without GI: %g",
          st_view_max_diff(&direct, &none));
    CHECK(st_view_max_diff(&off, &none) <= 1e-6, "GI off again = without GI: %g",
          st_view_max_diff(&off, &none));
    // combined = direct + indirect, per pixel.
    double worst = combined.data && direct.data && indirect.data ? 0 : INFINITY;
    int shadowed_lit = 0;
    for (int j = 0; worst < INFINITY && j < N; j++)
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                double a = st_image_px(&combined, i, j)[c],
                       b = st_image_px(&direct, i, j)[c] + st_image_px(&indirect, i, j)[c];
                worst = fmax(worst, fabs(a - b) / (1e-3 + fabs(b)));
                if (c == 0)
                    shadowed_lit += st_image_px(&direct, i, j)[0] == 0 &&
                                    st_image_px(&indirect, i, j)[0] > 1e-3;
            }
    CHECK(worst <= 1e-4, "combined vs direct + indirect: worst relative %g", worst);
    // Indirect light reaches where the light does not (under and behind the box).
    CHECK(shadowed_lit > 20, "pixels without direct light lit indirectly: %d", shadowed_lit);
    double m_dir = st_view_mean(&direct, 0, 0, N, N), m_ind = st_view_mean(&indirect, 0, 0, N, N);
    double m_comb = st_view_mean(&combined, 0, 0, N, N), m_atlas = st_view_mean(&atlas, 0, 0, N, N);
    CHECK(m_ind > 0.05 * m_dir && m_ind < m_dir, "indirect mean %g vs direct mean %g", m_ind,
          m_dir);
    // Every mode shows something different.
    const st_image *modes[4] = {&direct, &indirect, &combined, &atlas};
    const char *names[4] = {"direct", "indirect", "combined", "atlas"};
    for (int a = 0; a < 4; a++)
        for (int b = a + 1; b < 4; b++) {
            int n = st_view_count_diff(modes[a], modes[b], 1e-3);
            CHECK(n > N * N / 20, "%s vs %s: %d pixels differ", names[a], names[b], n);
        }
    // The atlas view shows the same light at atlas resolution.
    CHECK(fabs(m_atlas - m_comb) < 0.2 * m_comb, "atlas view mean %g vs combined %g", m_atlas,
          m_comb);
    printf("means: direct %g indirect %g combined %g atlas %g; combined-(direct+indirect) worst "
           "rel %g; "
           "indirect-only pixels %d\n",
           m_dir, m_ind, m_comb, m_atlas, worst, shadowed_lit);

    // Atlas passes: on the first frame only; not for a display switch or a camera move.
    const char *files[5] = {"s_direct", "s_static", "s_indirect", "s_cam", "s_atlas"};
    const char *want[5] = {"ran", "skipped", "skipped", "skipped", "skipped"};
    for (int k = 0; k < 5; k++) {
        snprintf(path, sizeof path, "%s/%s.json", D, files[k]);
        cJSON *s = st_view_json(path);
        const char *gb = st_view_pass_state(s, "atlas_gi", "gbuffer"),
                   *ga = st_view_pass_state(s, "atlas_gi", "gather");
        CHECK(!strcmp(gb, want[k]) && !strcmp(ga, want[k]),
              "%s: atlas gbuffer %s, gather %s, expected %s", files[k], gb, ga, want[k]);
        CHECK(!strcmp(st_view_pass_state(s, "world", "regular"), "ran"), "%s: regular pass ran",
              files[k]);
        if (k == 0) {
            double g = st_view_pass_num(s, "atlas_gi", "gather", "gpu_ms");
            CHECK(g > 0, "atlas gather GPU time %g ms", g);
        }
        cJSON_Delete(s);
    }
    st_image *imgs[] = {&none, &direct, &indirect, &combined, &atlas, &off, &ref};
    for (size_t i = 0; i < sizeof imgs / sizeof imgs[0]; i++)
        st_image_free(imgs[i]);
    return st_test_summary("test_view_gi");
}
