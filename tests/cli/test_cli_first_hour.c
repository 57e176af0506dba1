// A researcher's first hour (issue 37) through the real `strahl` command:
// switching techniques from the command line (--enable/--disable, --set on
// the enabled one), two in-scattering techniques refused unless overlaid,
// honest status lines and the terminal-only progress line, -o repeated,
// `strahl info` and --auto-camera, a driver's limit in the parameter's help.
// Renders are 32x24 point frames, or short box runs.
#include "st_test.h"
#include "st_test_render.h"
#include "st_base.h"
#include "st_image.h"
#include "st_scene.h"
#include <math.h>

static char out[16384];
static const char *win = ST_TEST_SOURCE_DIR "/scenes/godrays_window.json";
#define SMALL "--size 32x24 --filter point --frames 1"

static int run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int run(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    // view needs an X server: a virtual one (xvfb-run, which tools/setup.sh installs).
    const char *wrap = strncmp(fmt, "view ", 5) ? "" : "xvfb-run -a -s '-screen 0 320x240x24' ";
    int rc = st_test_strahl_v(out, sizeof out, ST_TEST_SCRATCH, 120, wrap, fmt, ap);
    va_end(ap);
    return rc;
}

static bool has(const char *s) {
    return strstr(out, s) != NULL;
}

// Two EXRs of the scratch folder hold the same pixels.
static bool same_exr(const char *a, const char *b) {
    char pa[1024], pb[1024];
    snprintf(pa, sizeof pa, "%s/%s", ST_TEST_SCRATCH, a);
    snprintf(pb, sizeof pb, "%s/%s", ST_TEST_SCRATCH, b);
    st_image x = {0}, y = {0};
    bool ok = st_test_read(pa, &x) && st_test_read(pb, &y) && x.width == y.width &&
              x.height == y.height && x.channels == y.channels &&
              !memcmp(x.data, y.data, sizeof(float) * (size_t)x.width * x.height * x.channels);
    st_image_free(&x);
    st_image_free(&y);
    return ok;
}

static double mean_exr(const char *a) {
    char pa[1024];
    snprintf(pa, sizeof pa, "%s/%s", ST_TEST_SCRATCH, a);
    st_image x = {0};
    double s = 0;
    size_t n = 0;
    if (st_test_read(pa, &x)) n = (size_t)x.width * x.height * x.channels;
    for (size_t i = 0; i < n; i++)
        s += x.data[i];
    st_image_free(&x);
    return n ? s / (double)n : -1;
}

static bool exists(const char *name) {
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", ST_TEST_SCRATCH, name);
    return st_test_exists(p);
}

// Byte-equal files of the scratch folder.
static bool same_file(const char *a, const char *b) {
    char pa[1024], pb[1024];
    snprintf(pa, sizeof pa, "%s/%s", ST_TEST_SCRATCH, a);
    snprintf(pb, sizeof pb, "%s/%s", ST_TEST_SCRATCH, b);
    st_err e = {0};
    size_t la = 0, lb = 0;
    char *x = st_read_file(pa, &la, &e), *y = st_read_file(pb, &lb, &e);
    bool ok = x && y && la == lb && !memcmp(x, y, la);
    free(x);
    free(y);
    return ok;
}

