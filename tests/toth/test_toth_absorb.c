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
#include "toth_test.h"

#define W 96
#define H 72
static const double CAM[3] = {0, 1.5, 6}, TGT[3] = {0, 1, -1}, UP[3] = {0, 1, 0};
static const double FOV = 50, FAR = 12;
static const double SA[3] = {0.6, 0.3, 0.1};  // sigma_a, 1/m
static const double EM[3] = {1.0, 0.5, 0.25}; // emitter radiance
static const double BG[3] = {0.2, 0.3, 0.4};  // background radiance
static const double LP[3] = {0, 3, 2}, LI[3] = {10, 8, 6}, RHO = 0.5;
static const double EM_X = 1.5, EM_Y0 = 0, EM_Y1 = 3, EM_Z = -1; // emitter quad
static const double FL_X = 4, FL_Z0 = -1, FL_Z1 = 6;             // floor y = 0
static const double MARGIN = 0.03; // metres kept from an edge (the centre ray's neighbours)

static char scene[512], out[512];

static void write_scene(const char *modules) {
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g, \"near\": 0.05, \"far\": %g},\n"
             " \"background\": [%g, %g, %g],\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [%g, %g, %g], \"u\": [%g, 0, 0], \"v\": [0, %g, 0]},"
             " \"albedo\": [0, 0, 0], \"emission\": [%g, %g, %g]},\n"
             "  {\"quad\": {\"corner\": [%g, 0, %g], \"u\": [0, 0, %g], \"v\": [%g, 0, 0]},"
             " \"albedo\": [%g, %g, %g]}],\n"
             " \"medium\": {\"sigma_s\": [0, 0, 0], \"sigma_a\": [%g, %g, %g]},\n"
             " \"modules\": [%s]}\n",
             W, H, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, FAR, BG[0], BG[1], BG[2],
             LP[0], LP[1], LP[2], LI[0], LI[1], LI[2], -EM_X, EM_Y0, EM_Z, 2 * EM_X, EM_Y1 - EM_Y0,
             EM[0], EM[1], EM[2], -FL_X, FL_Z0, FL_Z1 - FL_Z0, 2 * FL_X, RHO, RHO, RHO, SA[0],
             SA[1], SA[2], modules);
    st_test_write(scene, json);
}

typedef struct {
    int emitter, floor, background; // pixels checked
    double worst;                   // relative error
    double min_t_emitter;           // the shortest emitter distance seen
} result;

// Checks every pixel whose centre ray hits the emitter, the floor or nothing
// at least MARGIN from any edge.
static result check(const st_image *img) {
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, W, H);
    result r = {0, 0, 0, 0, 1e30};
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            double te = (EM_Z - CAM[2]) / d[2], tf = d[1] < 0 ? -CAM[1] / d[1] : 1e30;
            double pe[3], pf[3];
            for (int k = 0; k < 3; k++)
                pe[k] = CAM[k] + te * d[k], pf[k] = CAM[k] + tf * d[k];
            // Distances of the hit points from the quads' edges (> 0 inside).
            double ie = fmin(EM_X - fabs(pe[0]), fmin(pe[1] - EM_Y0, EM_Y1 - pe[1]));
            double iflo = fmin(FL_X - fabs(pf[0]), fmin(pf[2] - FL_Z0, FL_Z1 - pf[2]));
            bool hit_e = te > 0 && ie > 0, hit_f = tf < 1e30 && iflo > 0;
            double want[3], t;
            int *count;
            if (hit_f && (!hit_e || tf < te)) { // the floor (in front of the emitter)
                if (iflo < MARGIN || (hit_e && te - tf < MARGIN)) continue;
                double l[3] = {LP[0] - pf[0], LP[1] - pf[1], LP[2] - pf[2]};
                double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2], dl = sqrt(d2);
                t = tf;
                for (int k = 0; k < 3; k++)
                    want[k] = RHO / M_PI * LI[k] * (l[1] / dl) / d2 * exp(-SA[k] * (dl + t));
                count = &r.floor;
            } else if (hit_e) {
                if (ie < MARGIN) continue;
                t = te;
                for (int k = 0; k < 3; k++)
                    want[k] = EM[k] * exp(-SA[k] * t);
                r.min_t_emitter = fmin(r.min_t_emitter, t);
                count = &r.emitter;
            } else {
                if (ie > -MARGIN || iflo > -MARGIN) continue; // near an edge, outside
                double cos_axis = d[0] * c.f[0] + d[1] * c.f[1] + d[2] * c.f[2];
                t = FAR / cos_axis;
                for (int k = 0; k < 3; k++)
                    want[k] = BG[k] * exp(-SA[k] * t);
                count = &r.background;
            }
            const float *px = st_image_px(img, i, j);
            for (int k = 0; k < 3; k++)
                r.worst = fmax(r.worst, fabs(px[k] - want[k]) / want[k]);
            (*count)++;
        }
    return r;
}

static void run(const char *what, const char *modules, bool reference) {
    write_scene(modules);
    st_image img = {0};
    int rc = reference
                 ? st_test_sh("%s reference %s -o %s --spp 1 --bounces 0 --filter point >/dev/null",
                              ST_TEST_STRAHL, scene, out)
                 : st_test_render(scene, out, NULL);
    CHECK(rc == 0, "%s: exit %d", what, rc);
    if (rc != 0 || !st_test_read(out, &img)) return;
    result r = check(&img);
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
