// Interleaved sampling and reduced march resolution against the full march:
// a room with a floating box in front of the back wall (a depth edge and a
// volumetric shadow). The gather must leave no M x M block pattern, and
// neither the gather nor the upsampling may mix the box's in-scattered light
// with the wall's behind it: with the geometry test switched off
// (edge_tolerance 10) the error at the box's silhouette grows several-fold.
// Both samplings run every case (equi-angular against its own full march);
// the geometry-blind check is the uniform march's, where the in-scattered
// light itself is upsampled (equi-angular upsamples only the visible fraction
// and bleeds far less).
#include "toth_test.h"

enum { N = 96 };
static const double LIGHT[3] = {0.9, 2.6, -1.0}, I[3] = {10, 10, 10};
static char scene[512], out[512];
static const char *sampling = "uniform";

static void write_scene(const char *params) {
    char json[4096], toth_params[512];
    snprintf(toth_params, sizeof toth_params, "\"sampling\": \"%s\", %s", sampling, params);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],\n"
             " \"geometry\": [{\"box\": {\"min\": [-2, 0, -2], \"max\": [2, 3, 2]}, \"inward\": "
             "true, \"albedo\": [0, 0, 0]},\n"
             "   {\"box\": {\"min\": [-0.4, 0.6, -0.3], \"max\": [0.4, 1.6, 0.1]}, \"albedo\": [0, "
             "0, 0]}],\n"
             " \"medium\": {\"sigma_s\": [0.3, 0.3, 0.3], \"sigma_a\": [0.05, 0.05, 0.05]},\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}},"
             " {\"name\": \"toth\", \"params\": {%s}}]}\n",
             N, N, ROOM_CAM[0], ROOM_CAM[1], ROOM_CAM[2], ROOM_TGT[0], ROOM_TGT[1], ROOM_TGT[2],
             ROOM_FOV, LIGHT[0], LIGHT[1], LIGHT[2], I[0], I[1], I[2], toth_params);
    st_test_write(scene, json);
}

// Pixels whose 5x5 neighbourhood sees both the box and the wall behind it.
static int edge[N][N];
static void find_edges(void) {
    st_test_cam c = st_test_camera(ROOM_CAM, ROOM_TGT, ROOM_UP, ROOM_FOV, N, N);
    const double bmin[3] = {-0.4, 0.6, -0.3}, bmax[3] = {0.4, 1.6, 0.1};
    static int box[N][N];
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            box[j][i] = st_test_ray_box(c.pos, d, bmin, bmax) >= 0;
        }
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            int any = 0, all = 1;
            for (int y = j - 2; y <= j + 2; y++)
                for (int x = i - 2; x <= i + 2; x++) {
                    if (x < 0 || y < 0 || x >= N || y >= N) continue;
                    any |= box[y][x];
                    all &= box[y][x];
                }
            edge[j][i] = any && !all;
        }
}

typedef struct {
    double mean, edge_mean, block_spread;
} cmp;

// Relative errors against the full march; block_spread: the range of the
// mean signed relative error over the M x M pixel classes (x mod M, y mod M)
// away from silhouettes and the border. Without the gather a class would be
// off by about -(1 - 1/M^2).
static cmp compare(const st_image *a, const st_image *ref, int M) {
    cmp r = {0, 0, 0};
    double cls[8][8] = {{0}};
    int ncls[8][8] = {{0}}, ne = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double want = st_image_px(ref, i, j)[0];
            double rel = fabs(st_image_px(a, i, j)[0] - want) / fmax(want, 1e-6);
            r.mean += rel / (N * N);
            if (edge[j][i]) r.edge_mean += rel, ne++;
            // Blocks would show in smooth regions; silhouettes and the image
            // border (one-sided windows) are measured above.
            if (edge[j][i] || i < 8 || j < 8 || i >= N - 8 || j >= N - 8) continue;
            cls[j % M][i % M] += (st_image_px(a, i, j)[0] - want) / fmax(want, 1e-6);
            ncls[j % M][i % M]++;
        }
    r.edge_mean /= ne;
    double lo = 1e9, hi = -1e9;
    for (int y = 0; y < M; y++)
        for (int x = 0; x < M; x++) {
            double m = cls[y][x] / ncls[y][x];
            lo = fmin(lo, m), hi = fmax(hi, m);
        }
    r.block_spread = hi - lo;
    return r;
}

