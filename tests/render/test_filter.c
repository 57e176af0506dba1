// The pixel filter of stills (docs/physics.md, docs/architecture.md "Pixel
// filter"): the jitter sequence, box against point on an emitter whose
// slanted edges cross pixels (the box value is the pixel's covered fraction),
// the frame graph's caching under jitter (--stats=json run counts), the EXR
// header's strahl.filter and compare's warning on a mismatch.
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"
#include <cjson/cJSON.h>

// (b) The sequence: k = 0 is the centre, every offset inside the pixel. Two
// interleaved halves (the convergence test's): the even frames' first
// 2^a 3^b offsets put one point in each cell of the 2^a x 3^b grid (shifted
// by half a pixel with the points), the odd frames' first 3^a 2^b one in
// each cell of a 3^a x 2^b grid under their own fixed shift; the mean offset
// of both within half a cell of 0, and the halves not one another shifted.
static const double ODD_SHIFT[2] = {0.7548776662466927, 0.5698402909980532};

static void check_half(int odd, int nx, int ny) {
    int n = nx * ny, cells[432] = {0};
    double mx = 0, my = 0;
    float o[2];
    for (int j = 0; j < n; j++) {
        st_jitter_offset((uint32_t)(2 * j + odd), o);
        CHECK(o[0] >= -0.5f && o[0] < 0.5f && o[1] >= -0.5f && o[1] < 0.5f,
              "offset %d (%g, %g) outside the pixel", 2 * j + odd, o[0], o[1]);
        mx += o[0], my += o[1];
        // Undo the shifts: h = (offset - odd shift) mod 1 is the Halton point.
        double h[2];
        for (int a = 0; a < 2; a++) {
            h[a] = o[a] - (odd ? ODD_SHIFT[a] : 0.0);
            h[a] -= floor(h[a]);
        }
        // Halton points lie on cell boundaries (left-closed): 1e-4 absorbs
        // float rounding (and a point a hair below 1 belongs to cell 0).
        int cx = (int)(h[0] * nx + 1e-4) % nx, cy = (int)(h[1] * ny + 1e-4) % ny;
        cells[cy * nx + cx]++;
    }
    int empty = 0, crowded = 0;
    for (int c = 0; c < n; c++)
        empty += cells[c] == 0, crowded += cells[c] > 1;
    CHECK(empty == 0 && crowded == 0, "first %d %s offsets on a %dx%d grid: %d empty, %d crowded",
          n, odd ? "odd" : "even", nx, ny, empty, crowded);
    // One point per cell (of a shifted grid) keeps the mean within a cell of
    // 0, half a cell without a shift.
    double lim = odd ? 1.0 : 0.5;
    CHECK(fabs(mx / n) <= lim / nx && fabs(my / n) <= lim / ny, "mean %s offset of %d: (%g, %g)",
          odd ? "odd" : "even", n, mx / n, my / n);
}

static void check_sequence(void) {
    float o[2], e[2];
    st_jitter_offset(0, o);
    CHECK(o[0] == 0 && o[1] == 0, "offset 0 is (%g, %g), not the centre", o[0], o[1]);
    static const int grids[][2] = {{2, 3}, {4, 9}, {8, 27}, {16, 3}};
    for (size_t g = 0; g < sizeof grids / sizeof grids[0]; g++) {
        check_half(0, grids[g][0], grids[g][1]);
        check_half(1, grids[g][1], grids[g][0]);
    }
    // The odd frames are not the even ones under one shift (whose errors
    // would correlate and fool the test): their differences vary.
    double d0[2] = {0, 0}, spread = 0;
    for (int j = 0; j < 64; j++) {
        st_jitter_offset((uint32_t)(2 * j), e);
        st_jitter_offset((uint32_t)(2 * j + 1), o);
        for (int a = 0; a < 2; a++) {
            double d = o[a] - e[a];
            if (j == 0) d0[a] = d;
            d -= d0[a];
            spread = fmax(spread, fabs(d - floor(d + 0.5)));
        }
    }
    CHECK(spread > 0.25, "odd offsets are the even ones shifted (spread %g)", spread);
}

// The emitter: a parallelogram of radiance 1 seen head-on by a pinhole
// camera, so its image is a parallelogram in pixel coordinates: corner
// C + s U + t V (s, t in [0, 1]), pixels (x right, y down the image).
#define W 32
#define H 32
typedef struct {
    double c[2], u[2], v[2];
} para;
static const para BIG = {{7.3, 24.6}, {16.45, 0.0}, {5.7, -15.35}};
static const double CAM_D = 4.0, FOV = 40.0;
static const para *E_ = &BIG; // the emitter inside() tests

