// ssgi, the screen-space baseline: with every sender in view it agrees with
// atlas_gi (validated against form factors) on the receiver's mean indirect
// radiance, pixel by pixel, within 5%; with the emitter out of view it
// loses that light completely, while atlas_gi still gives rho F: the
// artifact the atlas removes. Finite for sample counts 1..1024 and both
// estimators.
#include "gi_test.h"

#define H 128
#define K 100
static const double RHO = 0.5;

// Perpendicular unit squares: receiver on the floor, emitter wall at z = 0 facing +z.
static void scene(char *out, size_t n, const char *camera, const char *module) {
    snprintf(out, n,
             "{\"image\": {\"width\": %d, \"height\": %d}, %s, \"lights\": [],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [0, 0, 0], \"u\": [0, 0, 1], \"v\": [1, 0, 0]}, "
             "\"albedo\": [%g, %g, %g]},\n"
             "  {\"quad\": {\"corner\": [0, 0, 0], \"u\": [1, 0, 0], \"v\": [0, 1, 0]}, "
             "\"albedo\": [0, 0, 0], "
             "\"emission\": [1, 1, 1]}],\n"
             " \"modules\": [%s]}\n",
             H, H, camera, RHO, RHO, RHO, module);
}

static const char *atlas_mod =
    "{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, \"mode\": \"gather\", "
    "\"visibility\": false, \"sampling\": \"uniform\", \"samples\": 256, "
    "\"display\": \"indirect\", \"max_frames\": 12, \"tolerance\": 0}}";

int main(void) {
    char json[4096], cam[512];
    // Oblique view: the emitter wall and the receiver both fully in view.
    snprintf(cam, sizeof cam,
             "\"camera\": {\"position\": [0.5, 1.2, 2.6], \"target\": [0.5, 0.35, 0.3], \"up\": "
             "[0, 1, 0], "
             "\"fov_y\": 45, \"near\": 0.05, \"far\": 100}");
    st_image ref = {0}, ss = {0};
    scene(json, sizeof json, cam, atlas_mod);
    int ok = gi_render("oblique_atlas", json, "--frames 12", &ref);
    scene(json, sizeof json, cam,
          "{\"name\": \"ssgi\", \"params\": {\"samples\": 1024, \"display\": \"indirect\"}}");
    ok = gi_render("oblique_ssgi", json, NULL, &ss) && ok;
    if (ok) {
        int n = 0;
        double a = gi_masked_mean(&ref, &ref, &n), s = gi_masked_mean(&ss, &ref, &n);
        printf("emitter in view: receiver pixels %d, mean indirect atlas_gi %.6f, ssgi %.6f (rel "
               "%+.4f)\n",
               n, a, s, s / a - 1);
        CHECK(n > 2000, "receiver pixels: %d", n);
        CHECK_REL(s, a, 0.05, 0);
    }
    st_image_free(&ref);
    st_image_free(&ss);

    // The camera in the emitter's plane, looking away over the receiver: the
    // emitter covers no pixel of the G-buffer.
    snprintf(
        cam, sizeof cam,
        "\"camera\": {\"position\": [0.5, 1.5, 0], \"target\": [0.5, 0, 1], \"up\": [0, 1, 0], "
        "\"fov_y\": 60, \"near\": 0.05, \"far\": 100}");
    scene(json, sizeof json, cam, atlas_mod);
    ok = gi_render("edge_on_atlas", json, "--frames 12", &ref);
    scene(json, sizeof json, cam,
          "{\"name\": \"ssgi\", \"params\": {\"samples\": 256, \"display\": \"indirect\"}}");
    ok = gi_render("edge_on_ssgi", json, NULL, &ss) && ok;
    if (ok) {
        int n = 0;
        double a = gi_masked_mean(&ref, &ref, &n), s = gi_masked_mean(&ss, &ref, &n);
        printf("emitter out of view: receiver pixels %d, atlas_gi %.6f, ssgi %.6f\n", n, a, s);
        CHECK(n > 2000, "receiver pixels: %d", n);
        CHECK(a > 0.05, "atlas_gi still lights the receiver: %g", a);
        CHECK(s < 0.01 * a, "ssgi loses the unseen emitter: %g vs %g", s, a);
    }
    st_image_free(&ref);
    st_image_free(&ss);

    // Stress: sample counts and estimators, combined display.
    const int samples[] = {1, 3, 64, 1024};
    for (int e = 0; e < 2; e++)
        for (int k = 0; k < 4; k++) {
            char mod[256], name[64];
            snprintf(mod, sizeof mod,
                     "{\"name\": \"ssgi\", \"params\": {\"samples\": %d, \"estimator\": \"%s\"}}",
                     samples[k], e ? "thesis" : "area");
            snprintf(cam, sizeof cam,
                     "\"camera\": {\"position\": [0.5, 0.02, 0.02], \"target\": [0.5, 0.5, 0], "
                     "\"up\": [0, 1, 0], "
                     "\"fov_y\": 100, \"near\": 0.001, \"far\": 100}");
            scene(json, sizeof json, cam, mod);
            snprintf(name, sizeof name, "stress_%s_%d", e ? "thesis" : "area", samples[k]);
            st_image img = {0};
            if (gi_render(name, json, NULL, &img)) st_image_free(&img);
        }
    return st_test_summary("test_ssgi");
}
