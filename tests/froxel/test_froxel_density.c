// froxel's in-scattered light against a per-pixel quadrature of the model
// (docs/physics.md) in a closed room lit by one point light and no occluder
// but the walls: L_in = integral_0^s sigma_s d(x) phase I / r^2
// e^(-sigma_t tau_light) e^(-sigma_t tau_view) dt, with the optical depths of
// exponential height fog in closed form (st_height_fog_integral) and the
// homogeneous medium as d = 1; a VDB grid of density 2 around the whole
// room as d = 2. froxel's L_in is its image minus the image
// without a volumetric module (the regular pass: surfaces times the view's
// transmittance, which froxel must not apply again), so surfaces cancel.
// Per case: NRMSE of L_in (rms error over R, G, B / mean) <= 0.10 at the
// defaults, and the surfaces' share checked by the same difference being
// non-negative everywhere.
#include "st_test_render.h"
#include "st_physics.h"
#include "reference/vdb_writer.h"

#define N 64
static const double CAM[3] = {0, 1.2, 1.5}, TGT[3] = {0, 1.0, -2}, UP[3] = {0, 1, 0}, FOV = 60;
static const double BMIN[3] = {-2, 0, -2}, BMAX[3] = {2, 3, 2};
static const double LP[3] = {0.6, 2.1, -0.8}, LI = 10;
static const double SS = 0.3, SA = 0.05, G = 0.3;

typedef struct {
    double o[3], d[3], falloff; // falloff < 0: homogeneous
    double scale;               // the homogeneous density
} ray_ctx;

static double tau(const ray_ctx *c, const double p[3], const double w[3], double len) {
    if (c->falloff < 0) return c->scale * len;
    return st_height_fog_integral(0.0, c->falloff, p[1], w[1], len);
}

static double integrand(double t, void *ctx) {
    const ray_ctx *c = ctx;
    double x[3], v[3];
    for (int k = 0; k < 3; k++)
        x[k] = c->o[k] + t * c->d[k], v[k] = LP[k] - x[k];
    double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    double w[3] = {v[0] / r, v[1] / r, v[2] / r};
    double cos_t = w[0] * c->d[0] + w[1] * c->d[1] + w[2] * c->d[2];
    double dens = c->falloff < 0 ? c->scale : exp(-c->falloff * x[1]);
    double st = SS + SA;
    return SS * dens * st_phase_hg(cos_t, G) * LI / (r * r) *
           exp(-st * (tau(c, x, w, r) + tau(c, c->o, c->d, t)));
}

static double box_exit(const double o[3], const double d[3]) {
    double t = 1e30;
    for (int k = 0; k < 3; k++) {
        if (d[k] > 1e-15) t = fmin(t, (BMAX[k] - o[k]) / d[k]);
        if (d[k] < -1e-15) t = fmin(t, (BMIN[k] - o[k]) / d[k]);
    }
    return t;
}

static void write_scene(const char *path, const char *density, const char *modules) {
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],\n"
             " \"geometry\": [{\"box\": {\"min\": [-2, 0, -2], \"max\": [2, 3, 2]}, \"inward\": "
             "true, \"albedo\": [0.5, 0.5, 0.5]}],\n"
             " \"medium\": {\"sigma_s\": [%g, %g, %g], \"sigma_a\": [%g, %g, %g], \"phase\": "
             "{\"hg\": %g}%s},\n"
             " \"modules\": [%s]}\n",
             N, N, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, LP[0], LP[1], LP[2], LI, LI,
             LI, SS, SS, SS, SA, SA, SA, G, density, modules);
    st_test_write(path, json);
}

// falloff >= 0: height fog; scale > 0: a VDB block of that density around
// the whole room (homogeneous inside it); else homogeneous.
static void run(const char *what, double falloff, double scale) {
    char scene[512], out_f[512], out_0[512], density[256] = "";
    snprintf(scene, sizeof scene, "%s/room.json", ST_TEST_SCRATCH);
    snprintf(out_f, sizeof out_f, "%s/froxel.exr", ST_TEST_SCRATCH);
    snprintf(out_0, sizeof out_0, "%s/none.exr", ST_TEST_SCRATCH);
    if (falloff >= 0)
        snprintf(density, sizeof density,
                 ", \"density\": {\"height\": {\"base\": 0, \"falloff\": %g}}", falloff);
    if (scale > 0) {
        char vdb[600];
        snprintf(vdb, sizeof vdb, "%s/block.vdb", ST_TEST_SCRATCH);
        // Voxel centres from (-2.5, -0.3, -2.5) to (2.5, 3.3, 2.5): the room and
        // every light path in it lie inside, where the trilinear density is flat.
        st_test_vdb spec = {
            .name = "density", .n = {26, 19, 26}, .value = (float)scale, .voxel = 0.2};
        CHECK(st_test_write_vdb(vdb, &spec), "writing %s", vdb);
        snprintf(density, sizeof density,
                 ", \"density\": {\"vdb\": \"block.vdb\", \"transform\": {\"translate\": "
                 "[-2.5, -0.3, -2.5]}}");
    }
    write_scene(scene, density, "{\"name\": \"shadow_map\"}, {\"name\": \"froxel\"}");
    int rc = st_test_render(scene, out_f, NULL);
    write_scene(scene, density, "{\"name\": \"shadow_map\"}");
    rc |= st_test_render(scene, out_0, NULL);
    CHECK(rc == 0, "%s: render exit %d", what, rc);
    st_image a = {0}, b = {0};
    if (rc != 0 || !st_test_read(out_f, &a) || !st_test_read(out_0, &b)) return;
    CHECK(st_test_all_finite(&a), "%s: finite", what);
    st_test_cam cam = st_test_camera(CAM, TGT, UP, FOV, N, N);
    double se = 0, sum = 0, lo = 0, gsum = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            ray_ctx c = {{CAM[0], CAM[1], CAM[2]}, {0}, falloff, scale > 0 ? scale : 1.0};
            st_test_ray(&cam, i, j, c.d);
            double s = box_exit(CAM, c.d);
            double want = st_integrate(integrand, &c, 0.0, s, 1e-300, 1e-8);
            const float *pa = st_image_px(&a, i, j), *pb = st_image_px(&b, i, j);
            for (int k = 0; k < 3; k++) {
                double got = (double)pa[k] - pb[k];
                se += (got - want) * (got - want);
                sum += want;
                gsum += got;
                lo = fmin(lo, got);
            }
        }
    double nrmse = sqrt(se / (3.0 * N * N)) / (sum / (3.0 * N * N));
    printf("  %-12s in-scattered light: mean %.5f (froxel %.5f), nrmse %.4f, smallest %.2e\n", what,
           sum / (3.0 * N * N), gsum / (3.0 * N * N), nrmse, lo);
    CHECK(nrmse <= 0.10, "%s: nrmse %.4f", what, nrmse);
    CHECK(lo >= -1e-6, "%s: froxel took light away (%.3g): extinction applied twice?", what, lo);
    st_image_free(&a);
    st_image_free(&b);
}

int main(void) {
    run("homogeneous", -1, 0);
    run("height fog", 0.7, 0);
    run("steep fog", 3.0, 0);
    run("vdb block", -1, 2.0);
    return st_test_summary("test_froxel_density");
}
