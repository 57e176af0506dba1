// The out-of-tree example plugin (examples/plugin, exponential height fog:
// a compute pass writes each pixel's optical depth into the plugin's target,
// exported to the full-screen pass that applies it) built against an
// installed strahl, twice: with find_package(strahl) and with pkg-config.
// The installed strahl renders a plane under a point light seen from above
// through the fog; every pixel must match
//   L = L_s T + R (1 - T),  L_s = rho/pi I cos / r^2,  T = e^(-tau),
//   tau = a e^(-b (y0 - h)) (1 - e^(-b d dir_y)) / (b dir_y)
// along the pixel's ray (d the distance to the plane).
#include "sdk_test.h"
#include "st_test_render.h"

#define N 33
static const double H = 3, HL = 2, I = 4, RHO = 0.5;      // camera height, light height
static const double A = 0.3, B = 0.7, HF = 0.5, R = 0.25; // fog parameters

static const char *scene_fmt =
    "{\"image\": {\"width\": %d, \"height\": %d},\n"
    " \"camera\": {\"position\": [0, %g, 0], \"target\": [0, 0, 0], \"up\": [0, 0, -1], \"fov_y\": "
    "60,"
    " \"near\": 0.05, \"far\": 100},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, %g, 0], \"intensity\": [%g, %g, %g]}],\n"
    " \"geometry\": [{\"quad\": {\"corner\": [-10, 0, -10], \"u\": [0, 0, 20], \"v\": [20, 0, 0]},"
    " \"albedo\": [%g, %g, %g]}],\n"
    " \"modules\": [{\"name\": \"height_fog\", \"params\": {\"density\": %g, \"falloff\": %g, "
    "\"height\": %g,"
    " \"radiance\": %g}}]}\n";

static double expected(int i, int j) {
    const double pos[3] = {0, H, 0}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
    st_test_cam c = st_test_camera(pos, target, up, 60, N, N);
    double d[3];
    st_test_ray(&c, i, j, d);
    double t = H / -d[1], x = t * d[0], z = t * d[2];
    double r = sqrt(x * x + HL * HL + z * z);
    double Ls = RHO / M_PI * I * (HL / r) / (r * r);
    double k = B * t * d[1];
    double tau = A * exp(-B * (H - HF)) * (1 - exp(-k)) / (B * d[1]);
    double T = exp(-tau);
    return Ls * T + R * (1 - T);
}

// Renders the scene with the installed strahl and the plugin in `modules`;
// returns the max relative error over all pixels (or 1e9 on failure).
static double check_render(const char *prefix, const char *modules, const char *scene,
                           const char *what) {
    char out[1200];
    snprintf(out, sizeof out, "%s/%s.exr", ST_TEST_SCRATCH, what);
    unlink(out);
    int rc = st_test_sh("env -u STRAHL_SHADER_PATH STRAHL_MODULE_PATH=%s %s/bin/strahl render %s "
                        "-o %s --filter point",
                        modules, prefix, scene, out);
    CHECK(rc == 0, "%s: installed strahl renders with the example plugin (rc %d)", what, rc);
    st_image img = {0};
    if (rc || !st_test_read(out, &img)) return 1e9;
    double worst = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double e = expected(i, j);
            for (int ch = 0; ch < 3; ch++) {
                double rel = fabs(st_image_px(&img, i, j)[ch] - e) / e;
                if (!(rel <= worst)) worst = rel;
            }
        }
    printf("%s: centre pixel %.6f, expected %.6f; max relative error over %dx%d pixels %.2e\n",
           what, st_image_px(&img, N / 2, N / 2)[0], expected(N / 2, N / 2), N, N, worst);
    st_image_free(&img);
    return worst;
}

int main(void) {
    char prefix[1024], fog[1024], pc[1024], scene[1024], json[4096];
    snprintf(prefix, sizeof prefix, "%s/prefix", ST_TEST_SCRATCH);
    snprintf(fog, sizeof fog, "%s/fog", ST_TEST_SCRATCH);
    snprintf(pc, sizeof pc, "%s/pc", ST_TEST_SCRATCH);
    snprintf(scene, sizeof scene, "%s/fog.json", ST_TEST_SCRATCH);
    snprintf(json, sizeof json, scene_fmt, N, N, H, HL, I, I, I, RHO, RHO, RHO, A, B, HF, R);
    st_test_write(scene, json);
    st_test_sh("rm -rf %s", pc);

    int rc = sdk_install(prefix);
    CHECK(rc == 0, "cmake --install (rc %d)", rc);
    // The SDK's headers are what a plugin needs (with the shared model and
    // services), each one compiling on its own; the host's side of the world,
    // statistics, images and files are not installed.
    static const char *const sdk[] = {"st_base.h",  "st_bvh.h",    "st_gl.h",       "st_godray.h",
                                      "st_gpu.h",   "st_model.h",  "st_module.h",   "st_physics.h",
                                      "st_scene.h", "st_shader.h", "st_world_api.h"};
    char listing[1024] = "";
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "LC_ALL=C ls %s/include/strahl | tr '\\n' ' '", prefix);
    st_test_capture(listing, sizeof listing, cmd);
    char want[1024] = "";
    for (size_t i = 0; i < sizeof sdk / sizeof sdk[0]; i++) {
        size_t l = strlen(want);
        snprintf(want + l, sizeof want - l, "%s ", sdk[i]);
        rc = st_test_sh("printf '#include <%s>\\nint main(void) { return 0; }\\n' | %s -std=c11 "
                        "-fsyntax-only -x c - $(PKG_CONFIG_PATH=%s/lib/pkgconfig pkg-config "
                        "--cflags strahl)",
                        sdk[i], ST_TEST_CC, prefix);
        CHECK(rc == 0, "installed %s compiles on its own (rc %d)", sdk[i], rc);
    }
    CHECK(!strcmp(listing, want), "installed headers: '%s', expected '%s'", listing, want);
    // find_package(strahl) and strahl_add_plugin.
    char src[1200];
    snprintf(src, sizeof src, "%s/examples/plugin", ST_TEST_SOURCE_DIR);
    rc = sdk_build(src, fog, prefix, NULL);
    CHECK(rc == 0, "example configures and builds against the installed SDK (rc %d)", rc);
    // pkg-config, by hand: the .so and its shaders/height_fog/ beside it.
    rc = st_test_sh(
        "mkdir -p %s/shaders && cp -r %s/examples/plugin/shaders/height_fog %s/shaders/ && "
        "PKG_CONFIG_PATH=%s/lib/pkgconfig %s -std=c11 -shared -fPIC -fvisibility=hidden "
        "-o %s/height_fog.so %s/examples/plugin/height_fog.c $(PKG_CONFIG_PATH=%s/lib/pkgconfig "
        "pkg-config --cflags --libs strahl)",
        pc, ST_TEST_SOURCE_DIR, pc, prefix, ST_TEST_CC, pc, ST_TEST_SOURCE_DIR, prefix);
    CHECK(rc == 0, "example builds with pkg-config (rc %d)", rc);

    char modules[1200];
    snprintf(modules, sizeof modules, "%s/modules", fog);
    double e1 = check_render(prefix, modules, scene, "cmake");
    double e2 = check_render(prefix, pc, scene, "pkgconfig");
    CHECK(e1 < 2e-4, "find_package build: max relative error %g", e1);
    CHECK(e2 < 2e-4, "pkg-config build: max relative error %g", e2);
    return st_test_summary("test_sdk_example");
}
