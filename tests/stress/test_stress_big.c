// Image-size stress: a 4096 x 4096 render of a lit floor with only the
// regular pass (no modules) must render (its time is printed, not asserted) with every
// value finite and match the analytic direct light; so must the extreme
// aspect ratios 4096 x 1 and 1 x 4096 (a near-180 degree horizontal field).
#include "stress.h"

static const double CAM[3] = {0, 2.5, 3}, TGT[3] = {0, 0, 0}, UP[3] = {0, 1, 0}, FOV = 50;
static const double LIGHT[3] = {0.3, 1, -0.2}, I = 2, RHO = 0.6;

static const char *SCENE =
    "{\"image\": {\"width\": 64, \"height\": 64},"
    " \"camera\": {\"position\": [0, 2.5, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "50,"
    " \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0.3, 1, -0.2], \"intensity\": [2, 2, 2]}],"
    " \"geometry\": [{\"quad\": {\"corner\": [-50, 0, -50], \"u\": [0, 0, 100], \"v\": [100, 0, "
    "0]},"
    " \"albedo\": [0.6, 0.6, 0.6]}]}";

// Worst relative error against rho/pi I cos / d^2 over every `step`-th
// pixel that sees the floor within 40 m (the quad's far edge is at 50 m).
static double floor_error(const st_image *img, int step, int *checked) {
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, img->width, img->height);
    const double q[3] = {0, 0, 0}, n[3] = {0, 1, 0};
    double worst = 0;
    *checked = 0;
    for (int j = 0; j < img->height; j += step)
        for (int i = 0; i < img->width; i += step) {
            double t;
            double want = stress_plane_direct(&c, i, j, q, n, RHO, LIGHT, I, &t);
            if (!(t > 0) || t > 40) continue;
            double got = st_image_px(img, i, j)[0];
            // Radiance falls as 1/d^3 far away: an absolute floor of 1e-6
            // of the peak (0.6/pi * 2 = 0.38) keeps float rounding out.
            worst = fmax(worst, fabs(got - want) / (want + 4e-7));
            ++*checked;
        }
    return worst;
}

int main(void) {
    double t0 = stress_now();
    const struct {
        const char *size;
        int step;
    } cases[] = {{"4096x4096", 16}, {"4096x1", 1}, {"1x4096", 1}};
    for (int k = 0; k < 3; k++) {
        char name[64], extra[64];
        snprintf(name, sizeof name, "big_%s", cases[k].size);
        snprintf(extra, sizeof extra, "--size %s", cases[k].size);
        st_image img = {0};
        double t = stress_now();
        int ok = stress_render(name, SCENE, extra, &img);
        t = stress_now() - t;
        if (!ok) continue;
        int checked;
        double e = floor_error(&img, cases[k].step, &checked);
        stress_stats s = stress_image_stats(&img);
        printf("  %-16s %dx%d in %.1f s, max %.4g, analytic error %.2e over %d pixels\n", name,
               img.width, img.height, t, s.max, e, checked);
        CHECK(checked >= 20, "%s: %d pixels checked", name, checked);
        CHECK(e < 0.01, "%s: worst relative error against the analytic floor %.3g", name, e);
        CHECK(s.negative == 0, "%s: %zu negative values", name, s.negative);
        st_image_free(&img);
    }
    printf("  %.1f s\n", stress_now() - t0);
    return st_test_summary("test_stress_big");
}