static bool inside(double x, double y) {
    const double *C = E_->c, *U = E_->u, *V = E_->v;
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
        // Distance in pixels to the nearest edge crossing, roughly: probe
        // around, farther than the rasteriser's snapping of vertices to
        // 1/256 px moves an edge.
        for (int d = 0; d < 4; d++) {
            double e = 1e-2, dx = d == 0 ? e : d == 1 ? -e : 0, dy = d == 2 ? e : d == 3 ? -e : 0;
            if (inside(x + dx, y + dy) != inside(x, y)) *margin = 0;
        }
    }
    return (double)in / n;
}

static void write_emitter_scene(const char *path, const char *filter) {
    const double *C = E_->c, *U = E_->u, *V = E_->v;
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
    CHECK_REL(area, fabs(BIG.u[0] * BIG.v[1] - BIG.u[1] * BIG.v[0]), 1e-3, 0);

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

// Exact covered fraction of pixel (i, j) by the emitter: the parallelogram
// clipped to the pixel's square (Sutherland-Hodgman), its area.
static double exact_coverage(int i, int j) {
    const para *e = E_;
    double poly[16][2], tmp[16][2];
    int n = 4;
    for (int k = 0; k < 4; k++) {
        poly[k][0] = e->c[0] + (k == 1 || k == 2) * e->u[0] + (k >= 2) * e->v[0];
        poly[k][1] = e->c[1] + (k == 1 || k == 2) * e->u[1] + (k >= 2) * e->v[1];
    }
    // The pixel's four half-planes: x >= i, x <= i + 1, y >= j, y <= j + 1.
    for (int side = 0; side < 4; side++) {
        int a = side / 2, m = 0;
        double lim = (a ? j : i) + side % 2, sg = side % 2 ? -1 : 1;
        for (int k = 0; k < n; k++) {
            const double *p = poly[k], *q = poly[(k + 1) % n];
            double dp = sg * (p[a] - lim), dq = sg * (q[a] - lim);
            if (dp >= 0) tmp[m][0] = p[0], tmp[m][1] = p[1], m++;
            if ((dp < 0) != (dq < 0)) {
                double t = dp / (dp - dq);
                tmp[m][0] = p[0] + t * (q[0] - p[0]), tmp[m][1] = p[1] + t * (q[1] - p[1]), m++;
            }
        }
        memcpy(poly, tmp, sizeof tmp);
        n = m;
    }
    double area = 0;
    for (int k = 0; k < n; k++)
        area += poly[k][0] * poly[(k + 1) % n][1] - poly[(k + 1) % n][0] * poly[k][1];
    return fabs(area) / 2;
}

// NRMSE of an image of the current emitter against its covered fractions.
static double image_nrmse(const st_image *img) {
    double sq = 0, sum = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double want = exact_coverage(i, j);
            for (int c = 0; c < 3; c++)
                sq += pow(st_image_px(img, i, j)[c] - want, 2), sum += want;
        }
    return sqrt(sq / (3.0 * W * H)) / (sum / (3.0 * W * H));
}

// One box still of the current emitter: its NRMSE against the exact covered
// fractions, and what render reports (frames, converged, estimated error).
static double still_nrmse(const char *scene, const char *extra, long *frames, double *est,
                          bool *converged) {
    char out[512], cmd[1024], buf[4096];
    snprintf(out, sizeof out, "%s/stop.exr", ST_TEST_SCRATCH);
    unlink(out);
    snprintf(cmd, sizeof cmd, "%s render %s -o %s %s", ST_TEST_STRAHL, scene, out, extra);
    int rc = st_test_capture(buf, sizeof buf, cmd);
    char state[32] = "";
    *frames = 0, *est = -1;
    const char *line = strstr(buf, "strahl render: ");
    // "converged after N frame(s), ..." only when it did; "N frame(s) (--frames N), ..."
    bool parsed = line && sscanf(line,
                                 "strahl render: %31s after %ld frame(s), %*f ms, estimated "
                                 "remaining relative error %lf",
                                 state, frames, est) == 3;
    if (line && !parsed) {
        snprintf(state, sizeof state, "frames");
        parsed = sscanf(line,
                        "strahl render: %ld frame(s) (--frames %*d), %*f ms, estimated remaining "
                        "relative error %lf",
                        frames, est) == 2;
    }
    CHECK(rc == 0 && parsed, "%s: rc %d, output %s", cmd, rc, buf);
    *converged = !strcmp(state, "converged");
    st_image img = {0};
    if (!st_test_read(out, &img)) return INFINITY;
    double e = image_nrmse(&img);
    st_image_free(&img);
    return e;
}

