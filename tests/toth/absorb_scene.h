// The scene of the absorption tests (test_toth_absorb: a constant density;
// test_toth_density_absorb: medium.density): an emitter, a lit floor and the
// background seen through a purely absorbing medium, and the per-pixel
// closed form each centre ray must match.
#ifndef ABSORB_SCENE_H
#define ABSORB_SCENE_H
#include "toth_test.h"
#include "st_physics.h"

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
static const char *density_json; // the medium's "density" value (NULL: constant density)

static void write_scene(const char *modules) {
    char json[4096], density[512] = "";
    if (density_json) snprintf(density, sizeof density, ", \"density\": %s", density_json);
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
             " \"medium\": {\"sigma_s\": [0, 0, 0], \"sigma_a\": [%g, %g, %g]%s},\n"
             " \"modules\": [%s]}\n",
             W, H, CAM[0], CAM[1], CAM[2], TGT[0], TGT[1], TGT[2], FOV, FAR, BG[0], BG[1], BG[2],
             LP[0], LP[1], LP[2], LI[0], LI[1], LI[2], -EM_X, EM_Y0, EM_Z, 2 * EM_X, EM_Y1 - EM_Y0,
             EM[0], EM[1], EM[2], -FL_X, FL_Z0, FL_Z1 - FL_Z0, 2 * FL_X, RHO, RHO, RHO, SA[0],
             SA[1], SA[2], density, modules);
    st_test_write(scene, json);
}

typedef struct {
    int emitter, floor, background; // pixels checked
    double worst;                   // relative error
    double min_t_emitter;           // the shortest emitter distance seen
} result;

// Optical depth per unit sigma along o + s w, s in [0, len]: the length
// itself for a constant density (den NULL).
static double absorb_tau(const st_density_desc *den, const double o[3], const double w[3],
                         double len) {
    return den ? st_density_integral(den, o, w, 0, len) : len;
}

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
                double tau = absorb_tau(den, pf, wl, dl) + absorb_tau(den, CAM, d, t);
                for (int k = 0; k < 3; k++)
                    want[k] = RHO / M_PI * LI[k] * (l[1] / dl) / d2 * exp(-SA[k] * tau);
                count = &r.floor;
            } else if (hit_e) {
                if (ie < MARGIN) continue;
                t = te;
                double tau = absorb_tau(den, CAM, d, t);
                for (int k = 0; k < 3; k++)
                    want[k] = EM[k] * exp(-SA[k] * tau);
                r.min_t_emitter = fmin(r.min_t_emitter, t);
                count = &r.emitter;
            } else {
                if (ie > -MARGIN || iflo > -MARGIN) continue; // near an edge, outside
                double cos_axis = d[0] * c.f[0] + d[1] * c.f[1] + d[2] * c.f[2];
                t = FAR / cos_axis;
                double tau = absorb_tau(den, CAM, d, t);
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
#endif
