// froxel's temporal reprojection under a moving camera (godrays_window at
// 64 x 64, point filter, scripted `strahl view` under Xvfb): 45 frames
// converge at the scene's pose A, then the camera moves to pose B (0.5 m
// sideways and up, the shafts seen from another angle) and the screenshots
// after 1 and 10 frames there are compared with the CPU reference at B. The
// history must follow the move: its error at B stays within 1.5x the plain
// single frame's at B (no history) plus 0.01, and far below the error of the
// image left from pose A (what a history that did not move would give).
#include "froxel/froxel_test.h"
#include "view/view_test.h"

static const char pose_a[] = "\"position\": [2.4, 1.5, 2.6]";
static const char pose_b[] = "\"position\": [2.0, 1.8, 2.9]";

// Scene A's text with the camera moved to pose B (no relative asset paths).
static bool write_pose_b(const char *a, const char *b) {
    st_err err = {0};
    char *text = st_read_file(a, NULL, &err);
    char *at = text ? strstr(text, pose_a) : NULL;
    FILE *f = at ? fopen(b, "w") : NULL;
    if (!f) {
        free(text);
        return false;
    }
    fprintf(f, "%.*s%s%s", (int)(at - text), text, pose_b, at + strlen(pose_a));
    free(text);
    return fclose(f) == 0;
}

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], scene_b[512], ref[512], plain[512], script[512], path[1024];
    snprintf(scene, sizeof scene, "%s/scenes/godrays_window_froxel.json", ST_TEST_SOURCE_DIR);
    snprintf(scene_b, sizeof scene_b, "%s/pose_b.json", D);
    snprintf(ref, sizeof ref, "%s/ref_b.exr", D);
    snprintf(plain, sizeof plain, "%s/plain_b.exr", D);
    snprintf(script, sizeof script, "%s/motion.script", D);
    CHECK(write_pose_b(scene, scene_b), "scene at pose B");
    if (st_t_fail || !froxel_reference(scene_b, ref, 8, "--size 64x64"))
        return st_test_summary("test_froxel_motion");

    FILE *f = fopen(script, "w");
    CHECK(f != NULL, "script");
    if (!f) return st_test_summary("test_froxel_motion");
    fprintf(f,
            "frames 45\nscreenshot %s/at_a\n"
            "camera 2.0 1.8 2.9 -1.2 0.9 -0.6\nframes 1\nscreenshot %s/moved1\n"
            "frames 9\nscreenshot %s/moved10\n",
            D, D, D);
    fclose(f);
    static char log[65536];
    int rc = st_view_run(scene, script, "--size 64x64 --set froxel.temporal=true", log, sizeof log);
    CHECK(rc == 0, "strahl view --script exit code %d:\n%s", rc, log);

    froxel_cmp p = froxel_compare(scene_b, ref, plain, "--size 64x64");
    double e[3];
    static const char *const shots[] = {"at_a", "moved1", "moved10"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/%s.exr", D, shots[k]);
        st_image a = {0}, b = {0}, bs = {0};
        st_err err = {0};
        st_metrics m;
        e[k] = INFINITY;
        if (st_test_read(path, &a) && st_test_read(ref, &b) &&
            st_image_read_exr_stderr(ref, &bs, &err) &&
            st_image_compare_noisy(&a, &b, &bs, &m, &err) && m.mean_b[3] > 0)
            e[k] = m.rmse_debiased[3] / m.mean_b[3];
        CHECK(isfinite(e[k]), "%s against the reference at B: %s", shots[k], err.msg);
        st_image_free(&a), st_image_free(&b), st_image_free(&bs);
    }
    printf("  nrmse at pose B: plain frame %.4f; temporal 1 frame after the move %.4f, 10 frames "
           "%.4f; the image left from pose A %.4f\n",
           p.nrmse, e[1], e[2], e[0]);
    for (int k = 1; k < 3; k++)
        CHECK(e[k] <= 1.5 * p.nrmse + 0.01, "%s: nrmse %.4f above 1.5 x plain %.4f + 0.01",
              shots[k], e[k], p.nrmse);
    CHECK(e[0] >= 4 * fmax(e[1], e[2]), "the move is too small to show a smear: pose A %.4f", e[0]);
    return st_test_summary("test_froxel_motion");
}
