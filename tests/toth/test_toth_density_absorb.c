// The GPU's view and light transmittance through a medium of varying
// density (medium.density, common/medium.glsl), per pixel against the C model
// (st_density_integral: height fog's closed form, a grid's exact DDA). A
// purely absorbing medium, so nothing scatters and every pixel is a closed
// form (centre ray, within 0.2%; measured 1.7e-4 height fog, 4.6e-5 grid):
//   - an emitter: E e^(-sigma_a tau(camera -> hit));
//   - a lit floor: rho/pi I cos / d^2 e^(-sigma_a (tau(hit -> light) + tau(camera -> hit)));
//   - the background at the far plane: B e^(-sigma_a tau(camera, far / cos));
// with no module and with shadow_map + toth (which adds nothing here: the
// view ray's share belongs to the regular pass). Height fog: the oracle of
// the issue (the closed form per pixel); a grid: a 10^3 block of density 2
// (trilinear, falling to 0 over one voxel at its faces) between the camera
// and the emitter. A module that models a homogeneous medium only
// (mitchell) is refused with exit 2, also when switched on later.
#include "toth_test.h"
#include "../reference/vdb_writer.h"
#include "st_test_support.h"
#include "st_world.h"

#define W 96
#define H 72
static const double CAM[3] = {0, 1.5, 6}, TGT[3] = {0, 1, -1}, UP[3] = {0, 1, 0};
static const double FOV = 50, FAR = 12;
static const double SA[3] = {0.6, 0.3, 0.1};  // sigma_a, 1/m
static const double EM[3] = {1.0, 0.5, 0.25}; // emitter radiance
static const double BG[3] = {0.2, 0.3, 0.4};  // background radiance
static const double LP[3] = {0, 3, 2}, LI[3] = {10, 8, 6}, RHO = 0.5;
static const double EM_X = 1.5, EM_Y0 = 0, EM_Y1 = 3, EM_Z = -1; // emitter quad
static const double FL_X = 4, FL_Z0 = -1, FL_Z1 = 6;             // floor y = 0
static const double MARGIN = 0.03; // metres kept from an edge (the centre ray's neighbours)

static char scene[512], out[512];
static const char *density_json; // the medium's "density" value

static void write_scene(const char *modules) {
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [%g, %g, %g], \"target\": [%g, %g, %g], \"up\": [0, 1, "
             "0], \"fov_y\": %g, \"near\": 0.05, \"far\": %g},\n"
             " \"background\": [%g, %g, %g],\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [%g, %g, %g], \"u\": [%g, 0, 0], \"v\": [0, %g, 0]},"
             " \"albedo\": [0, 0, 0], \"emission\": [%g, %g, %g]},\n"
             "  {\"quad\": {\"corner\": [%g, 0, %g], \"u\": [0, 0, %g], \"v\": [%g, 0, 0]},"
             " \"albedo\": [%g, %g, %g]}],\n"
             " \"medium\": {\"sigma_s\": [0, 0, 0], \"sigma_a\": [%g, %g, %g], \"density\": %s},\n"
             " \"modules\": [%s]}\n",
             W, H, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, FAR, BG[0], BG[1], BG[2],
             LP[0], LP[1], LP[2], LI[0], LI[1], LI[2], -EM_X, EM_Y0, EM_Z, 2 * EM_X, EM_Y1 - EM_Y0,
             EM[0], EM[1], EM[2], -FL_X, FL_Z0, FL_Z1 - FL_Z0, 2 * FL_X, RHO, RHO, RHO, SA[0],
             SA[1], SA[2], density_json, modules);
    st_test_write(scene, json);
}

typedef struct {
    int emitter, floor, background; // pixels checked
    double worst;                   // relative error
    double min_t_emitter;           // the shortest emitter distance seen
} result;

