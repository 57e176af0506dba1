// Shadowed single scattering: a closed room whose ceiling (a 0.1 m slab) has
// a square opening, the light above it. The light reaches a point in the
// room exactly when the segment to the light passes the opening at both faces
// of the slab: eight half-spaces, so the lit part of a view ray is one
// interval (clipped exactly, Cyrus-Beck) and the CPU integral over it is the
// oracle. A view ray entirely in shadow must get no in-scattered light; the
// shaft must appear where, and as bright as, the CPU integral says.
#include "toth_test.h"

enum { N = 64 };
static const double LIGHT[3] = {0.15, 3.2, 0.1}, INTENSITY = 20, HOLE = 0.3, Y0 = 2.0, Y1 = 2.1;
static const double SS = 0.3, SA = 0.05;
static const double CAM[3] = {-3.0, 1.0, 3.0}, TGT[3] = {0, 0.2, 0}, UP[3] = {0, 1, 0}, FOV = 45;

static int shadow_res = 1024;

// toth parameters that leave visibility to the map's own lookups.
#define TOTH_MAP_ONLY                                                                              \
    "\"exact_edges\": false, \"probes\": 0" // shadow_map.resolution of the scene written next

static void write_scene(const char *path, const char *toth_params) {
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, 0]}, "
             "\"albedo\": [0, 0, 0]},\n"
             "  {\"quad\": {\"corner\": [-4, 0, -4], \"u\": [8, 0, 0], \"v\": [0, 2, 0]}, "
             "\"albedo\": [0, 0, 0]},\n"
             "  {\"quad\": {\"corner\": [-4, 0, 4], \"u\": [0, 2, 0], \"v\": [8, 0, 0]}, "
             "\"albedo\": [0, 0, 0]},\n"
             "  {\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 2, 0], \"v\": [0, 0, 8]}, "
             "\"albedo\": [0, 0, 0]},\n"
             "  {\"quad\": {\"corner\": [4, 0, -4], \"u\": [0, 0, 8], \"v\": [0, 2, 0]}, "
             "\"albedo\": [0, 0, 0]},\n"
             "  {\"box\": {\"min\": [-4, %g, -4], \"max\": [4, %g, %g]}, \"albedo\": [0, 0, 0]},\n"
             "  {\"box\": {\"min\": [-4, %g, %g], \"max\": [4, %g, 4]}, \"albedo\": [0, 0, 0]},\n"
             "  {\"box\": {\"min\": [-4, %g, %g], \"max\": [%g, %g, %g]}, \"albedo\": [0, 0, 0]},\n"
             "  {\"box\": {\"min\": [%g, %g, %g], \"max\": [4, %g, %g]}, \"albedo\": [0, 0, 0]}],\n"
             " \"medium\": {\"sigma_s\": [%g, %g, %g], \"sigma_a\": [%g, %g, %g]},\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": %d}},"
             " {\"name\": \"toth\", \"params\": {%s}}]}\n",
             N, N, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, LIGHT[0], LIGHT[1],
             LIGHT[2], INTENSITY, INTENSITY, INTENSITY, Y0, Y1, -HOLE, Y0, HOLE, Y1, Y0, -HOLE,
             -HOLE, Y1, HOLE, HOLE, Y0, -HOLE, Y1, HOLE, SS, SS, SS, SA, SA, SA, shadow_res,
             toth_params);
    st_test_write(path, json);
}

// Where the ray o + t d, t in [0, s], leaves the room (floor, walls, ceiling underside).
static double room_exit(const double o[3], const double d[3]) {
    const double mn[3] = {-4, 0, -4}, mx[3] = {4, Y0, 4};
    return toth_box_exit(o, d, mn, mx);
}

static double cpu_inscatter(const st_test_cam *c, int i, int j, double *lit_len) {
    double d[3], t0, t1;
    st_test_ray(c, i, j, d);
    double s = room_exit(c->pos, d);
    *lit_len = 0;
    if (!toth_lit_interval(LIGHT, Y0, Y1, c->pos, d, s, HOLE, &t0, &t1)) return 0;
    *lit_len = t1 - t0;
    st_inscatter_problem p;
    for (int k = 0; k < 3; k++)
        p.origin[k] = c->pos[k], p.dir[k] = d[k], p.light[k] = LIGHT[k];
    p.length = s, p.intensity = INTENSITY, p.sigma_s = SS, p.sigma_t = SS + SA,
    p.phase = ST_PHASE_ISOTROPIC, p.g = 0;
    return st_integrate(toth_integrand_cb, &p, t0, t1, 1e-300, 1e-10);
}

