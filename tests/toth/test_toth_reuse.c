// toth reuse=on (default): the jittered frames of a box still read the first
// frame's visible fraction at their sub-pixel position instead of marching.
// On godrays_window at 64x48 (shafts a few pixels wide, 16 frames) the still
// must stay close to the one that marches every frame (reuse=0): rmse 1.1e-3
// measured, where reading the first frame's own pixel (no interpolation
// inside the pixel) gives 3.6e-3. (The image means differ by 1% after 16
// frames, both within 0.6% of the 1024-spp CPU reference's: the frames' own
// noise, not a bias; docs/benchmarks.md.) A point still does not change at all (no keep pass runs).
// The pass counts (march once per still) are in test_toth_passes.
#include "st_test_render.h"

static char scene[1024], on[1024], off[1024], pon[1024], poff[1024];

static int render(const char *out, const char *filter, const char *extra) {
    unlink(out);
    return st_test_sh("%s render %s -o %s --size 64x48 --filter %s %s", ST_TEST_STRAHL, scene, out,
                      filter, extra);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/scenes/godrays_window.json", ST_TEST_SOURCE_DIR);
    snprintf(on, sizeof on, "%s/toth_reuse_on.exr", ST_TEST_SCRATCH);
    snprintf(off, sizeof off, "%s/toth_reuse_off.exr", ST_TEST_SCRATCH);
    snprintf(pon, sizeof pon, "%s/toth_reuse_point_on.exr", ST_TEST_SCRATCH);
    snprintf(poff, sizeof poff, "%s/toth_reuse_point_off.exr", ST_TEST_SCRATCH);
    CHECK(render(on, "box", "--frames 16") == 0, "box still, reuse on");
    CHECK(render(off, "box", "--frames 16 --set toth.reuse=0") == 0, "box still, reuse off");
    CHECK(render(pon, "point", "") == 0, "point still, reuse on");
    CHECK(render(poff, "point", "--set toth.reuse=0") == 0, "point still, reuse off");
    st_image a = {0}, b = {0}, pa = {0}, pb = {0};
    if (!st_test_read(on, &a) || !st_test_read(off, &b) || !st_test_read(pon, &pa) ||
        !st_test_read(poff, &pb))
        return st_test_summary("toth_reuse");
    CHECK(st_test_all_finite(&a), "reuse: finite");
    st_metrics m, mp;
    st_err err = {0};
    CHECK(st_image_compare(&a, &b, &m, &err), "compare box stills: %s", err.msg);
    CHECK(st_image_compare(&pa, &pb, &mp, &err), "compare point stills: %s", err.msg);
    printf("box, reuse on vs off: rmse %.4g max_abs %.4g mean %.6g vs %.6g\n", m.rmse[3],
           m.max_abs[3], m.mean_a[3], m.mean_b[3]);
    CHECK(m.rmse[3] <= 1.6e-3, "box still with reuse: rmse %.4g against reuse=0 (bound 1.6e-3)",
          m.rmse[3]);
    CHECK(mp.max_abs[3] == 0, "point still: reuse changes nothing (max_abs %.4g)", mp.max_abs[3]);
    st_image_free(&a);
    st_image_free(&b);
    st_image_free(&pa);
    st_image_free(&pb);
    return st_test_summary("toth_reuse");
}