// (1) Switching techniques on the command line gives the variant scene's
// image bit for bit; --set reaches the enabled module; mistakes exit 2.
static void switching(void) {
    int rc = run("render %s " SMALL " --disable toth --enable froxel -o sw.exr", win);
    CHECK(rc == 0, "--disable toth --enable froxel: exit %d: %s", rc, out);
    rc = run("render %s/scenes/godrays_window_froxel.json " SMALL " -o fx.exr", ST_TEST_SOURCE_DIR);
    CHECK(rc == 0 && same_exr("sw.exr", "fx.exr"),
          "switched to froxel differs from godrays_window_froxel.json (exit %d)", rc);
    rc = run("render %s " SMALL " --set mitchell.n=50 --set mitchell.sky=1 --disable toth --enable "
             "mitchell -o swm.exr",
             win);
    CHECK(rc == 0, "--enable mitchell with --set mitchell.n=50: exit %d: %s", rc, out);
    rc = run("render %s/scenes/godrays_window_mitchell.json " SMALL " --set mitchell.n=50 -o m.exr",
             ST_TEST_SOURCE_DIR);
    CHECK(rc == 0 && same_exr("swm.exr", "m.exr"), "switched to mitchell differs (exit %d)", rc);
    // What an enabled module requires comes with it: toth brings shadow_map.
    rc = run("render %s/scenes/plane.json " SMALL " --enable toth --set toth.samples=8 -o p.exr",
             ST_TEST_SOURCE_DIR);
    CHECK(rc == 0, "plane.json --enable toth: exit %d: %s", rc, out);
    rc = run("info %s/scenes/plane.json --enable toth", ST_TEST_SOURCE_DIR);
    CHECK(rc == 0 && has("  shadow_map\n") && has("requires shadow_map: shadow_map"),
          "info --enable toth does not list shadow_map providing it: %s", out);
    // bench and view switch alike (view under a virtual X server).
    rc = run("bench %s --filter point --reference fx.exr --sweep froxel.slices=32,48 "
             "--csv b.csv --frames 1 --warmup 0 --size 32x24 --disable toth --enable froxel",
             win);
    CHECK(rc == 0, "bench --disable toth --enable froxel: exit %d: %s", rc, out);
    char script[1024];
    snprintf(script, sizeof script, "%s/switch.script", ST_TEST_SCRATCH);
    FILE *f = fopen(script, "w");
    fputs("frames 1\nexpect-module froxel on\nexpect-module toth off\nset froxel.slices 32\n"
          "expect-param froxel.slices 32\nquit\n",
          f);
    fclose(f);
    rc = run("view %s --size 32x24 --disable toth --enable froxel --script switch.script", win);
    CHECK(rc == 0, "view --disable toth --enable froxel: exit %d: %s", rc, out);
    rc = run("render %s " SMALL " --disable nosuch -o bad.exr", win);
    CHECK(rc == 2 && has("disable 'nosuch'") && has("not in the scene") && !exists("bad.exr"),
          "--disable nosuch: exit %d: %s", rc, out);
    rc = run("render %s " SMALL " --disable shadow_map -o bad.exr", win);
    CHECK(rc == 2 && has("'toth' still requires 'shadow_map'") && !exists("bad.exr"),
          "--disable shadow_map under toth: exit %d: %s", rc, out);
    rc = run("render %s " SMALL " --enable nosuch -o bad.exr", win);
    CHECK(rc == 2 && has("enable 'nosuch'") && !exists("bad.exr"), "--enable nosuch: exit %d: %s",
          rc, out);
}

// (2) toth and froxel both add the medium's in-scattering: refused, both
// named, unless overlaid on purpose; the overlay adds light.
static void inscatter(void) {
    int rc = run("render %s " SMALL " --enable froxel -o both.exr", win);
    CHECK(rc == 2 && has("'toth'") && has("'froxel'") && has("in-scattering") &&
              !exists("both.exr"),
          "toth + froxel: exit %d: %s", rc, out);
    rc = run("render %s " SMALL " --enable froxel --overlay -o both.exr", win);
    CHECK(rc == 0, "toth + froxel --overlay: exit %d: %s", rc, out);
    rc = run("render %s " SMALL " -o toth.exr", win);
    double both = mean_exr("both.exr"), toth = mean_exr("toth.exr"), fx = mean_exr("fx.exr");
    CHECK(rc == 0 && both > toth && both > fx, "overlay mean %g, toth %g, froxel %g", both, toth,
          fx);
    // The scene key says the same as --overlay.
    char p[1024];
    snprintf(p, sizeof p, "%s/overlay.json", ST_TEST_SCRATCH);
    FILE *f = fopen(p, "w");
    fprintf(f, "{\"inscatter_overlay\": true, \"image\": {\"width\": 32, \"height\": 24},\n"
               " \"camera\": {\"position\": [0, 1, 4], \"target\": [0, 1, 0], \"fov_y\": 50},\n"
               " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.8, 0], \"intensity\": [3, "
               "3, 3]}],\n"
               " \"geometry\": [{\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}}],\n"
               " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0, 0, 0]},\n"
               " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}, {\"name\": "
               "\"froxel\"}]}\n");
    fclose(f);
    rc = run("render overlay.json " SMALL " -o key.exr");
    CHECK(rc == 0, "\"inscatter_overlay\": true: exit %d: %s", rc, out);
}

