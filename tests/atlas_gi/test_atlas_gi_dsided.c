// Double-sided surfaces (issue 20): each side of a double-sided mesh has its
// own texels, lit by what that side faces.
//  1. A closed mesh renders the same whether its material is double-sided
//     or not: the Cornell box exported from Blender with its default
//     materials (doubleSided: true; walls as closed 5 cm boxes, two
//     blocks), against the same file with double_sided overridden to
//     false, in transfer mode and in gather mode, and transfer against
//     gather. The back sides lie inside the closed boxes: the transfer
//     leaves them out ("sealed" in --stats).
//  2. An open double-sided wall lit from one side is lit on that side only,
//     and its back receives only what the back faces: a wall standing on a
//     floor that is split by it, the light on the front's side; each side
//     seen by its own camera, against `strahl reference`.
//  3. The other plugins make no single-sided assumption: shadow_map (with
//     its refine rays: any hit, whatever the side), toth (the shadow map in
//     a medium) and mitchell (its occlusion image counts a double-sided
//     emitter on both sides; a closed mesh has no visible back) render a
//     closed mesh the same whether double-sided or not: the Blender room of
//     closed wall boxes (tests/data/crosscheck/fog_room.glb) in a medium.
#include "st_test_render.h" // first: it defines _GNU_SOURCE
#include "st_test_support.h"

#include "gi_refcmp.h"
#include <stdio.h>
#include <stdlib.h>

static bool mean_of(const char *path, double *mean) {
    st_image img = {0};
    if (!st_test_read(path, &img)) return false;
    double s = 0;
    for (size_t i = 0; i < (size_t)img.width * img.height; i++)
        for (int k = 0; k < 3; k++)
            s += img.data[i * img.channels + k];
    *mean = s / (3.0 * img.width * img.height);
    bool finite = st_test_all_finite(&img);
    st_image_free(&img);
    return finite;
}

// relMSE of a against b (both RGB EXRs of one size).
static double relmse_of(const char *a, const char *b) {
    st_image x = {0}, y = {0};
    double r = INFINITY;
    if (st_test_read(a, &x) && st_test_read(b, &y) && x.width == y.width && x.height == y.height) {
        double s = 0;
        size_t n = (size_t)x.width * x.height;
        for (size_t i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) {
                double p = x.data[i * x.channels + k], q = y.data[i * y.channels + k];
                s += (p - q) * (p - q) / (q * q + 0.01);
            }
        r = s / (3.0 * n);
    }
    st_image_free(&x);
    st_image_free(&y);
    return r;
}

static void closed_mesh(void) {
    const char *glb = ST_TEST_SOURCE_DIR "/scenes/assets/gi_blender_cornell_ds.glb";
    char img[2][2][512];
    for (int ds = 0; ds < 2; ds++) {
        char scene[512], json[2048];
        snprintf(scene, sizeof scene, "%s/cornell_%s.json", ST_TEST_SCRATCH, ds ? "ds" : "ss");
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": 47, \"height\": 48},\n"
                 " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, "
                 "0], \"fov_y\": 40, \"near\": 0.05, \"far\": 100},\n"
                 " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.55, 0], \"intensity\": "
                 "[3, 3, 3]}],\n"
                 " \"geometry\": [{\"gltf\": \"%s\", \"double_sided\": %s}],\n"
                 " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"atlas_gi\", \"params\": "
                 "{\"atlas_size\": 256, \"display\": \"indirect\"}}]}\n",
                 glb, ds ? "true" : "false");
        st_test_write(scene, json);
        for (int g = 0; g < 2; g++) {
            snprintf(img[ds][g], sizeof img[ds][g], "%s/cornell_%s_%s.exr", ST_TEST_SCRATCH,
                     ds ? "ds" : "ss", g ? "gather" : "transfer");
            CHECK(st_test_render(scene, img[ds][g],
                                 g ? "--set atlas_gi.mode=gather --set atlas_gi.atlas_size=128 "
                                     "--frames 24"
                                   : "") == 0,
                  "render %s", img[ds][g]);
        }
    }
    double m[2][2] = {{0}};
    for (int ds = 0; ds < 2; ds++)
        for (int g = 0; g < 2; g++)
            CHECK(mean_of(img[ds][g], &m[ds][g]), "%s: finite", img[ds][g]);
    double rt = relmse_of(img[1][0], img[0][0]), rg = relmse_of(img[1][1], img[0][1]);
    printf("closed mesh, mean indirect: transfer %.5f (double-sided) vs %.5f, gather %.5f vs "
           "%.5f; relMSE double- vs single-sided: transfer %.5f, gather %.5f\n",
           m[1][0], m[0][0], m[1][1], m[0][1], rt, rg);
    // Transfer: deterministic, so the double-sided file matches closely
    // (before the fix: 40% of the indirect light, black texels).
    CHECK_REL(m[1][0], m[0][0], 0.03, 0);
    CHECK(rt < 0.01, "transfer: relMSE %.5f double- vs single-sided", rt);
    // Gather: 24 frames of Monte Carlo noise in both.
    CHECK_REL(m[1][1], m[0][1], 0.03, 0);
    CHECK_REL(m[1][0], m[1][1], 0.05, 0); // transfer (atlas 256) against gather (128)
}

