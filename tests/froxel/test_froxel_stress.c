// Numerical stress: singular and extreme configurations must render every
// pixel finite and non-negative (the render must succeed and every value of
// the image read back is checked), and froxel only adds
// light: each image at least the one without a volumetric module. The light
// on a pixel's centre ray, at the camera, behind it, on a wall (d -> 0);
// sigma 0, 1e-30 and 1e3; g = 0.999; a 1 x 1 x 1 grid and a 256 x 256 x 16
// one, 1 and 256 slices, exponents 0 and 30, a grid that ends before the
// walls (the camera outside the fog beyond it), near field off and at its
// radius limits, jitter; height fog with the camera inside the dense layer
// and far above a thin one. Energy bound: a sun over a floor in a medium
// with sigma_t = 2000 /m can scatter at most sigma_s / sigma_t phase E
// toward the camera (the floor itself is extinguished).
// The scenes render in this process (st_test_render_here, as `strahl render
// --filter point` does): a process start-up per scene cost more than the render.
#include "st_test_render.h"
#include "st_test_support.h"

enum { N = 32 };
static char scene[512];
static int renders, bad;

// Renders the scene file; 0 on success, else 1 (why goes to stderr).
static int render(st_image *img) {
    st_err err = {0};
    if (st_test_render_here(scene, img, &err)) return 0;
    fprintf(stderr, "%s: %s\n", scene, err.msg);
    return 1;
}
static const double CAM[3] = {0, 1.2, 1.5}, TGT[3] = {0, 1.0, -2}, UP[3] = {0, 1, 0};

static void write_room(const double light[3], const char *medium, const char *modules) {
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": 60, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%.17g, %.17g, %.17g], "
             "\"intensity\": [10, 20, 5]},\n"
             "   {\"type\": \"spot\", \"position\": [0.5, 2.9, -1], \"direction\": [0, -1, 0], "
             "\"intensity\": [5, 5, 5], \"outer_angle\": 20},\n"
             "   {\"type\": \"directional\", \"direction\": [0.3, -1, 0.2], \"irradiance\": [1, "
             "1, 1]}],\n"
             " \"geometry\": [{\"box\": {\"min\": [-2, 0, -2], \"max\": [2, 3, 2]}, \"inward\": "
             "true, \"albedo\": [0.6, 0.6, 0.6]},\n"
             "   {\"box\": {\"min\": [-0.5, 0, -1], \"max\": [0, 1, -0.5]}, \"albedo\": [0.5, 0.5, "
             "0.5]}],\n"
             " \"medium\": {%s},\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 128}}%s]}\n",
             N, N, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], light[0], light[1], light[2],
             medium, modules);
    st_test_write(scene, json);
}

// The image without a volumetric module, per light and medium (rendered once).
static st_image base[4][8];
static int base_rc[4][8];

static void run(int li, const double light[3], int mi, const char *medium, const char *params) {
    if (!base[li][mi].data && !base_rc[li][mi]) {
        write_room(light, medium, "");
        base_rc[li][mi] = render(&base[li][mi]);
    }
    int rc0 = base_rc[li][mi];
    const st_image *img0 = &base[li][mi];
    char mods[512];
    snprintf(mods, sizeof mods, ", {\"name\": \"froxel\", \"params\": {%s}}", params);
    write_room(light, medium, mods);
    renders++;
    st_image img = {0};
    int rc = render(&img);
    bool ok = rc == 0 && rc0 == 0 && st_test_all_finite(&img);
    float lo = 0, less = 0;
    for (size_t k = 0; ok && k < (size_t)N * N * 3; k++) {
        lo = fminf(lo, img.data[k]);
        less = fminf(less, img.data[k] - img0->data[k]);
    }
    CHECK(ok, "light (%g %g %g), %s, %s: render %d/%d, finite", light[0], light[1], light[2],
          medium, params, rc, rc0);
    CHECK(lo >= 0, "light (%g %g %g), %s, %s: negative radiance %g", light[0], light[1], light[2],
          medium, params, lo);
    CHECK(less >= -1e-6f, "light (%g %g %g), %s, %s: froxel took light away (%g)", light[0],
          light[1], light[2], medium, params, less);
    if (!ok || lo < 0 || less < -1e-6f) {
        bad++;
        st_test_sh("cp %s %s/stress_failed_%d.json", scene, ST_TEST_SCRATCH, bad);
    }
    st_image_free(&img);
}

