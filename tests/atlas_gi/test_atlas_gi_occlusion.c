// Visibility: parallel opposed unit squares (emitter L0 = 1 above, receiver
// of albedo rho below, F = 0.199825) with a black wall between them. Without
// visibility (the thesis) the wall changes nothing: the receiver still gets
// rho F. With visibility the BVH rays find the wall and the light is gone.
// Visibility must not remove light that is not blocked: without the wall,
// and for perpendicular squares sharing an edge (rays graze the concave
// edge), visibility on still gives rho F.
#include "gi_test.h"

#define H 128
#define K 100
static const double RHO = 0.5;

static double receiver(const char *name, const char *emitter, const char *extra_geometry, bool vis,
                       double D) {
    char cam[512], json[4096];
    gi_headon_camera(cam, sizeof cam, H, K, D);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d}, %s, \"lights\": [],\n"
             " \"geometry\": [\n"
             "  {\"quad\": {\"corner\": [0, 0, 0], \"u\": [0, 0, 1], \"v\": [1, 0, 0]}, "
             "\"albedo\": [%g, %g, %g]},\n"
             "  {\"quad\": %s, \"albedo\": [0, 0, 0], \"emission\": [1, 1, 1]}%s],\n"
             " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, \"mode\": "
             "\"gather\", \"sampling\": \"uniform\", \"samples\": 256,"
             " \"display\": \"indirect\", \"visibility\": %s, \"max_frames\": 12, \"tolerance\": "
             "0}}]}\n",
             H, H, cam, RHO, RHO, RHO, emitter, extra_geometry, vis ? "true" : "false");
    st_image img = {0};
    double v = -1;
    if (gi_render(name, json, "--frames 12", &img)) {
        v = gi_headon_mean(&img, K, 1);
        st_image_free(&img);
    }
    printf("%s: receiver mean indirect %.6f (rho F %.6f)\n", name, v, RHO * 0.199825);
    return v;
}

int main(void) {
    const char *parallel = "{\"corner\": [0, 1, 0], \"u\": [1, 0, 0], \"v\": [0, 0, 1]}";
    const char *perp = "{\"corner\": [0, 0, 0], \"u\": [1, 0, 0], \"v\": [0, 1, 0]}";
    // A 2 m black wall at y = 0.8 (the camera looks from y = 0.5, below it).
    const char *wall = ",\n  {\"quad\": {\"corner\": [-0.5, 0.8, -0.5], \"u\": [0, 0, 2], \"v\": "
                       "[2, 0, 0]}, \"albedo\": [0, 0, 0]}";
    double off = receiver("wall_visibility_off", parallel, wall, false, 0.5);
    double on = receiver("wall_visibility_on", parallel, wall, true, 0.5);
    double open = receiver("open_visibility_on", parallel, "", true, 0.5);
    double edge = receiver("perpendicular_visibility_on", perp, "", true, 3.0);
    CHECK_REL(off, RHO * 0.199825, 0.02, 0);
    CHECK(on >= 0 && on < 1e-3 * off,
          "the wall removes the indirect light: %.3g vs %.3g without visibility", on, off);
    CHECK_REL(open, RHO * 0.199825, 0.02, 0);
    CHECK_REL(edge, RHO * 0.200044, 0.02, 0);
    return st_test_summary("test_atlas_gi_occlusion");
}