// The same through the API, with st_world_opts' tolerance and cap: frames
// until the world says it is done (at most 2000), and the image's NRMSE.
static double world_nrmse(const char *scene, double tol, int cap, uint32_t *frames, bool *done) {
    st_scene sc = {0};
    st_err err = {0};
    st_world *w = NULL;
    st_image img = {0};
    double e = INFINITY;
    *frames = 0, *done = false;
    bool ok = st_scene_load(scene, &sc, &err);
    st_world_opts o = {.filter = ST_FILTER_BOX, .filter_tolerance = tol, .filter_max_frames = cap};
    ok = ok && (w = st_world_create(&sc, &o, &err));
    for (int f = 0; ok && !*done && f < 2000; f++) {
        ok = st_world_frame(w, &err);
        *frames = st_world_accumulated(w, done);
    }
    if (ok && st_world_read(w, &img, &err)) e = image_nrmse(&img);
    CHECK(ok && img.data, "%s (tolerance %g, cap %d): %s", scene, tol, cap, err.msg);
    st_image_free(&img);
    st_world_destroy(w);
    st_scene_free(&sc);
    return e;
}

// (e) The stopping rule bounds the image's NRMSE. A bright emitter on black
// covering a tenth of the image: its edge pixels carry all the error, the
// case where the old per-pixel relative rule stopped at its cap of 64 frames
// with an NRMSE several times its tolerance. Its estimate tracks the true NRMSE, accumulation
// continues while that is above the tolerance and stops once it is within; an image that every
// offset sees alike (an emitter filling the view) stops at the minimum.
static void check_stopping(void) {
    static const para part = {{9.3, 22.6}, {11.45, 1.7}, {3.7, -10.35}};
    char scene[512];
    snprintf(scene, sizeof scene, "%s/small.json", ST_TEST_SCRATCH);
    E_ = &part;
    write_emitter_scene(scene, NULL);
    long n;
    double est;
    bool conv;
    // At a fixed count the estimate is within a factor 2.5 of the truth.
    static const int counts[] = {16, 64, 256};
    double at64 = 0;
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
        char extra[32];
        snprintf(extra, sizeof extra, "--frames %d", counts[k]);
        double e = still_nrmse(scene, extra, &n, &est, &conv);
        printf("emitter, %d frames: NRMSE %.5f, estimate %.5f\n", counts[k], e, est);
        CHECK(n == counts[k] && est > e / 2.5 && est < e * 2.5,
              "%d frames: %ld ran, estimate %g against NRMSE %g", counts[k], n, est, e);
        if (counts[k] == 64) at64 = e;
    }
    // 64 frames leave it above the tolerance; the default runs on past them
    // and stops within it (the estimate's noise allowed for: 2x).
    double e = still_nrmse(scene, "", &n, &est, &conv);
    printf("emitter, to convergence: %ld frames, NRMSE %.5f, estimate %.5f\n", n, e, est);
    CHECK(at64 > ST_FILTER_TOLERANCE, "64 frames already within the tolerance: %g", at64);
    CHECK(conv && n > 64 && n < ST_FILTER_MAX_FRAMES && est <= ST_FILTER_TOLERANCE,
          "converged %d after %ld frames, estimate %g", conv, n, est);
    CHECK(e <= 2 * ST_FILTER_TOLERANCE, "converged still's NRMSE %g", e);
    // st_world_opts: a tolerance of 4x stops earlier and within it (the API
    // counts as render does); a cap of 40 stops there, short of converged.
    uint32_t m;
    bool done;
    e = world_nrmse(scene, 4 * ST_FILTER_TOLERANCE, 0, &m, &done);
    printf("emitter, tolerance %g: %u frames, NRMSE %.5f\n", 4 * ST_FILTER_TOLERANCE, m, e);
    CHECK(done && m >= ST_FILTER_MIN_FRAMES && m < n && e <= 2 * 4 * ST_FILTER_TOLERANCE,
          "tolerance 4x: done %d after %u frames (default %ld), NRMSE %g", done, m, n, e);
    e = world_nrmse(scene, 0, 40, &m, &done);
    CHECK(done && m == 40 && e > ST_FILTER_TOLERANCE, "cap 40: done %d after %u frames, NRMSE %g",
          done, m, e);
    // Every offset alike: the halves agree from the start.
    static const para full = {{-4, 36}, {40, 0}, {0, -40}};
    snprintf(scene, sizeof scene, "%s/full.json", ST_TEST_SCRATCH);
    E_ = &full;
    write_emitter_scene(scene, NULL);
    e = still_nrmse(scene, "", &n, &est, &conv);
    CHECK(conv && n == ST_FILTER_MIN_FRAMES && est == 0 && e < 1e-6,
          "uniform image: converged %d after %ld frames, estimate %g, NRMSE %g", conv, n, est, e);
    E_ = &BIG;
}

