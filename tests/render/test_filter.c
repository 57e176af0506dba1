// The pixel filter of stills (docs/physics.md, docs/architecture.md "Pixel
// filter"): the jitter sequence, box against point on an emitter whose
// slanted edges cross pixels (the box value is the pixel's covered fraction),
// the frame graph's caching under jitter (--stats=json run counts), the EXR
// header's strahl.filter and compare's warning on a mismatch.
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"
#include <cjson/cJSON.h>

// (b) The sequence: k = 0 is the centre, every offset inside the pixel, the
// first 2^a 3^b offsets one per cell of the 2^a x 3^b grid (shifted by half
// a pixel with the points), the mean offset near 0.
static void check_sequence(void) {
    float o[2];
    st_jitter_offset(0, o);
    CHECK(o[0] == 0 && o[1] == 0, "offset 0 is (%g, %g), not the centre", o[0], o[1]);
    static const int grids[][2] = {{2, 3}, {4, 9}, {8, 27}, {16, 3}};
    for (size_t g = 0; g < sizeof grids / sizeof grids[0]; g++) {
        int nx = grids[g][0], ny = grids[g][1], n = nx * ny, cells[432] = {0};
        double mx = 0, my = 0;
        for (int k = 0; k < n; k++) {
            st_jitter_offset((uint32_t)k, o);
            CHECK(o[0] >= -0.5f && o[0] < 0.5f && o[1] >= -0.5f && o[1] < 0.5f,
                  "offset %d (%g, %g) outside the pixel", k, o[0], o[1]);
            mx += o[0], my += o[1];
            // Undo the half-pixel shift: h = offset mod 1 is the Halton point.
            double hx = o[0] < 0 ? o[0] + 1.0 : o[0], hy = o[1] < 0 ? o[1] + 1.0 : o[1];
            // Halton points lie on cell boundaries (left-closed): 1e-4 absorbs float rounding.
            cells[(int)(hy * ny + 1e-4) * nx + (int)(hx * nx + 1e-4)]++;
        }
        int empty = 0, crowded = 0;
        for (int c = 0; c < n; c++)
            empty += cells[c] == 0, crowded += cells[c] > 1;
        CHECK(empty == 0 && crowded == 0, "first %d offsets on a %dx%d grid: %d empty, %d crowded",
              n, nx, ny, empty, crowded);
        // A grid of n cells puts the mean within half a cell of 0 in each axis.
        CHECK(fabs(mx / n) <= 0.5 / nx && fabs(my / n) <= 0.5 / ny, "mean offset of %d: (%g, %g)",
              n, mx / n, my / n);
    }
}

// The emitter: a parallelogram of radiance 1 seen head-on by a pinhole
// camera, so its image is a parallelogram in pixel coordinates: corner
// C + s U + t V (s, t in [0, 1]), pixels (x right, y down the image).
#define W 32
#define H 32
static const double C[2] = {7.3, 24.6}, U[2] = {16.45, 0.0}, V[2] = {5.7, -15.35};
static const double CAM_D = 4.0, FOV = 40.0;

static bool inside(double x, double y) {
    // Solve (x, y) - C = s U + t V.
    double det = U[0] * V[1] - U[1] * V[0];
    double px = x - C[0], py = y - C[1];
    double s = (px * V[1] - py * V[0]) / det, t = (U[0] * py - U[1] * px) / det;
    return s >= 0 && s <= 1 && t >= 0 && t <= 1;
}

// Covered fraction of pixel (i, j): 256 x 256 point samples.
static double coverage(int i, int j) {
    int n = 0;
    for (int b = 0; b < 256; b++)
        for (int a = 0; a < 256; a++)
            n += inside(i + (a + 0.5) / 256, j + (b + 0.5) / 256);
    return n / 65536.0;
}

// What the mean of the first n jittered frames sees at pixel (i, j).
static double halton_coverage(int i, int j, int n, double *margin) {
    int in = 0;
    *margin = 1;
    for (int k = 0; k < n; k++) {
        float o[2];
        st_jitter_offset((uint32_t)k, o);
        double x = i + 0.5 + o[0], y = j + 0.5 + o[1];
        in += inside(x, y);
        // Distance in pixels to the nearest edge crossing, roughly: probe around.
        for (int d = 0; d < 4; d++) {
            double e = 1e-3, dx = d == 0 ? e : d == 1 ? -e : 0, dy = d == 2 ? e : d == 3 ? -e : 0;
            if (inside(x + dx, y + dy) != inside(x, y)) *margin = 0;
        }
    }
    return (double)in / n;
}

