// Numerical stress: singular and extreme configurations must render every
// pixel finite and non-negative (the render succeeds and every value of the
// image read back is checked): the light on a
// pixel's centre ray, at the camera, behind it, on a surface (d -> 0); sigma
// 0 and 1e3; g = +-0.999; 1 to 1024 samples (equi-angular: at most 256 per
// ray, llvmpipe's loop budget); both samplings, each
// integrator, interleaving and reduced resolution, bisection and node counts
// at their limits.
// The 112 scenes render in this process (st_test_render_here, as `strahl
// render --filter point` does): a process start-up per scene cost 5x the
// renders.
#include "toth_test.h"
#include "st_test_support.h"

enum { N = 32 };
static char scene[512];
static int renders, bad;

// The scene file rendered on the point filter: 1 on success (else a CHECK
// says why), img holds the image.
static int render_here(const char *path, st_image *img) {
    st_err err = {0};
    bool ok = st_test_render_here(path, img, &err);
    CHECK(ok, "%s: %s", path, err.msg);
    if (ok) CHECK(st_test_all_finite(img), "%s: every pixel finite", path);
    return ok && st_test_all_finite(img);
}

static void run(const double light[3], const char *medium, const char *params) {
    const double I[3] = {10, 20, 5};
    toth_write_room(scene, N, light, I, 0.6, medium, params);
    st_image img = {0};
    renders++;
    int ok = render_here(scene, &img);
    float lo = 0;
    for (size_t k = 0; ok && k < (size_t)N * N * 3; k++)
        lo = fminf(lo, img.data[k]);
    if (!ok || !st_test_all_finite(&img) || lo < 0) {
        // Keep the scene for a post-mortem.
        bad++;
        st_test_sh("cp %s %s/stress_failed_%d.json", scene, ST_TEST_SCRATCH, bad);
    }
    CHECK(lo >= 0, "light (%g %g %g), %s, %s: negative radiance %g", light[0], light[1], light[2],
          medium, params, lo);
    st_image_free(&img);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/stress.json", ST_TEST_SCRATCH);
    st_context *ctx = st_test_context();
    st_test_cam c = st_test_camera(ROOM_CAM, ROOM_TGT, ROOM_UP, ROOM_FOV, N, N);

    // Light positions: on the centre ray of pixel (11, 7) at 1.7 m; exactly at
    // the camera; 0.5 m behind it; on the back wall where pixel (20, 13) looks.
    double on_ray[3], on_wall[3], behind[3], d[3];
    st_test_ray(&c, 11, 7, d);
    for (int k = 0; k < 3; k++)
        on_ray[k] = c.pos[k] + 1.7 * d[k];
    st_test_ray(&c, 20, 13, d);
    double s = toth_box_exit(c.pos, d, ROOM_MIN, ROOM_MAX);
    for (int k = 0; k < 3; k++)
        on_wall[k] = c.pos[k] + s * d[k], behind[k] = c.pos[k] - 0.5 * c.f[k];
    const double *lights[4] = {on_ray, ROOM_CAM, behind, on_wall};

    const char *media[] = {
        "\"sigma_s\": [0.2, 0.3, 0.4], \"sigma_a\": [0.01, 0, 0.1]",
        "\"sigma_s\": [1000, 1000, 1000], \"sigma_a\": [1000, 1000, 1000]",
        "\"sigma_s\": [0, 0.5, 1000], \"sigma_a\": [0, 0, 0], \"phase\": {\"hg\": 0.999}",
        "\"sigma_s\": [0.2, 0.2, 0.2], \"phase\": {\"hg\": -0.999}",
        "\"sigma_s\": [0, 0, 0], \"sigma_a\": [1000, 0, 0]",
        "\"sigma_s\": [1e-30, 1e-30, 1e-30], \"phase\": \"rayleigh\"",
    };
    const char *params[] = {
        "\"samples\": 1",
        // 256 equi-angular steps per ray: the most llvmpipe runs whole (toth
        // refuses more there, test_toth_budget); 1024 over 2x2 and 3x3 below.
        "\"samples\": 256, \"interleave\": 1",
        "\"sampling\": \"uniform\", \"samples\": 1024, \"interleave\": 1",
        "\"samples\": 64, \"interleave\": 8, \"resolution\": \"quarter\"",
        "\"samples\": 1, \"integrator\": \"thesis\", \"jitter\": false",
        "\"samples\": 7, \"integrator\": \"thesis_far\", \"resolution\": \"half\"",
        "\"samples\": 1024, \"interleave\": 3, \"jitter\": false",
        "\"sampling\": \"uniform\", \"samples\": 1",
        "\"sampling\": \"uniform\", \"samples\": 64, \"interleave\": 8, \"resolution\": "
        "\"quarter\"",
        "\"samples\": 1, \"bisect\": 8, \"nodes\": 4, \"refine\": 0",
        "\"samples\": 1024, \"bisect\": 0, \"nodes\": 64, \"resolution\": \"half\", "
        "\"interleave\": 2",
    };
    // Every light with every medium at default settings, then every setting
    // with every light in the first two media.
    for (int l = 0; l < 4; l++)
        for (size_t m = 0; m < sizeof media / sizeof media[0]; m++)
            run(lights[l], media[m], "");
    for (int l = 0; l < 4; l++)
        for (size_t p = 0; p < sizeof params / sizeof params[0]; p++)
            for (int m = 0; m < 3; m += 2)
                run(lights[l], media[m], params[p]);
    printf("  %d renders, %d failed or non-finite\n", renders, bad);
    CHECK(bad == 0, "%d of %d stress renders failed", bad, renders);
    st_context_destroy(ctx);
    return st_test_summary("toth_stress");
}