// (f) The error map (--error-map): its rms over the image's mean is the
// estimate render reports; it is exactly 0 where the pixel and its
// neighbours are wholly inside or outside the emitter (every offset sees the
// same), and it is not 0 on the edges. A point still or one frame is refused
// before anything is written.
static void check_error_map(void) {
    static const para part = {{9.3, 22.6}, {11.45, 1.7}, {3.7, -10.35}};
    char scene[512], out[512], map[512], extra[1100];
    snprintf(scene, sizeof scene, "%s/small.json", ST_TEST_SCRATCH);
    snprintf(map, sizeof map, "%s/error_map.exr", ST_TEST_SCRATCH);
    E_ = &part;
    write_emitter_scene(scene, NULL);
    unlink(map);
    snprintf(extra, sizeof extra, "--frames 64 --error-map %s", map);
    long n;
    double est;
    bool conv;
    still_nrmse(scene, extra, &n, &est, &conv);
    snprintf(out, sizeof out, "%s/stop.exr", ST_TEST_SCRATCH);
    st_image img = {0}, m = {0};
    CHECK(st_test_read(out, &img) && st_test_read(map, &m), "read %s and %s", out, map);
    double sq = 0, sum = 0;
    int flat_nonzero = 0, edge_nonzero = 0;
    for (int j = 0; img.data && m.data && j < H; j++)
        for (int i = 0; i < W; i++) {
            int lo = 0, hi = 0; // neighbours wholly outside / inside
            for (int b = -1; b <= 1; b++)
                for (int a = -1; a <= 1; a++) {
                    int x = i + a, y = j + b;
                    double c = x < 0 || y < 0 || x >= W || y >= H ? 0 : exact_coverage(x, y);
                    lo += c == 0, hi += c == 1;
                }
            double e = st_image_px(&m, i, j)[0];
            flat_nonzero += (lo == 9 || hi == 9) && e != 0;
            edge_nonzero += lo < 9 && hi < 9 && e > 0;
            for (int c = 0; c < 3; c++)
                sq += pow(st_image_px(&m, i, j)[c], 2), sum += st_image_px(&img, i, j)[c];
        }
    double rms_over_mean = sqrt(sq / (3.0 * W * H)) / (sum / (3.0 * W * H));
    printf("error map, 64 frames: rms / mean %.5f, reported %.5f, %d edge pixels non-zero\n",
           rms_over_mean, est, edge_nonzero);
    CHECK_REL(rms_over_mean, est, 2e-3, 0);
    CHECK(flat_nonzero == 0 && edge_nonzero > 20, "%d flat pixels non-zero, %d edge pixels",
          flat_nonzero, edge_nonzero);
    st_image_free(&img);
    st_image_free(&m);
    // Refused, exit 2, nothing written.
    unlink(map), unlink(out);
    snprintf(extra, sizeof extra, "--filter point --error-map %s", map);
    CHECK(render_as_is(scene, out, extra) == 2 && access(out, F_OK) != 0 && access(map, F_OK) != 0,
          "--error-map with the point filter is not refused before rendering");
    snprintf(extra, sizeof extra, "--frames 1 --error-map %s", map);
    CHECK(render_as_is(scene, out, extra) == 2 && access(out, F_OK) != 0 && access(map, F_OK) != 0,
          "--error-map of one frame is not refused before rendering");
    E_ = &BIG;
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
// renders the shadow cube, the atlas G-buffer, the transfer and toth's march
// once.
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
        // toth (reuse=on) marches the first frame of a box still only: its
        // jittered frames read the kept visible fraction (test_toth_passes).
        CHECK(pass_runs(j, "toth", "march", NULL) == (box ? 1 : 8), "toth march: %d runs (%s)",
              pass_runs(j, "toth", "march", NULL), box ? "box" : "point");
        CHECK(pass_runs(j, "toth", "compose", NULL) == 8, "toth compose: %d runs",
              pass_runs(j, "toth", "compose", NULL));
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
    st_context *ctx = st_test_context();
    check_stopping();
    check_error_map();
    st_context_destroy(ctx);
    check_caching();
    check_header();
    return st_test_summary("test_filter");
}