// Checks every pixel whose centre ray hits the emitter, the floor or nothing
// at least MARGIN from any edge.
static result check(const st_image *img, const st_density_desc *den) {
    st_test_cam c = st_test_camera(CAM, TGT, UP, FOV, W, H);
    result r = {0, 0, 0, 0, 1e30};
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            double te = (EM_Z - CAM[2]) / d[2], tf = d[1] < 0 ? -CAM[1] / d[1] : 1e30;
            double pe[3], pf[3];
            for (int k = 0; k < 3; k++)
                pe[k] = CAM[k] + te * d[k], pf[k] = CAM[k] + tf * d[k];
            // Distances of the hit points from the quads' edges (> 0 inside).
            double ie = fmin(EM_X - fabs(pe[0]), fmin(pe[1] - EM_Y0, EM_Y1 - pe[1]));
            double iflo = fmin(FL_X - fabs(pf[0]), fmin(pf[2] - FL_Z0, FL_Z1 - pf[2]));
            bool hit_e = te > 0 && ie > 0, hit_f = tf < 1e30 && iflo > 0;
            double want[3], t;
            int *count;
            if (hit_f && (!hit_e || tf < te)) { // the floor (in front of the emitter)
                if (iflo < MARGIN || (hit_e && te - tf < MARGIN)) continue;
                double l[3] = {LP[0] - pf[0], LP[1] - pf[1], LP[2] - pf[2]};
                double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2], dl = sqrt(d2);
                t = tf;
                double wl[3] = {l[0] / dl, l[1] / dl, l[2] / dl};
                double tau = st_density_integral(den, pf, wl, 0, dl) +
                             st_density_integral(den, CAM, d, 0, t);
                for (int k = 0; k < 3; k++)
                    want[k] = RHO / M_PI * LI[k] * (l[1] / dl) / d2 * exp(-SA[k] * tau);
                count = &r.floor;
            } else if (hit_e) {
                if (ie < MARGIN) continue;
                t = te;
                double tau = st_density_integral(den, CAM, d, 0, t);
                for (int k = 0; k < 3; k++)
                    want[k] = EM[k] * exp(-SA[k] * tau);
                r.min_t_emitter = fmin(r.min_t_emitter, t);
                count = &r.emitter;
            } else {
                if (ie > -MARGIN || iflo > -MARGIN) continue; // near an edge, outside
                double cos_axis = d[0] * c.f[0] + d[1] * c.f[1] + d[2] * c.f[2];
                t = FAR / cos_axis;
                double tau = st_density_integral(den, CAM, d, 0, t);
                for (int k = 0; k < 3; k++)
                    want[k] = BG[k] * exp(-SA[k] * tau);
                count = &r.background;
            }
            const float *px = st_image_px(img, i, j);
            for (int k = 0; k < 3; k++)
                r.worst = fmax(r.worst, fabs(px[k] - want[k]) / want[k]);
            (*count)++;
        }
    return r;
}

static void run(const char *what, const char *modules) {
    write_scene(modules);
    st_scene sc;
    st_err err = {0};
    if (!st_scene_load(scene, &sc, &err)) {
        CHECK(0, "%s: %s", what, err.msg);
        return;
    }
    st_image img = {0};
    int rc = st_test_render(scene, out, NULL);
    CHECK(rc == 0, "%s: exit %d", what, rc);
    if (rc == 0 && st_test_read(out, &img)) {
        result r = check(&img, &sc.density);
        printf("  %-26s worst relative error %.2e (%d emitter px, %d floor, %d background)\n", what,
               r.worst, r.emitter, r.floor, r.background);
        CHECK(r.emitter > 300 && r.floor > 300 && r.background > 100, "%s: pixels %d %d %d", what,
              r.emitter, r.floor, r.background);
        CHECK(r.worst < 0.002, "%s: worst relative error %.4f", what, r.worst);
        CHECK(st_test_all_finite(&img), "%s: finite", what);
        st_image_free(&img);
    }
    st_scene_free(&sc);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/density.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/density.exr", ST_TEST_SCRATCH);
    const char *toth = "{\"name\": \"shadow_map\"}, {\"name\": \"toth\"}";
    // Height fog thinning upward from y = 0.5: the floor rays cross e-folds.
    density_json = "{\"height\": {\"base\": 0.5, \"falloff\": 0.9}}";
    run("height fog, no module", "");
    run("height fog, toth", toth);
    // A homogeneous-only module is refused, with no image left behind.
    write_scene("{\"name\": \"mitchell\"}");
    char buf[4096], cmd[2048];
    unlink(out);
    snprintf(cmd, sizeof cmd, "%s render %s -o %s", ST_TEST_STRAHL, scene, out);
    int rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 2 && strstr(buf, "module 'mitchell' models a homogeneous medium only") &&
              !st_test_exists(out),
          "mitchell with height fog: rc %d, '%s'", rc, buf);
    // Switched on in a running world (the viewer's path), likewise.
    st_context *ctx = st_test_context();
    st_scene sc;
    st_err err = {0};
    write_scene("");
    if (ctx && st_scene_load(scene, &sc, &err)) {
        st_world *w = st_world_create(&sc, NULL, &err);
        CHECK(w != NULL, "world: %s", err.msg);
        if (w) {
            bool ok = st_world_enable(w, "mitchell", true, &err);
            CHECK(!ok && err.kind == ST_ERR_INPUT && strstr(err.msg, "module 'mitchell'") &&
                      !st_world_has_module(w, "mitchell"),
                  "enabling mitchell with height fog: %d '%s'", ok, err.msg);
            err = (st_err){0};
            CHECK(st_world_enable(w, "toth", true, &err), "enabling toth: %s", err.msg);
            st_world_destroy(w);
        }
        st_scene_free(&sc);
    } else {
        CHECK(0, "context or scene: %s", err.msg);
    }
    st_context_destroy(ctx);
    // A grid: 10^3 voxels of 0.2 m holding 2, centred at (0, 1.5, 2).
    char vdb[600];
    snprintf(vdb, sizeof vdb, "%s/block.vdb", ST_TEST_SCRATCH);
    st_test_vdb spec = {.name = "density", .n = {10, 10, 10}, .value = 2.0f, .voxel = 0.2};
    CHECK(st_test_write_vdb(vdb, &spec), "writing %s", vdb);
    density_json = "{\"vdb\": \"block.vdb\", \"transform\": {\"translate\": [-0.9, 0.6, 1.1]}}";
    run("vdb block, no module", "");
    run("vdb block, toth", toth);
    return st_test_summary("test_toth_density_absorb");
}