// A sun straight over a floor (the medium above the floor is lit without
// loss: the sun's path starts at the scene's top, the floor), the camera 1 m
// above it looking down, isotropic medium with sigma_s = sigma_a = 1000:
// every pixel <= 0.5 E / (4 pi), and reaches it (the floor is extinguished).
static void energy_bound(const char *params, bool reach) {
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [0, 1, 0.5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 60, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], "
             "\"irradiance\": [3, 2, 1]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-5, 0, -5], \"u\": [0, 0, 10], \"v\": [10, "
             "0, 0]}, \"albedo\": [0.8, 0.8, 0.8]}],\n"
             " \"medium\": {\"sigma_s\": [1000, 1000, 1000], \"sigma_a\": [1000, 1000, 1000]},\n"
             " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"froxel\", \"params\": "
             "{%s}}]}\n",
             N, N, params);
    st_test_write(scene, json);
    st_image img = {0};
    int rc = render(&img);
    CHECK(rc == 0, "energy bound %s: render %d", params, rc);
    if (rc != 0) return;
    const double E[3] = {3, 2, 1};
    double worst = 0, top = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int k = 0; k < 3; k++) {
                double bound = 0.5 * E[k] / (4 * M_PI), v = st_image_px(&img, i, j)[k];
                worst = fmax(worst, v / bound);
                if (i == N / 2 && j == N / 2) top = fmax(top, v / bound);
            }
    printf("  energy bound %-30s largest pixel / bound %.4f (centre %.4f)\n", params, worst, top);
    CHECK(worst <= 1.001, "energy bound %s: %.4f of the bound", params, worst);
    // The medium is optically thick right at the camera: the bound is reached
    // (not by a single slice sampled 50 m away, below the floor).
    CHECK(!reach || top >= 0.95, "energy bound %s: centre only %.4f of the bound", params, top);
    st_image_free(&img);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/stress.json", ST_TEST_SCRATCH);
    st_context *ctx = st_test_context();
    st_test_cam c = st_test_camera(CAM, TGT, UP, 60, N, N);
    double on_ray[3], on_wall[3], behind[3], d[3];
    st_test_ray(&c, 11, 7, d);
    for (int k = 0; k < 3; k++)
        on_ray[k] = c.pos[k] + 1.7 * d[k];
    st_test_ray(&c, 20, 13, d);
    double s = st_test_ray_box(c.pos, d, (const double[3]){-2, 0, -2}, (const double[3]){2, 3, 2});
    for (int k = 0; k < 3; k++)
        on_wall[k] = c.pos[k] + s * d[k], behind[k] = c.pos[k] - 0.5 * c.f[k];
    const double *lights[4] = {on_ray, CAM, on_wall, behind};
    const char *media[] = {
        "\"sigma_s\": [0.2, 0.3, 0.4], \"sigma_a\": [0.01, 0, 0.1]",
        "\"sigma_s\": [1000, 1000, 1000], \"sigma_a\": [1000, 1000, 1000]",
        "\"sigma_s\": [0, 0.5, 1000], \"sigma_a\": [0, 0, 0], \"phase\": {\"hg\": 0.999}",
        "\"sigma_s\": [1e-30, 1e-30, 1e-30], \"phase\": \"rayleigh\"",
        "\"sigma_s\": [0.5, 0.5, 0.5], \"density\": {\"height\": {\"base\": 2.5, \"falloff\": 4}}",
        "\"sigma_s\": [5, 5, 5], \"density\": {\"height\": {\"base\": -3, \"falloff\": 40}}",
    };
    const char *params[] = {
        "\"grid_x\": 1, \"grid_y\": 1, \"slices\": 1, \"min_rows\": 0",
        "\"grid_x\": 256, \"grid_y\": 256, \"slices\": 16",
        "\"slices\": 256, \"exponent\": 30",
        "\"slices\": 7, \"exponent\": 0, \"tile\": 64, \"min_rows\": 0",
        "\"far\": 0.5",
        "\"near_field\": false",
        "\"near_radius\": 16",
        "\"near_radius\": 0.25, \"jitter\": true",
    };
    // The first three lights with every medium at default settings, then
    // every setting with the light on a ray and at the camera in the first
    // medium; the light behind the camera with the extreme ones.
    for (int l = 0; l < 3; l++)
        for (size_t m = 0; m < sizeof media / sizeof media[0]; m++)
            run(l, lights[l], (int)m, media[m], "");
    for (int l = 0; l < 2; l++)
        for (size_t p = 0; p < sizeof params / sizeof params[0]; p++)
            run(l, lights[l], 0, media[0], params[p]);
    for (int m = 1; m < 3; m++)
        run(3, lights[3], m, media[m], "\"slices\": 3, \"grid_x\": 5");
    energy_bound("", true);
    energy_bound("\"slices\": 1, \"grid_x\": 1, \"grid_y\": 1, \"min_rows\": 0", false);
    energy_bound("\"slices\": 256, \"exponent\": 0", true);
    printf("  %d renders, %d failed\n", renders, bad);
    st_context_destroy(ctx);
    return st_test_summary("test_froxel_stress");
}
