// A purely absorbing medium (sigma_s = 0): nothing scatters, but every path
// is attenuated (docs/physics.md), and the view ray's share belongs to the
// regular pass, so it is applied whichever volumetric module is loaded (none,
// toth, mitchell, sousa), each of which has nothing to add here. Per pixel
// (centre ray) within 1%:
//   - an emitter 7 m away (sigma_a = 0.6/m on axis): E e^(-sigma_a t);
//   - a lit floor: rho/pi I cos / d^2 e^(-sigma_a (d + t));
//   - the background at the far plane: B e^(-sigma_a far / cos);
// and `strahl reference` gives the same values. That toth, when it runs,
// does not apply the view's extinction a second time is
// test_toth_analytic's compose check (L_surface e^(-sigma_t s) + L_in to 1e-4).
#include "absorb_scene.h"

static void run(const char *what, const char *modules, bool reference) {
    write_scene(modules);
    st_image img = {0};
    int rc = reference
                 ? st_test_sh("%s reference %s -o %s --spp 1 --bounces 0 --filter point >/dev/null",
                              ST_TEST_STRAHL, scene, out)
                 : st_test_render(scene, out, NULL);
    CHECK(rc == 0, "%s: exit %d", what, rc);
    if (rc != 0 || !st_test_read(out, &img)) return;
    result r = check(&img, NULL);
    printf(
        "  %-22s worst relative error %.2e (%d emitter px from %.2f m, %d floor, %d background)\n",
        what, r.worst, r.emitter, r.min_t_emitter, r.floor, r.background);
    CHECK(r.emitter > 300 && r.floor > 300 && r.background > 100, "%s: pixels %d %d %d", what,
          r.emitter, r.floor, r.background);
    CHECK(r.worst < 0.01, "%s: worst relative error %.4f", what, r.worst);
    CHECK(st_test_all_finite(&img), "%s: finite", what);
    st_image_free(&img);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/absorb.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/absorb.exr", ST_TEST_SCRATCH);
    run("no module", "", false);
    run("toth", "{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}", false);
    run("mitchell", "{\"name\": \"mitchell\"}", false);
    run("sousa", "{\"name\": \"sousa\"}", false);
    run("reference", "", true);
    // On the axis the emitter is 7 m away: e^(-0.6 * 7) = 0.015, not 1.
    write_scene("{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}");
    st_image img = {0};
    if (st_test_render(scene, out, NULL) == 0 && st_test_read(out, &img)) {
        // The pixel below the image centre whose ray meets the emitter at x = 0.
        st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, W, H);
        double best = 1e30, got = 0, t_axis = 0;
        for (int j = 0; j < H; j++) {
            double d[3];
            st_test_ray(&c, W / 2, j, d);
            double te = (EM_Z - CAM[2]) / d[2], y = CAM[1] + te * d[1];
            if (y > EM_Y0 + 0.2 && y < EM_Y1 && fabs(y - 1.5) < best)
                best = fabs(y - 1.5), got = st_image_px(&img, W / 2, j)[0], t_axis = te;
        }
        printf("  emitter at %.2f m: %.5f (e^(-0.6 t) = %.5f)\n", t_axis, got, exp(-0.6 * t_axis));
        CHECK(fabs(got - exp(-0.6 * t_axis)) < 0.01 * exp(-0.6 * t_axis), "emitter: %.5f", got);
        st_image_free(&img);
    }
    return st_test_summary("test_toth_absorb");
}
