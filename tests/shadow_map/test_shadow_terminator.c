// shadow_map at a smooth mesh's shadow terminator (issue 20, spot_room:
// pixels at Suzanne's ear lit at 0.57 where the reference and Cycles are
// black). Near the terminator of a coarse smooth-shaded sphere the
// interpolated normal still faces the light where the facet itself has
// turned away: the exact shadow ray (`strahl reference`) leaves through the
// facet and finds the sphere, so the point is in shadow; the shadow map,
// biased, saw nothing there. Against `strahl reference --aov direct --spp 1
// --filter point` (pixel centres, no noise for a point light): no pixel lit
// where the reference is black, and the image within NRMSE 0.02 of it.
#include "st_test_render.h"
#include "st_test_support.h"

static const char *const SCENE =
    "{\"image\": {\"width\": 96, \"height\": 96},\n"
    " \"camera\": {\"position\": [-0.6, 0.3, 4], \"target\": [0, 0, 0], \"up\": [0, 1, 0],"
    " \"fov_y\": 36, \"near\": 0.05, \"far\": 100},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [4, 0.6, 0.3], \"intensity\": [20, 20, "
    "20]}],\n"
    " \"geometry\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 1, \"rings\": 6, "
    "\"segments\": 8}, \"albedo\": [0.8, 0.8, 0.8]}],\n"
    " \"modules\": [{\"name\": \"shadow_map\"}]}\n";

int main(void) {
    char scene[512], out[512], ref[512], cmd[2048];
    static char buf[1 << 14];
    snprintf(scene, sizeof scene, "%s/terminator.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/terminator.exr", ST_TEST_SCRATCH);
    snprintf(ref, sizeof ref, "%s/terminator_ref.exr", ST_TEST_SCRATCH);
    st_test_write(scene, SCENE);
    snprintf(cmd, sizeof cmd, "%s reference %s -o %s --aov direct --spp 1 --filter point 2>&1",
             ST_TEST_STRAHL, scene, ref);
    CHECK(st_test_capture(buf, sizeof buf, cmd) == 0, "reference: %s", buf);
    CHECK(st_test_render(scene, out, NULL) == 0, "render");
    st_image img = {0}, exact = {0};
    if (st_test_read(ref, &exact) && st_test_read(out, &img)) {
        int lit = 0, dark = 0, wrong = 0;
        double sq = 0, sum = 0;
        for (int j = 0; j < img.height; j++)
            for (int i = 0; i < img.width; i++) {
                const float *v = st_image_px(&img, i, j), *r = st_image_px(&exact, i, j);
                double a = (v[0] + v[1] + v[2]) / 3, b = (r[0] + r[1] + r[2]) / 3;
                lit += b > 0.01, dark += b == 0;
                // Self-shadowed in the reference, lit in the render.
                wrong += b == 0 && a > 0.01;
                for (int c = 0; c < 3; c++)
                    sq += (v[c] - r[c]) * (v[c] - r[c]), sum += r[c];
            }
        double n = 3.0 * img.width * img.height, nrmse = sqrt(sq / n) / (sum / n);
        printf("terminator: %d lit and %d black pixels in the reference, %d of them lit in the "
               "render; NRMSE %.4f\n",
               lit, dark, wrong, nrmse);
        CHECK(lit > 500 && dark > 1000, "the sphere is not partly lit: %d lit, %d black", lit,
              dark);
        CHECK(wrong == 0, "%d pixels lit where the reference is self-shadowed", wrong);
        CHECK(nrmse <= 0.02, "NRMSE %g against the reference", nrmse);
    }
    st_image_free(&img);
    st_image_free(&exact);
    return st_test_summary("test_shadow_terminator");
}
