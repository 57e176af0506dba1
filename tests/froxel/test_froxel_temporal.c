// froxel's temporal reprojection on a static view (godrays_window at 64 x 64,
// point filter): the first frame has no history and equals the plain
// method's frame; after the frames the module asks for (history^n < 1%:
// strahl render without --frames runs them) the blend of the jittered
// slice samples is at least as close to the reference as the slice
// midpoints, and `strahl render --stats` reports the frames blended.
#include "froxel/froxel_test.h"

int main(void) {
    char scene[512], ref[512], out[512], plain[512];
    snprintf(scene, sizeof scene, "%s/scenes/godrays_window_froxel.json", ST_TEST_SOURCE_DIR);
    snprintf(ref, sizeof ref, "%s/ref.exr", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/temporal.exr", ST_TEST_SCRATCH);
    snprintf(plain, sizeof plain, "%s/plain.exr", ST_TEST_SCRATCH);
    if (!froxel_reference(scene, ref, 8, "--size 64x64"))
        return st_test_summary("test_froxel_temporal");

    // Frame 0: no history yet, the slice midpoints.
    CHECK(st_test_render(scene, plain, "--size 64x64 --frames 1") == 0, "plain render");
    CHECK(st_test_render(scene, out, "--size 64x64 --frames 1 --set froxel.temporal=true") == 0,
          "temporal, one frame");
    st_image a = {0}, b = {0};
    if (st_test_read(plain, &a) && st_test_read(out, &b)) {
        double worst = 0, top = 0;
        for (size_t k = 0; k < (size_t)64 * 64 * 3; k++) {
            worst = fmax(worst, fabs(a.data[k] - b.data[k]));
            top = fmax(top, fabs(a.data[k]));
        }
        printf("  first frame: max |temporal - plain| %.3g (image max %.3g)\n", worst, top);
        CHECK(worst <= 1e-6 * top, "first frame differs by %.3g", worst);
    }
    st_image_free(&a);
    st_image_free(&b);

    froxel_cmp p = froxel_compare(scene, ref, plain, "--size 64x64");
    char log[512];
    snprintf(log, sizeof log, "%s/stats.txt", ST_TEST_SCRATCH);
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "--size 64x64 --set froxel.temporal=true --stats > %s", log);
    froxel_cmp t = froxel_compare(scene, ref, out, cmd);
    printf("  nrmse: slice midpoints %.4f, temporal %.4f\n", p.nrmse, t.nrmse);
    CHECK(t.ok && t.nrmse <= 0.10, "temporal nrmse %.4f", t.nrmse);
    CHECK(t.ok && t.nrmse <= p.nrmse * 1.05, "temporal %.4f worse than midpoints %.4f", t.nrmse,
          p.nrmse);
    char buf[8192] = "";
    snprintf(cmd, sizeof cmd, "cat %s", log);
    st_test_capture(buf, sizeof buf, cmd);
    const char *at = strstr(buf, "temporal: ");
    int done = 0, need = 0;
    CHECK(at && sscanf(at, "temporal: %d of %d frames blended", &done, &need) == 2,
          "--stats names the temporal blend");
    printf("  %d of %d frames blended\n", done, need);
    CHECK(need == 44 && done >= need, "frames blended %d of %d", done, need);
    return st_test_summary("test_froxel_temporal");
}
