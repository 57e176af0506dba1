// Display modes and the shadow map in the atlas. combined = direct +
// indirect pixel by pixel; "atlas" (the thesis' display: the combined atlas
// textured back) agrees with combined up to the atlas resolution; where
// the floor lies in a box's shadow the atlas' direct light is zero too, so
// shadow_map's visibility reached the G-buffer atlas even though atlas_gi
// comes first in the scene's module list ("shadow_map?" orders it after).
#include "gi_test.h"

static const char *scene_fmt =
    "{\"image\": {\"width\": 96, \"height\": 96},"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "40, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0.3, 1.6, 0.6], \"intensity\": [3, 3, 3]}],"
    " \"geometry\": ["
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 0, 2], \"v\": [2, 0, 0]}},"
    "  {\"quad\": {\"corner\": [-1, 2, -1], \"u\": [2, 0, 0], \"v\": [0, 0, 2]}},"
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [2, 0, 0], \"v\": [0, 2, 0]}},"
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}, \"albedo\": "
    "[0.75, 0.1, 0.1]},"
    "  {\"quad\": {\"corner\": [1, 0, -1], \"u\": [0, 0, 2], \"v\": [0, 2, 0]}, \"albedo\": [0.1, "
    "0.75, 0.1]},"
    "  {\"box\": {\"min\": [-0.7, 0, -0.7], \"max\": [-0.1, 1.2, -0.1]}}"
    " ],"
    " \"modules\": [%s]}";

#define ATLAS                                                                                      \
    "{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 256, \"mode\": \"gather\", "            \
    "\"visibility\": false, \"sampling\": \"uniform\", \"samples\": 64, \"progressive\": false, "  \
    "\"display\": \"%s\"}}"
#define SHADOW "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}"

static int render(const char *name, const char *display, bool shadow_first, st_image *img) {
    char mods[1024], json[4096];
    char atlas[320];
    snprintf(atlas, sizeof atlas, ATLAS, display);
    snprintf(mods, sizeof mods, "%s, %s", shadow_first ? SHADOW : atlas,
             shadow_first ? atlas : SHADOW);
    snprintf(json, sizeof json, scene_fmt, mods);
    return gi_render(name, json, NULL, img);
}

int main(void) {
    st_image comb = {0}, dir = {0}, ind = {0}, atl = {0}, atl2 = {0};
    int ok = render("combined", "combined", false, &comb) &
             render("direct", "direct", false, &dir) & render("indirect", "indirect", false, &ind) &
             render("atlas", "atlas", false, &atl) &
             render("atlas_shadow_first", "atlas", true, &atl2);
    if (!ok) return st_test_summary("test_atlas_gi_display");
    size_t n = (size_t)comb.width * comb.height * 3;
    double worst = 0, sc = 0, sa = 0;
    for (size_t i = 0; i < n; i++) {
        double e = fabs(comb.data[i] - (dir.data[i] + ind.data[i]));
        worst = fmax(worst, e / fmax(comb.data[i], 1e-3));
        sc += comb.data[i], sa += atl.data[i];
    }
    CHECK(worst < 1e-5, "combined = direct + indirect (worst rel %.3g)", worst);
    CHECK(!memcmp(atl.data, atl2.data, n * sizeof(float)),
          "module order does not change the atlas");
    printf("image mean: combined %.5f, atlas display %.5f (rel %+.4f)\n", sc / n, sa / n,
           sa / sc - 1);
    CHECK_REL(sa, sc, 0.03, 0);
    // Floor pixels in the tall box's shadow (no direct light, robustly: the
    // 3x3 neighbourhood too): the atlas display shows indirect light only.
    int shadowed = 0;
    double worst_sh = 0;
    for (int j = 60; j < 95; j++)
        for (int i = 1; i < 95; i++) {
            bool dark = true;
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++)
                    dark &= st_image_px(&dir, i + di, j + dj)[1] == 0;
            if (!dark || st_image_px(&ind, i, j)[1] <= 0) continue;
            shadowed++;
            double r = st_image_px(&atl, i, j)[1] / st_image_px(&ind, i, j)[1];
            worst_sh = fmax(worst_sh, fabs(r - 1));
        }
    printf("shadowed floor pixels %d: atlas display / indirect within %.4f\n", shadowed, worst_sh);
    CHECK(shadowed > 50, "shadowed floor pixels: %d", shadowed);
    CHECK(worst_sh < 0.05, "the atlas' direct light is shadowed: atlas/indirect off by %.3f",
          worst_sh);
    st_image_free(&comb);
    st_image_free(&dir);
    st_image_free(&ind);
    st_image_free(&atl);
    st_image_free(&atl2);
    return st_test_summary("test_atlas_gi_display");
}