static void write_emitter_scene(const char *path, const char *filter) {
    double s = 2.0 * CAM_D * tan(FOV * M_PI / 360.0) / H; // metres per pixel at z = 0
    double cx = (C[0] - W / 2.0) * s, cy = (H / 2.0 - C[1]) * s;
    double u[2] = {U[0] * s, -U[1] * s}, v[2] = {V[0] * s, -V[1] * s};
    // Front normal normalize(u x v) must face the camera (+z): order u, v so.
    bool swap = u[0] * v[1] - u[1] * v[0] < 0;
    char text[2048];
    snprintf(text, sizeof text,
             "{\"image\": {\"width\": %d, \"height\": %d%s%s%s},\n"
             " \"camera\": {\"position\": [0, 0, %g], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": %g, \"near\": 0.1, \"far\": 10},\n"
             " \"lights\": [],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [%.9g, %.9g, 0], \"u\": [%.9g, %.9g, 0], "
             "\"v\": [%.9g, %.9g, 0]}, \"albedo\": [0, 0, 0], \"emission\": [1, 1, 1]}],\n"
             " \"modules\": []}\n",
             W, H, filter ? ", \"filter\": \"" : "", filter ? filter : "", filter ? "\"" : "",
             CAM_D, FOV, cx, cy, swap ? v[0] : u[0], swap ? v[1] : u[1], swap ? u[0] : v[0],
             swap ? u[1] : v[1]);
    st_test_write(path, text);
}

// `strahl render SCENE -o OUT EXTRA` with no --filter of its own
// (st_test_render asks for point): the scene's filter or EXTRA's.
static int render_as_is(const char *scene, const char *out, const char *extra) {
    unlink(out);
    return st_test_sh("%s render %s -o %s %s", ST_TEST_STRAHL, scene, out, extra);
}

// (a) Box against point on the emitter's edges.
static void check_edges(void) {
    char scene[512], scene_point[512], out[512];
    snprintf(scene, sizeof scene, "%s/emitter.json", ST_TEST_SCRATCH);
    snprintf(scene_point, sizeof scene_point, "%s/emitter_point.json", ST_TEST_SCRATCH);
    write_emitter_scene(scene, NULL);
    write_emitter_scene(scene_point, "point");
    static double cov[W * H];
    double area = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            area += cov[j * W + i] = coverage(i, j);
    CHECK_REL(area, fabs(U[0] * V[1] - U[1] * V[0]), 1e-3, 0);

    // Point, by the scene key and by --filter: 0 or 1 as the centre is in or out.
    st_image p = {0}, q = {0};
    snprintf(out, sizeof out, "%s/point.exr", ST_TEST_SCRATCH);
    CHECK(render_as_is(scene_point, out, "") == 0, "point render (scene key)");
    CHECK(st_test_read(out, &p), "read %s", out);
    snprintf(out, sizeof out, "%s/point_flag.exr", ST_TEST_SCRATCH);
    CHECK(render_as_is(scene, out, "--filter point") == 0, "--filter point render");
    CHECK(st_test_read(out, &q), "read %s", out);
    int wrong = 0;
    double point_sq = 0;
    for (int j = 0; p.data && q.data && j < H; j++)
        for (int i = 0; i < W; i++) {
            double want = inside(i + 0.5, j + 0.5);
            wrong += fabs(st_image_px(&p, i, j)[0] - want) > 1e-4 ||
                     st_image_px(&q, i, j)[0] != st_image_px(&p, i, j)[0];
            point_sq += pow(st_image_px(&p, i, j)[0] - cov[j * W + i], 2);
        }
    CHECK(wrong == 0, "%d point pixels are not inside(centre)", wrong);

    // Box with exactly 36 frames: each pixel is the share of the first 36
    // jittered centres inside (where none lies on an edge), and within the
    // sequence's stratification of the covered fraction.
    st_image b = {0};
    snprintf(out, sizeof out, "%s/box36.exr", ST_TEST_SCRATCH);
    CHECK(render_as_is(scene, out, "--frames 36") == 0, "box render, 36 frames");
    CHECK(st_test_read(out, &b), "read %s", out);
    int off = 0, checked = 0;
    double max36 = 0;
    for (int j = 0; b.data && j < H; j++)
        for (int i = 0; i < W; i++) {
            double margin, want = halton_coverage(i, j, 36, &margin),
                           got = st_image_px(&b, i, j)[0];
            if (margin > 0) checked++, off += fabs(got - want) > 1e-4;
            max36 = fmax(max36, fabs(got - cov[j * W + i]));
        }
    CHECK(off == 0 && checked > W * H * 9 / 10, "%d of %d box pixels differ from the sequence", off,
          checked);
    CHECK(max36 <= 0.12, "36 frames: max |box - covered fraction| = %g", max36);

    // The default (box, run to convergence): close to the covered fraction
    // everywhere, far closer than the point filter, and the same total.
    st_image d = {0};
    snprintf(out, sizeof out, "%s/box.exr", ST_TEST_SCRATCH);
    CHECK(render_as_is(scene, out, "") == 0, "default render");
    CHECK(st_test_read(out, &d), "read %s", out);
    double box_sq = 0, maxd = 0, sum = 0;
    for (int j = 0; d.data && j < H; j++)
        for (int i = 0; i < W; i++) {
            double e = st_image_px(&d, i, j)[0] - cov[j * W + i];
            box_sq += e * e, maxd = fmax(maxd, fabs(e)), sum += st_image_px(&d, i, j)[0];
        }
    double box_rmse = sqrt(box_sq / (W * H)), point_rmse = sqrt(point_sq / (W * H));
    printf("covered fraction: point rmse %.4f, box rmse %.4f (max %.4f), 36 frames max %.4f\n",
           point_rmse, box_rmse, maxd, max36);
    CHECK(maxd <= 0.1, "box: max |box - covered fraction| = %g", maxd);
    CHECK(box_rmse * 5 <= point_rmse, "box rmse %g is not 5x below point's %g", box_rmse,
          point_rmse);
    CHECK_REL(sum, area, 0.01, 0);
    st_image_free(&p);
    st_image_free(&q);
    st_image_free(&b);
    st_image_free(&d);
}

