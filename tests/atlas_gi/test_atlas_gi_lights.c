// atlas_gi and ssgi take direct light from a sun and a spot into what they
// bounce (the atlas' G-buffer, the camera's HDR image). Perpendicular unit
// squares sharing an edge: the receiver on the floor (albedo 0.5, facing +y),
// the sender wall at z = 0 (albedo 0.5, facing +z), no emitters.
// - Sun from behind the floor (travel (0, 0.6, -0.8)): the wall gets
//   rho/pi E cos = 1 everywhere (E = pi / (0.5 0.8)), the floor nothing
//   directly, so its area-averaged indirect radiance is rho F with the form
//   factor F = 0.200044, within 2% (as test_atlas_gi_formfactor for an
//   emitter of radiance 1), for the transfer (default) and the gather.
// - Spot in front of the wall (inside its inner cone): the wall's radiance
//   L0(y) = rho/pi I cos / d^2 varies by 16% over it; the oracle is the
//   receiver's area average of rho/pi integral L0 cos cos / d^2 dA, by the
//   midpoint rule relative to the same rule for L0 = 1 (times the exact rho
//   F); within 2%.
// - ssgi with the sun (oblique view, both squares in it) agrees with atlas_gi
//   on the receiver's mean within 5%, as test_ssgi does for an emitter.
#include "gi_test.h"

#define H 128
#define K 100
static const double RHO = 0.5, COS_SUN = 0.8;
static const double SPOT[3] = {0.5, 0.5, 2.0}, SPOT_I = 3.0;

static void scene(char *out, size_t n, const char *camera, const char *light, const char *module) {
    snprintf(out, n,
             "{\"image\": {\"width\": %d, \"height\": %d}, %s, \"lights\": [%s],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [0, 0, 0], \"u\": [0, 0, 1], \"v\": [1, 0, 0]}, "
             "\"albedo\": [%g, %g, %g]},\n"
             "  {\"quad\": {\"corner\": [0, 0, 0], \"u\": [1, 0, 0], \"v\": [0, 1, 0]}, "
             "\"albedo\": [%g, %g, %g]}],\n"
             " \"modules\": [%s]}\n",
             H, H, camera, light, RHO, RHO, RHO, RHO, RHO, RHO, module);
}

// The sun: rho/pi E cos = 1 on the wall.
static void sun_json(char *out, size_t n) {
    double E = GI_PI / (RHO * COS_SUN);
    snprintf(out, n,
             "{\"type\": \"directional\", \"direction\": [0, 0.6, -0.8], \"irradiance\": [%.17g, "
             "%.17g, %.17g]}",
             E, E, E);
}

static void spot_json(char *out, size_t n) {
    snprintf(out, n,
             "{\"type\": \"spot\", \"position\": [%g, %g, %g], \"direction\": [0, 0, -1], "
             "\"intensity\": [%g, %g, %g], \"inner_angle\": 30, \"outer_angle\": 45}",
             SPOT[0], SPOT[1], SPOT[2], SPOT_I, SPOT_I, SPOT_I);
}

// The wall's radiance at (x, y, 0) under the spot (inside the inner cone: f = 1).
static double wall_L0_spot(double x, double y) {
    double v[3] = {SPOT[0] - x, SPOT[1] - y, SPOT[2]};
    double d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    return RHO / GI_PI * SPOT_I * (v[2] / sqrt(d2)) / d2;
}

// Area average over the receiver of rho/pi integral_wall L0 cos_x cos_y / d^2 dA
// (spot = 0: L0 = 1), midpoint rule with n^4 points.
static double receiver_mean(int n, int spot) {
    double s = 0;
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) {
            double x[3] = {(a + 0.5) / n, 0, (b + 0.5) / n};
            for (int e = 0; e < n; e++)
                for (int f = 0; f < n; f++) {
                    double y[3] = {(e + 0.5) / n, (f + 0.5) / n, 0};
                    double d[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
                    double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    double cx = d[1] / sqrt(d2), cy = -d[2] / sqrt(d2); // normals +y, +z
                    double L0 = spot ? wall_L0_spot(y[0], y[1]) : 1.0;
                    s += L0 * cx * cy / (GI_PI * d2);
                }
        }
    return RHO * s / ((double)n * n * n * n);
}