static void run_cases(void) {
    st_image ref = {0};
    write_scene("\"samples\": 128, \"interleave\": 1, \"jitter\": false, \"resolution\": \"full\"");
    if (!toth_render(scene, out, NULL, &ref)) return;
    printf(" sampling=%s\n", sampling);
    const struct {
        const char *params;
        int M;
        double mean, edge, spread; // bounds
    } cases[] = {
        {"\"samples\": 128, \"interleave\": 2, \"jitter\": false, \"resolution\": \"full\"", 2,
         0.02, 0.05, 0.005},
        {"\"samples\": 128, \"interleave\": 4, \"jitter\": false, \"resolution\": \"full\"", 4,
         0.03, 0.08, 0.005},
        {"\"samples\": 128, \"interleave\": 4, \"jitter\": true, \"resolution\": \"full\"", 4, 0.03,
         0.08, 0.005},
        {"\"samples\": 128, \"interleave\": 1, \"resolution\": \"half\", \"jitter\": false", 2,
         0.02, 0.05, 0.01},
        {"\"samples\": 128, \"interleave\": 1, \"resolution\": \"quarter\", \"jitter\": false", 4,
         0.04, 0.08, 0.02},
        {"\"samples\": 128, \"interleave\": 2, \"resolution\": \"half\", \"jitter\": true", 4, 0.04,
         0.08, 0.02},
    };
    double edge_default[2] = {0, 0};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        st_image img = {0};
        write_scene(cases[k].params);
        if (!toth_render(scene, out, NULL, &img)) continue;
        cmp e = compare(&img, &ref, cases[k].M);
        printf("  %-72s mean %.4f edge %.4f block spread %.5f\n", cases[k].params, e.mean,
               e.edge_mean, e.block_spread);
        CHECK(e.mean < cases[k].mean, "%s: mean rel. error %.4f", cases[k].params, e.mean);
        CHECK(e.edge_mean < cases[k].edge, "%s: silhouette rel. error %.4f", cases[k].params,
              e.edge_mean);
        CHECK(e.block_spread < cases[k].spread, "%s: no block pattern, class means spread %.5f",
              cases[k].params, e.block_spread);
        if (k == 1) edge_default[0] = e.edge_mean;
        if (k == 4) edge_default[1] = e.edge_mean;
        st_image_free(&img);
    }
    // The same without the geometry test: the silhouettes bleed.
    const char *blind[2] = {
        "\"samples\": 128, \"interleave\": 4, \"jitter\": false, \"resolution\": \"full\", "
        "\"edge_tolerance\": 10",
        "\"samples\": 128, \"interleave\": 1, \"resolution\": \"quarter\", \"jitter\": false, "
        "\"edge_tolerance\": 10"};
    for (int k = 0; k < 2 && !strcmp(sampling, "uniform"); k++) {
        st_image img = {0};
        write_scene(blind[k]);
        if (!toth_render(scene, out, NULL, &img)) continue;
        cmp e = compare(&img, &ref, 4);
        printf("  %-72s mean %.4f edge %.4f\n", blind[k], e.mean, e.edge_mean);
        CHECK(e.edge_mean > 3 * edge_default[k], "geometry-blind silhouette error %.4f vs %.4f",
              e.edge_mean, edge_default[k]);
        st_image_free(&img);
    }
    st_image_free(&ref);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/edge.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/edge.exr", ST_TEST_SCRATCH);
    find_edges();
    run_cases();
    sampling = "equiangular";
    run_cases();
    return st_test_summary("toth_interleave");
}