static int pass_runs(cJSON *j, const char *module, const char *pass, int *skipped) {
    cJSON *p;
    cJSON_ArrayForEach(p, cJSON_GetObjectItem(j, "passes")) {
        if (strcmp(cJSON_GetObjectItem(p, "module")->valuestring, module) ||
            strcmp(cJSON_GetObjectItem(p, "pass")->valuestring, pass))
            continue;
        if (skipped) *skipped = cJSON_GetObjectItem(p, "skipped")->valueint;
        return cJSON_GetObjectItem(p, "runs")->valueint;
    }
    return -1;
}

// (c) Jittered frames redo what depends on the camera only: a Cornell box
// with shadow_map, atlas_gi (transfer) and toth over 8 box-filtered frames
// renders the shadow cube, the atlas G-buffer and the transfer once.
static void check_caching(void) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/cornell.json", ST_TEST_SCRATCH);
    st_test_write(scene, "{\"image\": {\"width\": 48, \"height\": 48},\n"
                         " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], "
                         "\"up\": [0, 1, 0], \"fov_y\": 40},\n"
                         " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.9, 0], "
                         "\"intensity\": [3, 3, 3]}],\n"
                         " \"geometry\": [\n" ST_TEST_CORNELL_WALLS
                         "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}}],\n"
                         " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0, 0, 0]},\n"
                         " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": "
                         "64}},\n"
                         "  {\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 64}},\n"
                         "  {\"name\": \"toth\", \"params\": {\"samples\": 8}}]}\n");
    snprintf(out, sizeof out, "%s/cornell.exr", ST_TEST_SCRATCH);
    for (int box = 0; box < 2; box++) {
        int rc;
        cJSON *j =
            st_test_stats_json(scene, out, box ? "--frames 8 --filter box" : "--frames 8", &rc);
        CHECK(rc == 0 && j, "stats render rc %d", rc);
        if (!j) continue;
        int sk = -1;
        CHECK(pass_runs(j, "shadow_map", "cube", &sk) == 1 && sk == 7,
              "shadow_map cube: %d runs, %d skips", pass_runs(j, "shadow_map", "cube", NULL), sk);
        CHECK(pass_runs(j, "atlas_gi", "gbuffer", NULL) == 1, "atlas_gi gbuffer: %d runs",
              pass_runs(j, "atlas_gi", "gbuffer", NULL));
        CHECK(pass_runs(j, "atlas_gi", "gather", NULL) == 1, "atlas_gi transfer: %d runs",
              pass_runs(j, "atlas_gi", "gather", NULL));
        // What depends on the camera runs every frame; the accumulation only for box.
        CHECK(pass_runs(j, "world", "regular", NULL) == 8, "regular: %d runs",
              pass_runs(j, "world", "regular", NULL));
        CHECK(pass_runs(j, "toth", "march", NULL) == 8, "toth march: %d runs",
              pass_runs(j, "toth", "march", NULL));
        CHECK(pass_runs(j, "world", "accumulate", NULL) == (box ? 8 : -1),
              "accumulate: %d runs (%s)", pass_runs(j, "world", "accumulate", NULL),
              box ? "box" : "point");
        cJSON_Delete(j);
    }
    // A sun's cascades follow the camera's view slices; a sub-pixel shift
    // leaves them inside their fit, so they are not redrawn either.
    snprintf(scene, sizeof scene, "%s/sun.json", ST_TEST_SCRATCH);
    st_test_write(scene, "{\"image\": {\"width\": 48, \"height\": 32},\n"
                         " \"camera\": {\"position\": [0, 3, 5], \"target\": [0, 0, 0], "
                         "\"up\": [0, 1, 0], \"fov_y\": 50},\n"
                         " \"lights\": [{\"type\": \"directional\", \"direction\": [-0.3, -1, "
                         "-0.2], \"irradiance\": [2, 2, 2]}],\n"
                         " \"geometry\": [{\"quad\": {\"corner\": [-4, 0, 4], \"u\": [8, 0, 0], "
                         "\"v\": [0, 0, -8]}},\n"
                         "  {\"box\": {\"min\": [-0.5, 0, -0.5], \"max\": [0.5, 1, 0.5]}}],\n"
                         " \"modules\": [{\"name\": \"shadow_map\"}]}\n");
    int rc;
    cJSON *j = st_test_stats_json(scene, out, "--frames 8 --filter box", &rc);
    CHECK(rc == 0 && j, "sun stats render rc %d", rc);
    if (j) {
        CHECK(pass_runs(j, "shadow_map", "cascades", NULL) == 1, "sun cascades: %d runs",
              pass_runs(j, "shadow_map", "cascades", NULL));
        CHECK(pass_runs(j, "world", "accumulate", NULL) == 8, "sun accumulate: %d runs",
              pass_runs(j, "world", "accumulate", NULL));
        cJSON_Delete(j);
    }
}

