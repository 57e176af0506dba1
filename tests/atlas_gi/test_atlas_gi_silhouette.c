// The atlas display (the thesis' combined atlas textured onto the scene)
// decides the side the camera sees by the facet, as the regular pass does
// (common/facet.glsl): on a coarse smooth sphere lit from the side, the
// interpolated normal near the silhouette turns away from the camera while
// the camera sees the facet's front. Invariant: every pixel that the
// combined display shows lit is lit in the atlas display too (it was black
// there when the interpolated normal picked the side), and the two agree in
// the mean up to the atlas resolution.
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
    st_image comb = {0}, atl = {0};
    snprintf(json, sizeof json, scene_fmt, "combined");
    int ok = gi_render("silhouette_combined", json, NULL, &comb);
    snprintf(json, sizeof json, scene_fmt, "atlas");
    ok &= gi_render("silhouette_atlas", json, NULL, &atl);
    if (!ok) return st_test_summary("test_atlas_gi_silhouette");
    double peak = 0;
    for (int j = 0; j < comb.height; j++)
        for (int i = 0; i < comb.width; i++)
            peak = fmax(peak, st_image_px(&comb, i, j)[1]);
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
    return st_test_summary("test_atlas_gi_silhouette");
}