// (3) The final line says what stopped the frames; never "converged" for
// --frames, never an error of 0 or inf without the reason.
static void status_lines(void) {
    int rc = run("render %s --size 32x24 --frames 1 -o s.exr", win);
    CHECK(rc == 0 && has("1 frame(s) (--frames 1)") && has("no estimate") && !has("converged") &&
              !has("error 0") && !has("inf"),
          "--frames 1: exit %d: %s", rc, out);
    rc = run("render %s --size 32x24 --frames 6 -o s.exr", win);
    double e = -1;
    const char *p = strstr(out, "estimated remaining relative error ");
    if (p) sscanf(p, "estimated remaining relative error %lf", &e);
    CHECK(rc == 0 && has("6 frame(s) (--frames 6)") && !has("converged") && isfinite(e) && e > 0,
          "--frames 6: exit %d, error %g: %s", rc, e, out);
    rc = run("render %s --size 32x24 --max-frames 3 -o s.exr", win);
    CHECK(rc == 0 && has("3 frame(s), stopped by --max-frames 3 before converging") &&
              !has("converged after"),
          "--max-frames 3: exit %d: %s", rc, out);
    // Not a terminal: stderr stays empty (the final line is on stdout).
    char cmd[4096], err_path[1024];
    snprintf(err_path, sizeof err_path, "%s/stderr.txt", ST_TEST_SCRATCH);
    rc = st_test_sh("cd '%s' && '%s' render %s --size 32x24 --max-seconds 0.5 -o s.exr 2>'%s' "
                    ">/dev/null",
                    ST_TEST_SCRATCH, ST_TEST_STRAHL, win, err_path);
    size_t len = 99;
    st_err ignore = {0};
    free(st_read_file(err_path, &len, &ignore));
    CHECK(rc == 0 && len == 0, "stderr not a terminal: exit %d, %zu bytes on stderr", rc, len);
    // A terminal (script's pseudo-terminal): the self-overwriting line with
    // frames, the error and an ETA; --quiet: none.
    for (int quiet = 0; quiet < 2; quiet++) {
        snprintf(cmd, sizeof cmd,
                 "cd '%s' && script -qec \"'%s' render %s --size 32x24 --max-seconds 1.4 %s -o "
                 "s.exr\" /dev/null",
                 ST_TEST_SCRATCH, ST_TEST_STRAHL, win, quiet ? "--quiet" : "");
        rc = st_test_capture(out, sizeof out, cmd);
        bool line =
            has("\r\033[Kstrahl render: ") && has("ETA") && has("estimated remaining error");
        CHECK(rc == 0 && line != quiet, "on a terminal%s: exit %d, progress line %d: %s",
              quiet ? " with --quiet" : "", rc, line, out);
    }
}

// (4) -o repeated: every output holds the one still, as a single -o writes it.
static void outputs(void) {
    int rc = run("render %s " SMALL " -o two.png -o two.exr", win);
    CHECK(rc == 0 && exists("two.png") && exists("two.exr"), "-o a.png -o b.exr: exit %d: %s", rc,
          out);
    run("render %s " SMALL " -o one.png", win);
    run("render %s " SMALL " -o one.exr", win);
    CHECK(same_file("two.png", "one.png") && same_exr("two.exr", "one.exr"),
          "the outputs of one render differ from single renders");
    rc = run("render %s " SMALL " -o dup.png -o dup.png", win);
    CHECK(rc == 2 && has("given twice") && !exists("dup.png"), "-o twice: exit %d: %s", rc, out);
}