// (d) The header records the filter; compare warns when A and B differ, and
// counts a file without the attribute as point.
static void check_header(void) {
    char a[512], b[512], old[512], cmd[2048], buf[8192];
    snprintf(a, sizeof a, "%s/box.exr", ST_TEST_SCRATCH);        // from check_edges
    snprintf(b, sizeof b, "%s/point_flag.exr", ST_TEST_SCRATCH); // likewise
    snprintf(old, sizeof old, "%s/old.exr", ST_TEST_SCRATCH);
    st_exr_meta ma = {0}, mb = {0}, mo = {0};
    st_err err = {0};
    CHECK(st_image_read_exr_meta(a, &ma, &err) && !strcmp(ma.filter, "box"), "%s: filter '%s'", a,
          ma.filter);
    CHECK(st_image_read_exr_meta(b, &mb, &err) && !strcmp(mb.filter, "point"), "%s: filter '%s'", b,
          mb.filter);
    st_image img = {0};
    CHECK(st_test_read(b, &img) && st_image_write_exr(old, &img, &err), "write %s", old);
    CHECK(st_image_read_exr_meta(old, &mo, &err) && !mo.filter[0], "old file has filter '%s'",
          mo.filter);
    st_image_free(&img);
    struct {
        const char *x, *y;
        bool warn, absent;
    } cases[] = {
        {a, b, true, false}, {a, a, false, false}, {old, b, false, false}, {a, old, true, true}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        snprintf(cmd, sizeof cmd, "%s compare %s %s", ST_TEST_STRAHL, cases[k].x, cases[k].y);
        int rc = st_test_capture(buf, sizeof buf, cmd);
        CHECK(rc == 0, "compare rc %d", rc);
        bool warned = strstr(buf, "warning") && strstr(buf, "pixel filter");
        CHECK(warned == cases[k].warn, "case %zu: warned %d", k, warned);
        if (cases[k].absent)
            CHECK(strstr(buf, "no strahl.filter attribute") != NULL, "case %zu: absent not named",
                  k);
    }
    // Bad values are input errors naming them.
    char scene[512];
    snprintf(scene, sizeof scene, "%s/bad_filter.json", ST_TEST_SCRATCH);
    st_test_write(scene, "{\"image\": {\"width\": 8, \"height\": 8, \"filter\": \"gauss\"}, "
                         "\"geometry\": [], \"modules\": []}\n");
    snprintf(cmd, sizeof cmd, "%s render %s -o %s/bad.exr", ST_TEST_STRAHL, scene, ST_TEST_SCRATCH);
    int rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 2 && strstr(buf, "image.filter") && strstr(buf, "gauss"), "bad key: rc %d", rc);
    snprintf(cmd, sizeof cmd, "%s render %s -o %s/bad.exr --filter gauss", ST_TEST_STRAHL, a,
             ST_TEST_SCRATCH);
    rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 2 && strstr(buf, "--filter gauss"), "bad flag: rc %d", rc);
}

int main(void) {
    check_sequence();
    check_edges();
    check_caching();
    check_header();
    return st_test_summary("test_filter");
}