// Do the pixel's ray and the rays `margin` pixels around it all miss the
// light (lit = 0; for an opening 2 cm wider on every side, clear of
// shadow-map edge effects) or all catch it (lit = 1; opening 2 cm narrower)?
// At reduced march resolution a pixel's value comes from march pixels up to
// a few pixels away, so the margin grows with the settings.
static int robust(const st_test_cam *c, int i, int j, double margin, int lit) {
    for (int k = 0; k < 9; k++) {
        double sx = (k % 3 - 1) * margin, sy = (k / 3 - 1) * margin;
        double x = (2.0 * (i + 0.5 + sx) / c->w - 1.0) * c->tan_half * c->aspect;
        double y = (1.0 - 2.0 * (j + 0.5 + sy) / c->h) * c->tan_half;
        double d[3], t0, t1;
        for (int q = 0; q < 3; q++)
            d[q] = c->f[q] + x * c->r[q] + y * c->u[q];
        st_v_norm(d);
        if (toth_lit_interval(LIGHT, Y0, Y1, c->pos, d, room_exit(c->pos, d),
                              HOLE + (lit ? -0.02 : 0.02), &t0, &t1) != lit)
            return 0;
    }
    return 1;
}

int main(void) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/shaft.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/shaft.exr", ST_TEST_SCRATCH);
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, N, N);
    static double ref[N][N], lit[N][N];
    double ref_max = 0, ref_sum = 0, cx = 0, cy = 0;
    int dark = 0, shaft = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            ref[j][i] = cpu_inscatter(&c, i, j, &lit[j][i]);
            ref_max = fmax(ref_max, ref[j][i]);
            ref_sum += ref[j][i];
            cx += i * ref[j][i], cy += j * ref[j][i];
        }
    cx /= ref_sum, cy /= ref_sum;

    // Settings, the margin of robust pixels, bounds on the mean relative error
    // in the shaft and on the centroid's offset (pixels). The defaults march
    // at half resolution (32 x 32 here) with 2 x 2 interleaving: their shaft
    // edges are soft by about two pixels.
    const struct {
        const char *params;
        double margin, mean_rel, centroid;
        int max_missing; // pixels whose whole lit stretch may fall between two lookups
        double total;    // relative tolerance of the total
    } settings[] = {
        {"\"sampling\": \"uniform\", \"samples\": 256, \"interleave\": 1, \"jitter\": false, "
         "\"resolution\": \"full\"",
         0.5, 0.025, 0.1, 0, 0.01},
        {"\"sampling\": \"uniform\", \"samples\": 256, \"interleave\": 1, \"jitter\": true, "
         "\"resolution\": \"full\"",
         0.5, 0.025, 0.1, 0, 0.01},
        {"\"sampling\": \"uniform\", \"samples\": 256, \"interleave\": 2, \"jitter\": true, "
         "\"resolution\": \"full\"",
         1.5, 0.035, 0.1, 0, 0.01},
        {"", 4.0, 0.07, 0.25, 0, 0.01},
        // The bisection: 16 equi-angular steps with 6 halvings per boundary
        // place each of the ray's two shadow boundaries to 1/2048 of the
        // angle, as a 2048-step march would; without halvings (trapezoid of
        // the step's two lookups) the boundaries are only known to a step.
        // Rays that only graze the shaft, lit over less than one step
        // between two lookups, miss it (as a 16-step march would).
        // (The map's own lookups: exact_edges and probes off.)
        {"\"samples\": 16, \"bisect\": 6, \"jitter\": false, \"resolution\": "
         "\"full\", " TOTH_MAP_ONLY,
         0.5, 0.025, 0.1, 10, 0.02},
        {"\"samples\": 16, \"bisect\": 0, \"jitter\": false, \"resolution\": "
         "\"full\", " TOTH_MAP_ONLY,
         0.5, 1.0, 1.0, 10, 0.02},
        // A 64-texel cube (shadow_res below): the bisection places the
        // boundaries where the coarse map has them (mean 0.064); exact_edges
        // takes an exact ray (shadow_map.refine's BVH) wherever the map
        // cannot decide a lookup (refine's rule) and bisects with rays: 0.0002
        // (0.027 when only boundaries the map bracketed were traced, below
        // the 1024-texel map's own 0.023), also for grazing rays lit only
        // between two step ends (see the check after the loop).
        {"\"samples\": 16, \"bisect\": 6, \"jitter\": false, \"resolution\": "
         "\"full\", " TOTH_MAP_ONLY,
         0.5, 0.2, 0.5, 10, 0.05},
        {"\"samples\": 16, \"bisect\": 6, \"jitter\": false, \"resolution\": \"full\", "
         "\"exact_edges\": true, \"probes\": 0",
         0.5, 0.005, 0.1, 16, 0.02},
        // exact_edges with 3 probes per step (the defaults' visibility): the
        // lookups the coarse map cannot decide take exact rays, and the grazing
        // rays lit only between two step ends are found by the probes.
        {"\"samples\": 16, \"bisect\": 6, \"jitter\": false, \"resolution\": \"full\", "
         "\"exact_edges\": true, \"probes\": 3",
         0.5, 0.01, 0.1, 0, 0.01},
        // Half resolution (a 32 x 32 march: min_rows off), with and without
        // refine_kink: blocks whose fraction bends are marched at full
        // resolution instead of interpolated (the defaults before issue 35).
        {"\"min_rows\": 0, \"resolution\": \"half\", \"refine_kink\": 0.01", 4.0, 0.07, 0.25, 0,
         0.01},
        {"\"min_rows\": 0, \"resolution\": \"half\", \"refine_kink\": 0", 4.0, 0.07, 0.25, 0, 0.01},
    };
    enum { SETTINGS = sizeof settings / sizeof settings[0] };
    double mean_rel_of[SETTINGS] = {0};
    double worst_of[SETTINGS] = {0};
    for (int m = 0; m < SETTINGS; m++) {
        shadow_res = m >= 6 && m <= 8 ? 64 : 1024;
        write_scene(scene, settings[m].params);
        st_image img = {0};
        if (!toth_render(scene, out, NULL, &img)) continue;
        double worst_dark = 0, sum = 0, gx = 0, gy = 0, worst_rel = 0, mean_rel = 0;
        int missing = 0, lit_robust = 0;
        dark = shaft = 0;
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                double v = st_image_px(&img, i, j)[0];
                sum += v, gx += i * v, gy += j * v;
                if (robust(&c, i, j, settings[m].margin, 0)) {
                    dark++;
                    worst_dark = fmax(worst_dark, v);
                } else if (ref[j][i] > 0.05 * ref_max) {
                    // Clearly in the shaft: as bright as the CPU integral.
                    shaft++;
                    double rel = fabs(v - ref[j][i]) / ref[j][i];
                    worst_rel = fmax(worst_rel, rel);
                    mean_rel += rel;
                    if (robust(&c, i, j, settings[m].margin, 1))
                        lit_robust++, missing += v < 0.5 * ref[j][i];
                }
            }
        mean_rel /= shaft > 0 ? shaft : 1;
        gx /= sum, gy /= sum;
        const char *name = settings[m].params[0] ? settings[m].params : "defaults";
        printf("  %s: dark %d (max %.3g), shaft %d (mean rel %.4f, worst %.4f, missing %d), total "
               "%.5f "
               "vs %.5f, centroid (%.2f, %.2f) vs (%.2f, %.2f)\n",
               name, dark, worst_dark, shaft, mean_rel, worst_rel, missing, sum, ref_sum, gx, gy,
               cx, cy);
        CHECK(dark > 1000 && shaft > 150 && lit_robust > 100,
              "the view holds dark rays (%d) and the shaft (%d, %d)", dark, shaft, lit_robust);
        CHECK(worst_dark == 0, "%s: rays entirely in shadow get no light, max %.3g", name,
              worst_dark);
        CHECK(missing <= settings[m].max_missing, "%s: %d shaft pixels missing", name, missing);
        CHECK(fabs(sum / ref_sum - 1) < settings[m].total, "%s: total in-scatter %.5f vs CPU %.5f",
              name, sum, ref_sum);
        CHECK(fabs(gx - cx) < settings[m].centroid && fabs(gy - cy) < settings[m].centroid,
              "%s: shaft centroid (%.2f, %.2f) vs (%.2f, %.2f)", name, gx, gy, cx, cy);
        CHECK(mean_rel < settings[m].mean_rel, "%s: mean rel. error in the shaft %.4f", name,
              mean_rel);
        mean_rel_of[m] = mean_rel;
        worst_of[m] = worst_rel;
        st_image_free(&img);
    }
    CHECK(mean_rel_of[5] > 4 * mean_rel_of[4],
          "bisection: shaft error %.4f with 6 halvings, %.4f without", mean_rel_of[4],
          mean_rel_of[5]);
    CHECK(mean_rel_of[7] < 0.5 * mean_rel_of[6],
          "exact_edges on a 64-texel cube: shaft error %.4f, %.4f from the map alone",
          mean_rel_of[7], mean_rel_of[6]);
    // A grazing ray lit only between two step ends that both lie in shadow
    // near the shaft's edge: exact_edges walks the shadows from the first end
    // (each blocking triangle's shadow ends in closed form) and finds the lit
    // stretch with or without probes (worst 0.0007, mean 0.0002; when only the
    // step's midpoint was traced it stayed dark without probes, worst 1.0).
    CHECK(worst_of[7] < 0.01 && worst_of[8] < 0.01 && mean_rel_of[7] < 0.001 &&
              mean_rel_of[8] < 0.001,
          "exact_edges on a 64-texel cube: shaft error %.4f (worst %.4f) with probes, %.4f "
          "(worst %.4f) without",
          mean_rel_of[8], worst_of[8], mean_rel_of[7], worst_of[7]);
    // refine_kink at half resolution: 0.0008 against 0.0043 (worst pixel 0.037
    // against 0.18).
    CHECK(mean_rel_of[9] < 0.5 * mean_rel_of[10],
          "refine_kink at half resolution: shaft error %.4f, %.4f without", mean_rel_of[9],
          mean_rel_of[10]);
    return st_test_summary("toth_shadow");
}