// (5) info's numbers are the scene's; a glTF without a camera is refused
// with the way out named, and --auto-camera frames every corner of its bounds.
static void info_and_camera(void) {
    st_scene sc = {0};
    st_err err = {0};
    CHECK(st_scene_load(win, &sc, &err), "%s", err.msg);
    double lo[3], hi[3];
    st_scene_bounds(&sc, lo, hi);
    char tris[64], bounds[256];
    snprintf(tris, sizeof tris, "%llu triangles", (unsigned long long)st_scene_triangle_count(&sc));
    snprintf(bounds, sizeof bounds, "bounds: (%.4g, %.4g, %.4g) .. (%.4g, %.4g, %.4g)", lo[0],
             lo[1], lo[2], hi[0], hi[1], hi[2]);
    st_scene_free(&sc);
    int rc = run("info %s --disable toth --enable froxel", win);
    CHECK(rc == 0 && has(tris) && has(bounds) && has("  froxel\n") && !has("  toth\n") &&
              has("lights: 1") && has("medium: sigma_s (0.06, 0.065, 0.07)"),
          "info: exit %d, wanted '%s' and '%s': %s", rc, tris, bounds, out);
    char p[1024];
    snprintf(p, sizeof p, "%s/nocam.json", ST_TEST_SCRATCH);
    FILE *f = fopen(p, "w");
    fprintf(f,
            "{\"image\": {\"width\": 32, \"height\": 24},\n"
            " \"lights\": [{\"type\": \"point\", \"position\": [6, 8, 8], \"intensity\": [300, "
            "300, 300]}],\n"
            " \"geometry\": [{\"gltf\": \"%s/tests/data/crosscheck/meshes.glb\"}]}\n",
            ST_TEST_SOURCE_DIR);
    fclose(f);
    rc = run("render nocam.json --filter point -o cam.exr");
    CHECK(rc == 2 && has("camera") && has("--auto-camera") && !exists("cam.exr"),
          "no camera: exit %d: %s", rc, out);
    rc = run("render nocam.json --filter point --auto-camera -o cam.exr");
    CHECK(rc == 0 && mean_exr("cam.exr") > 0, "--auto-camera: exit %d, mean %g: %s", rc,
          mean_exr("cam.exr"), out);
    st_scene_opts o = {.flags = ST_AUTO_CAMERA};
    bool loaded = st_scene_load_ex(p, &o, &sc, &err);
    CHECK(loaded && sc.camera_auto, "%s", err.msg);
    if (!loaded) return;
    st_scene_bounds(&sc, lo, hi);
    const st_camera_desc *c = &sc.camera;
    double fw[3], up[3] = {c->up[0], c->up[1], c->up[2]}, rt[3], u[3], nf = 0, nr = 0;
    for (int k = 0; k < 3; k++)
        fw[k] = (double)c->target[k] - c->position[k], nf += fw[k] * fw[k];
    for (int k = 0; k < 3; k++)
        fw[k] /= sqrt(nf);
    for (int k = 0; k < 3; k++) {
        rt[k] = fw[(k + 1) % 3] * up[(k + 2) % 3] - fw[(k + 2) % 3] * up[(k + 1) % 3];
        nr += rt[k] * rt[k];
    }
    for (int k = 0; k < 3; k++)
        rt[k] /= sqrt(nr);
    for (int k = 0; k < 3; k++)
        u[k] = rt[(k + 1) % 3] * fw[(k + 2) % 3] - rt[(k + 2) % 3] * fw[(k + 1) % 3];
    double t = tan(c->fov_y * M_PI / 360.0), worst = 0;
    for (int k = 0; k < 8; k++) { // the vertical field is the narrower one (width >= height)
        double q[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double z = 0, x = 0, y = 0;
        for (int a = 0; a < 3; a++) {
            double d = q[a] - c->position[a];
            z += d * fw[a], x += d * rt[a], y += d * u[a];
        }
        CHECK(z > c->near_z && z < c->far_z, "corner %d at depth %g outside [%g, %g]", k, z,
              c->near_z, c->far_z);
        worst = fmax(worst, fmax(fabs(x), fabs(y)) / (z * t));
    }
    CHECK(worst <= 1.0 && worst > 0.3, "the bounds fill %g of the half field of view", worst);
    st_scene_free(&sc);
}

// (6) A limit a driver enforces below the descriptor's range is in the
// parameter's help, with the number that is enforced: on llvmpipe toth
// refuses 257 samples (per ray) and takes 256.
static void driver_ranges(void) {
    // (the whole list is longer than the buffer: grep keeps the line)
    int rc = run("modules --json | grep -o 'on llvmpipe at most 256 [a-z -]*'");
    CHECK(rc == 0 && has("on llvmpipe at most 256 equi-angular steps per ray"),
          "toth.samples' help does not name llvmpipe's 256: exit %d", rc);
    rc = run("render %s/scenes/plane.json --size 8x8 --filter point --stats=json -o r8.exr",
             ST_TEST_SOURCE_DIR);
    bool llvmpipe = rc == 0 && has("llvmpipe");
    rc = run("render %s --size 16x12 --filter point --frames 1 --set toth.samples=257 -o r.exr",
             win);
    if (llvmpipe)
        CHECK(rc == 2 && has("at most 256 per ray"), "llvmpipe, 257 samples: exit %d: %s", rc, out);
    else
        CHECK(rc == 0, "257 samples off llvmpipe: exit %d: %s", rc, out);
    rc = run("render %s --size 16x12 --filter point --frames 1 --set toth.samples=256 -o r.exr",
             win);
    CHECK(rc == 0, "256 samples: exit %d: %s", rc, out);
}

int main(void) {
    // Outputs of an earlier run must not pass for this one's.
    st_test_sh("rm -f '%s'/*.exr '%s'/*.png", ST_TEST_SCRATCH, ST_TEST_SCRATCH);
    switching();
    inscatter();
    status_lines();
    outputs();
    info_and_camera();
    driver_ranges();
    return st_test_summary("cli_first_hour");
}
