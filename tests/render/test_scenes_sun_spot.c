// The sun and spot scenes (scenes/colonnade_sun*.json: a low sun behind a
// colonnade, with toth, mitchell and sousa; scenes/spot_fog.json: a spot
// light in fog with toth) render through the command line at 48 x 48:
// - every one exits 0 with a finite, non-black image;
// - toth's (physical) images match the CPU reference (single scattering,
//   exact visibility, 16 spp) with relMSE <= 0.01 (measured 0.004 for the
//   colonnade, 3e-6 for the spot; most of the colonnade's error is in the
//   sky, where toth marches to the distance far instead of to the far plane,
//   README "background");
// - mitchell's and sousa's shafts are there: the image minus the same
//   render with exposure / brightness 0 is >= 0 everywhere and not 0.
#include "st_test_render.h"

#define SIZE "--size 48x48"
static char out[512], ref[512], off[512];

static double relmse(const st_image *a, const st_image *b) {
    double s = 0;
    size_t n = (size_t)a->width * a->height * 3;
    for (size_t k = 0; k < n; k++)
        s += pow(a->data[k] - b->data[k], 2) / (pow(b->data[k], 2) + 0.01);
    return s / n;
}

static double mean(const st_image *a) {
    double s = 0;
    size_t n = (size_t)a->width * a->height * 3;
    for (size_t k = 0; k < n; k++)
        s += a->data[k];
    return s / n;
}

static bool render(const char *scene, const char *path, const char *extra, st_image *img) {
    char file[1024], args[512];
    snprintf(file, sizeof file, "%s/scenes/%s.json", ST_TEST_SOURCE_DIR, scene);
    snprintf(args, sizeof args, SIZE " %s", extra ? extra : "");
    int rc = st_test_render(file, path, args);
    CHECK(rc == 0, "%s: strahl render rc %d", scene, rc);
    if (rc != 0 || !st_test_read(path, img)) return false;
    CHECK(st_test_all_finite(img), "%s: finite", scene);
    CHECK(mean(img) > 1e-4, "%s: not black (mean %g)", scene, mean(img));
    return true;
}

static void test_toth(const char *scene) {
    st_image gpu = {0}, cpu = {0};
    if (!render(scene, out, NULL, &gpu)) return;
    unlink(ref);
    int rc = st_test_sh("%s reference %s/scenes/%s.json -o %s " SIZE
                        " --spp 16 --bounces 0 --filter point",
                        ST_TEST_STRAHL, ST_TEST_SOURCE_DIR, scene, ref);
    CHECK(rc == 0, "%s: strahl reference rc %d", scene, rc);
    if (rc == 0 && st_test_read(ref, &cpu)) {
        double e = relmse(&gpu, &cpu);
        printf("%-16s toth vs reference: relMSE %.3g (mean %.4f vs %.4f)\n", scene, e, mean(&gpu),
               mean(&cpu));
        CHECK(e <= 0.01, "%s: toth vs reference relMSE %g", scene, e);
        // The sky pixels' rays end at the far plane, far / cos off the axis,
        // in both (toth once marched only `far`: colonnade_sun 0.2723 vs 0.2716
        // now, its background alone 14% too bright before).
        double rm = mean(&gpu) / fmax(mean(&cpu), 1e-30);
        CHECK(fabs(rm - 1.0) <= 0.01, "%s: toth mean / reference mean %g", scene, rm);
    }
    st_image_free(&gpu);
    st_image_free(&cpu);
}

static void test_screen_space(const char *scene, const char *zero) {
    st_image with = {0}, without = {0};
    if (render(scene, out, NULL, &with) && render(scene, off, zero, &without)) {
        double lo = 0, sum = 0;
        for (size_t k = 0; k < (size_t)with.width * with.height * 3; k++) {
            double d = with.data[k] - without.data[k];
            lo = fmin(lo, d), sum += d;
        }
        printf("%-24s shafts: energy %.4g, smallest difference %.3g\n", scene, sum, lo);
        CHECK(lo >= -1e-6 && sum > 1, "%s: shafts add light (energy %g, min %g)", scene, sum, lo);
    }
    st_image_free(&with);
    st_image_free(&without);
}

int main(void) {
    snprintf(out, sizeof out, "%s/scene.exr", ST_TEST_SCRATCH);
    snprintf(ref, sizeof ref, "%s/ref.exr", ST_TEST_SCRATCH);
    snprintf(off, sizeof off, "%s/off.exr", ST_TEST_SCRATCH);
    test_toth("colonnade_sun");
    test_toth("spot_fog");
    test_screen_space("colonnade_sun_mitchell", "--set mitchell.exposure=0");
    test_screen_space("colonnade_sun_sousa", "--set sousa.brightness=0");
    return st_test_summary("test_scenes_sun_spot");
}
