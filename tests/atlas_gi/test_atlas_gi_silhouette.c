// The side the camera sees is the facet's (common/facet.glsl), in the
// regular pass and in the atlas display (the thesis' combined atlas
// textured onto the scene): on a coarse smooth sphere lit from the side, the
// interpolated normal near the silhouette turns away from the camera while
// the camera sees the facet's front. Every pixel that the reference (exact
// direct light at the pixel centre; it decides by the winding) shows lit is
// lit in the combined display (the regular pass: direct light, no indirect
// reaches a lone convex sphere's outside; the reference also shadows the
// coarse mesh's facets that face away from the light, so it lights fewer
// pixels than the unshadowed regular pass), and every pixel lit there is lit
// in the atlas display too (each was black where the interpolated normal
// picked the side); the means agree (atlas: up to its resolution).
#include "gi_test.h"

static const char *scene_fmt =
    "{\"image\": {\"width\": 64, \"height\": 64},"
    " \"camera\": {\"position\": [0, 0, 2.6], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "50, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [3, 0.5, 0.3], \"intensity\": [8, 8, 8]}],"
    " \"geometry\": [{\"sphere\": {\"center\": [0, 0, 0], \"radius\": 0.9, \"rings\": 4, "
    "\"segments\": 6}}],"
    " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 256, \"mode\": "
    "\"gather\", \"visibility\": false, \"sampling\": \"uniform\", \"samples\": 16, "
    "\"progressive\": false, \"display\": \"%s\"}}]}";

int main(void) {
    char json[2048];
    st_image comb = {0}, atl = {0}, ref = {0};
    snprintf(json, sizeof json, scene_fmt, "combined");
    int ok = gi_render("silhouette_combined", json, NULL, &comb);
    snprintf(json, sizeof json, scene_fmt, "atlas");
    ok &= gi_render("silhouette_atlas", json, NULL, &atl);
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/silhouette_combined.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/silhouette_ref.exr", ST_TEST_SCRATCH);
    unlink(out);
    int rc = st_test_sh("%s reference %s -o %s --bounces 0 --spp 1 --filter point >/dev/null",
                        ST_TEST_STRAHL, scene, out);
    CHECK(rc == 0, "strahl reference exits %d", rc);
    ok &= rc == 0 && st_test_read(out, &ref);
    if (!ok) return st_test_summary("test_atlas_gi_silhouette");
    double peak = 0;
    for (int j = 0; j < comb.height; j++)
        for (int i = 0; i < comb.width; i++)
            peak = fmax(peak, st_image_px(&ref, i, j)[1]);
    int ref_lit = 0, ref_black = 0;
    double sr = 0, sg = 0;
    for (int j = 0; j < comb.height; j++)
        for (int i = 0; i < comb.width; i++) {
            double r = st_image_px(&ref, i, j)[1], c = st_image_px(&comb, i, j)[1];
            if (r <= 0.02 * peak) continue;
            ref_lit++, ref_black += c <= 0, sr += r, sg += c;
        }
    printf("reference: lit pixels %d, black in the regular pass %d, mean regular/reference "
           "%.4f\n",
           ref_lit, ref_black, ref_lit ? sg / sr : 0.0);
    CHECK(ref_lit > 150, "lit sphere pixels in the reference: %d", ref_lit);
    CHECK(ref_black == 0, "%d pixels the reference lights are black in the regular pass",
          ref_black);
    CHECK_REL(sg, sr, 0.01, 0);
    // Lit: above 2% of the peak (away from the terminator, where the atlas'
    // texels and the pixel may fall on either side of cos = 0).
    int lit = 0, black = 0;
    double sc = 0, sa = 0;
    for (int j = 0; j < comb.height; j++)
        for (int i = 0; i < comb.width; i++) {
            double c = st_image_px(&comb, i, j)[1], a = st_image_px(&atl, i, j)[1];
            if (c <= 0.02 * peak) continue;
            lit++, black += a <= 0, sc += c, sa += a;
        }
    printf("lit pixels %d (peak %.4g), black in the atlas display %d, mean atlas/combined %.4f\n",
           lit, peak, black, lit ? sa / sc : 0.0);
    CHECK(lit > 300, "lit sphere pixels: %d", lit);
    CHECK(black == 0, "%d lit pixels are black in the atlas display", black);
    CHECK_REL(sa, sc, 0.05, 0);
    st_image_free(&comb);
    st_image_free(&atl);
    st_image_free(&ref);
    return st_test_summary("test_atlas_gi_silhouette");
}