// A wall 1 m high (double-sided quad at x = 0, front +x) on a floor split by
// it, the light on the +x side, 2.2 m high: on the -x side the floor is lit
// beyond the wall's shadow (x < -0.75), and that is all the back side faces. Camera "front" sees
// the wall's +x side and camera "back" its -x side. Against the reference per pixel: the back side
// gets no direct light, and only the indirect light of what it faces.
static void open_wall(void) {
    static const char *geo =
        "  {\"quad\": {\"corner\": [-2, 0, 1.5], \"u\": [4, 0, 0], \"v\": [0, 0, -3]}, "
        "\"albedo\": [0.7, 0.7, 0.7]},\n"
        "  {\"quad\": {\"corner\": [0, 0, 1.2], \"u\": [0, 0, -2.4], \"v\": [0, 1.0, 0]}, "
        "\"albedo\": [0.6, 0.6, 0.6], \"double_sided\": true}\n";
    static const struct {
        const char *name, *pos, *target;
    } cams[2] = {{"front", "[3.2, 1.6, 0.9]", "[0, 0.5, -0.1]"},
                 {"back", "[-3.2, 1.6, 0.9]", "[0, 0.5, -0.1]"}};
    double mean[2] = {0};
    for (int c = 0; c < 2; c++) {
        char scene[512], json[2048], ref[512], img[512], cmd[2048];
        snprintf(scene, sizeof scene, "%s/wall_%s.json", ST_TEST_SCRATCH, cams[c].name);
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": 47, \"height\": 40},\n"
                 " \"camera\": {\"position\": %s, \"target\": %s, \"up\": [0, 1, 0], \"fov_y\": "
                 "50, \"near\": 0.05, \"far\": 100},\n"
                 " \"lights\": [{\"type\": \"point\", \"position\": [0.9, 2.2, 0.2], "
                 "\"intensity\": [2, 2, 2]}],\n"
                 " \"geometry\": [\n%s ],\n"
                 " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"atlas_gi\", "
                 "\"params\": {\"atlas_size\": 256}}]}\n",
                 cams[c].pos, cams[c].target, geo);
        st_test_write(scene, json);
        snprintf(ref, sizeof ref, "%s/wall_%s_ref.exr", ST_TEST_SCRATCH, cams[c].name);
        snprintf(img, sizeof img, "%s/wall_%s.exr", ST_TEST_SCRATCH, cams[c].name);
        snprintf(cmd, sizeof cmd,
                 "%s reference %s -o %s --bounces 1 --spp 1024 --seed 3 --filter point >/dev/null",
                 ST_TEST_STRAHL, scene, ref);
        CHECK(system(cmd) == 0, "%s", cmd);
        CHECK(st_test_render(scene, img, "") == 0, "render %s", img);
        gi_refcmp m = {0};
        st_err err = {0};
        bool ok = gi_refcmp_files(img, ref, 1, &m, &err);
        CHECK(ok, "%s: %s", cams[c].name, err.msg);
        if (!ok) continue;
        printf("open wall, %s side: relMSE %.5f, NRMSE %.4f (reference noise %.5f), mean %.5f "
               "vs %.5f\n",
               cams[c].name, m.relmse, m.nrmse, m.noise_relmse, m.mean_a, m.mean_b);
        CHECK(m.relmse <= 0.005, "%s side: relMSE %.5f", cams[c].name, m.relmse);
        CHECK(m.nrmse <= 0.05, "%s side: NRMSE %.4f", cams[c].name, m.nrmse);
        CHECK_REL(m.mean_a, m.mean_b, 0.03, 0);
        mean[c] = m.mean_a;
    }
    // The back side sees only the dark half of the floor: far below the front.
    CHECK(mean[1] < 0.25 * mean[0], "back side mean %.5f vs front %.5f", mean[1], mean[0]);
}

static void other_plugins(void) {
    static const char *const mods[] = {"toth", "mitchell"};
    for (int k = 0; k < 2; k++) {
        char img[2][512];
        for (int ds = 0; ds < 2; ds++) {
            char scene[512], json[2048];
            snprintf(scene, sizeof scene, "%s/room_%s_%d.json", ST_TEST_SCRATCH, mods[k], ds);
            snprintf(
                json, sizeof json,
                "{\"image\": {\"width\": 48, \"height\": 36},\n"
                " \"camera\": {\"position\": [2.4, 1.5, 2.6], \"target\": [-1.2, 0.9, -0.6], "
                "\"up\": [0, 1, 0], \"fov_y\": 60, \"near\": 0.05, \"far\": 40},\n"
                " \"lights\": [{\"type\": \"point\", \"position\": [-2.5, 2.4, 0.3], "
                "\"intensity\": [20, 20, 20]}],\n"
                " \"geometry\": [{\"gltf\": \"%s/tests/data/crosscheck/fog_room.glb\", "
                "\"double_sided\": %s}],\n"
                " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]},\n"
                " \"modules\": [{\"name\": \"shadow_map\"}, {\"name\": \"%s\"}]}\n",
                ST_TEST_SOURCE_DIR, ds ? "true" : "false", mods[k]);
            st_test_write(scene, json);
            snprintf(img[ds], sizeof img[ds], "%s/room_%s_%d.exr", ST_TEST_SCRATCH, mods[k], ds);
            CHECK(st_test_render(scene, img[ds], "--frames 1") == 0, "render %s", img[ds]);
        }
        double m = 0, r = relmse_of(img[1], img[0]);
        CHECK(mean_of(img[1], &m) && m > 0, "%s: finite, lit (mean %g)", mods[k], m);
        printf("closed room, shadow_map + %s: relMSE double- vs single-sided %.3g (mean %.5f)\n",
               mods[k], r, m);
        CHECK(r < 1e-6, "%s: relMSE %.3g double- vs single-sided", mods[k], r);
    }
}

int main(void) {
    setvbuf(stdout, NULL, _IOLBF, 0);
    closed_mesh();
    open_wall();
    other_plugins();
    return st_test_summary("test_atlas_gi_dsided");
}