// The midpoint rule overestimates near the shared edge, where the kernel is
// singular (n = 20: 3.4% for L0 = 1); the ratio to the same rule with L0 = 1
// cancels that, and times the exact rho F it converges (0.011213, 0.011217,
// 0.011223 at n = 10, 20, 40).
static double receiver_mean_spot(int n) {
    return receiver_mean(n, 1) / receiver_mean(n, 0) * RHO * 0.200044;
}

static const char *ATLAS_GATHER =
    "{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, \"mode\": \"gather\", "
    "\"visibility\": false, \"samples\": 256, \"display\": \"indirect\", \"max_frames\": 16, "
    "\"tolerance\": 0}}";
static const char *ATLAS_TRANSFER =
    "{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, \"display\": \"indirect\"}}";

static double headon(const char *name, const char *light, const char *module, const char *extra) {
    char json[4096], cam[512];
    gi_headon_camera(cam, sizeof cam, H, K, 3.0);
    scene(json, sizeof json, cam, light, module);
    st_image img = {0};
    if (!gi_render(name, json, extra, &img)) return NAN;
    double v = gi_headon_mean(&img, K, 0);
    CHECK_REL(gi_headon_mean(&img, K, 2), v, 1e-5, 1e-9); // grey in, grey out
    st_image_free(&img);
    return v;
}

int main(void) {
    char sun[256], spot[256];
    sun_json(sun, sizeof sun);
    spot_json(spot, sizeof spot);
    const double want_sun = RHO * 0.200044, want_spot = receiver_mean_spot(20);
    printf("spot: the wall's radiance at a bottom corner is %.3f of its centre's\n",
           wall_L0_spot(0, 0) / wall_L0_spot(0.5, 0.5));
    struct {
        const char *name, *light, *module, *extra;
        double want;
    } cases[4] = {
        {"sun_transfer", sun, ATLAS_TRANSFER, NULL, want_sun},
        {"sun_gather", sun, ATLAS_GATHER, "--frames 16", want_sun},
        {"spot_transfer", spot, ATLAS_TRANSFER, NULL, want_spot},
        {"spot_gather", spot, ATLAS_GATHER, "--frames 16", want_spot},
    };
    for (int k = 0; k < 4; k++) {
        double v = headon(cases[k].name, cases[k].light, cases[k].module, cases[k].extra);
        printf("%-14s receiver mean indirect %.6f, oracle %.6f (rel %+.4f)\n", cases[k].name, v,
               cases[k].want, v / cases[k].want - 1);
        CHECK(fabs(v / cases[k].want - 1) <= 0.02, "%s: %g vs %g", cases[k].name, v, cases[k].want);
    }

    // ssgi against atlas_gi with the sun, both squares in view.
    char json[4096];
    const char *cam = "\"camera\": {\"position\": [0.5, 1.2, 2.6], \"target\": [0.5, 0.35, 0.3], "
                      "\"up\": [0, 1, 0], \"fov_y\": 45, \"near\": 0.05, \"far\": 100}";
    st_image ref = {0}, ss = {0};
    scene(json, sizeof json, cam, sun, ATLAS_GATHER);
    int ok = gi_render("oblique_atlas", json, "--frames 16", &ref);
    scene(json, sizeof json, cam, sun,
          "{\"name\": \"ssgi\", \"params\": {\"samples\": 1024, \"display\": \"indirect\"}}");
    ok = gi_render("oblique_ssgi", json, NULL, &ss) && ok;
    if (ok) {
        double a = gi_masked_mean(&ref, &ref, NULL), s = gi_masked_mean(&ss, &ref, NULL);
        printf("sun, oblique view: mean indirect atlas_gi %.6f, ssgi %.6f (rel %+.4f)\n", a, s,
               s / a - 1);
        CHECK(a > 0.01 && fabs(s / a - 1) <= 0.05, "ssgi %g vs atlas_gi %g", s, a);
    }
    st_image_free(&ref);
    st_image_free(&ss);
    return st_test_summary("test_atlas_gi_lights");
}
