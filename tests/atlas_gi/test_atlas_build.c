// Atlas invariants on the CPU builder (modules/atlas_gi/atlas.c): no two
// charts share a texel and no chart folds onto itself, every triangle with
// area owns at least one texel, and the texels' world areas sum to the
// scene's surface area within 1% (exactly, up to float rounding, since each
// texel's area is the clipped triangle area). Checked for the Cornell box at
// atlas sizes 64..2048, a 40k-triangle sphere scene (curved charts), thin
// and tiny triangles, a double-sided quad (two texel sets) and TEXCOORD_1.
#include "st_test.h"
#include "atlas.h"

static const char *cornell =
    "{\"image\": {\"width\": 64, \"height\": 64},"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "40, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.9, 0], \"intensity\": [3, 3, 3]}],"
    " \"geometry\": ["
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 0, 2], \"v\": [2, 0, 0]}},"
    "  {\"quad\": {\"corner\": [-1, 2, -1], \"u\": [2, 0, 0], \"v\": [0, 0, 2]}},"
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [2, 0, 0], \"v\": [0, 2, 0]}},"
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}, \"albedo\": "
    "[0.75, 0.1, 0.1]},"
    "  {\"quad\": {\"corner\": [1, 0, -1], \"u\": [0, 0, 2], \"v\": [0, 2, 0]}, \"albedo\": [0.1, "
    "0.75, 0.1]},"
    "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}},"
    "  {\"box\": {\"min\": [-0.7, 0, -0.7], \"max\": [-0.1, 1.2, -0.1]}}"
    " ]}";

static const char *spheres =
    "{\"image\": {\"width\": 64, \"height\": 64},"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "40, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [],"
    " \"geometry\": ["
    "  {\"quad\": {\"corner\": [-2, 0, -2], \"u\": [0, 0, 4], \"v\": [4, 0, 0]}},"
    "  {\"sphere\": {\"center\": [-0.5, 0.5, 0], \"radius\": 0.5, \"rings\": 100, \"segments\": "
    "100}},"
    "  {\"sphere\": {\"center\": [0.7, 0.3, 0], \"radius\": 0.3, \"rings\": 100, \"segments\": "
    "100}},"
    "  {\"quad\": {\"corner\": [-1, 1.5, 0], \"u\": [2, 0, 0], \"v\": [0, 0, 1]}, "
    "\"double_sided\": true}"
    " ]}";

static void check_atlas(const char *what, const st_scene *sc, atlas_opts o, int expect_w) {
    atlas a;
    st_err err = {0};
    o.keep_chart_map = true;
    if (!atlas_build(&a, sc->meshes, sc->num_meshes, &o, &err)) {
        CHECK(0, "%s: atlas_build: %s", what, err.msg);
        return;
    }
    double rel = fabs(a.texel_area_sum - a.surface_area) / a.surface_area;
    printf("%s: %dx%d, %d charts, %ld valid texels, %d points, area %.6f vs %.6f (rel %.2e), %g "
           "texels/m\n",
           what, a.width, a.height, a.num_charts, a.valid_texels, a.num_points, a.texel_area_sum,
           a.surface_area, rel, a.texels_per_meter);
    if (expect_w) CHECK(a.width == expect_w, "%s: width %d, want %d", what, a.width, expect_w);
    CHECK(rel < 0.01, "%s: texel areas %.6f vs surface %.6f", what, a.texel_area_sum,
          a.surface_area);
    CHECK(rel < 1e-4, "%s: exact clipping should be far better than 1%%: rel %.3g", what, rel);
    CHECK(a.overlap_texels == 0, "%s: %ld overlapping texels", what, a.overlap_texels);
    CHECK(a.uncovered_tris == 0, "%s: %ld triangles without a texel", what, a.uncovered_tris);
    // Gutters: no valid texel of one chart within 2 texels (the dilated ring
    // plus the bilinear footprint) of another chart's valid texel.
    long close = 0;
    for (int y = 0; y < a.height; y++)
        for (int x = 0; x < a.width; x++) {
            int c = a.chart[(size_t)y * a.width + x];
            if (c < 0 || a.area[(size_t)y * a.width + x] <= 0) continue;
            for (int dy = -2; dy <= 2; dy++)
                for (int dx = -2; dx <= 2; dx++) {
                    int u = x + dx, v = y + dy;
                    if (u < 0 || v < 0 || u >= a.width || v >= a.height) continue;
                    int d = a.chart[(size_t)v * a.width + u];
                    close += d >= 0 && d != c && a.area[(size_t)v * a.width + u] > 0;
                }
        }
    if (!o.use_uv1)
        CHECK(close == 0, "%s: %ld texel pairs of different charts closer than the gutter", what,
              close);
    // Every uv lies inside the atlas; every point texel has area.
    int bad_uv = 0;
    for (uint32_t k = 0; k < a.num_tris; k++) {
        const float *t = a.tris + 16 * (size_t)k;
        float uv[6] = {t[3], t[7], t[11], t[12], t[13], t[14]};
        for (int i = 0; i < 6; i++)
            bad_uv += !(uv[i] >= 0 && uv[i] <= 1);
    }
    CHECK(bad_uv == 0, "%s: %d uvs outside [0,1]", what, bad_uv);
    // The regular pass' affine map (lookup) gives each corner its uv.
    double worst_map = 0;
    for (uint32_t k = 0; k < a.num_tris; k++) {
        const float *t = a.tris + 16 * (size_t)k, *L = a.lookup + 12 * (size_t)k;
        const float uv[3][2] = {{t[3], t[7]}, {t[11], t[12]}, {t[13], t[14]}};
        for (int c = 0; c < 3; c++) {
            double q[3];
            for (int r = 0; r < 3; r++)
                q[r] = (c == 1 ? t[4 + r] : c == 2 ? t[8 + r] : 0);
            double u = L[3] + q[0] * L[4] + q[1] * L[5] + q[2] * L[6],
                   v = L[7] + q[0] * L[8] + q[1] * L[9] + q[2] * L[10];
            double e = fmax(fabs(u - uv[c][0]), fabs(v - uv[c][1])) * a.width; // in texels
            // Only meaningful for triangles with area (degenerate ones map to uv0).
            double e1[3] = {t[4], t[5], t[6]}, e2[3] = {t[8], t[9], t[10]};
            double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                            e1[0] * e2[1] - e1[1] * e2[0]};
            if (sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]) > 1e-10)
                worst_map = fmax(worst_map, e);
        }
    }
    CHECK(worst_map < 0.01, "%s: the affine lookup misses a corner by %.4g texels", what,
          worst_map);
    int bad_pt = 0;
    for (int i = 0; i < a.num_points; i++) {
        const atlas_point *p = &a.points[i];
        bad_pt += !(a.area[(size_t)p->y * a.width + p->x] > 0) || !isfinite(p->pos[0]) ||
                  !isfinite(p->nrm[0]) || p->amesh < 0 || p->amesh >= a.num_meshes;
    }
    CHECK(bad_pt == 0, "%s: %d bad border points", what, bad_pt);
    atlas_free(&a);
}

int main(void) {
    st_scene sc = {0};
    st_err err = {0};
    atlas_opts o = {.size = 256, .max_size = 4096, .gutter = 2, .chart_angle_deg = 30};
    if (!st_scene_parse(cornell, strlen(cornell), "cornell.json", &sc, &err)) {
        CHECK(0, "parse: %s", err.msg);
        return st_test_summary("test_atlas_build");
    }
    for (int size = 64; size <= 2048; size *= 2) {
        char what[64];
        snprintf(what, sizeof what, "cornell %d", size);
        o.size = size;
        check_atlas(what, &sc, o, size);
    }
    // Fixed density: 100 texels/m for 17.44 m^2 needs at least 1744*... texels: 256 or 512.
    o.texels_per_meter = 100;
    check_atlas("cornell 100 texels/m", &sc, o, 0);
    o.texels_per_meter = 0;

    // TEXCOORD_1: give every mesh a trivial per-mesh uv layout in its own cell.
    for (int m = 0; m < sc.num_meshes; m++) {
        st_mesh *me = &sc.meshes[m];
        me->uv1 = malloc(me->num_vertices * 2 * sizeof(float));
        // Quads and box faces: the vertex's corner in a 4x2 grid cell per mesh, faces side by side.
        for (uint32_t v = 0; v < me->num_vertices; v++) {
            int face = (int)(v / 4), corner = (int)(v % 4);
            float cx = (float)(m % 4) / 4, cy = (float)(m / 4) / 2;
            float fx = (float)(face % 3) / 3, fy = (float)(face / 3) / 2;
            float u = (corner == 1 || corner == 2) ? 1.0f : 0.0f, w = corner >= 2 ? 1.0f : 0.0f;
            me->uv1[2 * v] = cx + (fx + (0.05f + 0.9f * u) / 3) / 4;
            me->uv1[2 * v + 1] = cy + (fy + (0.05f + 0.9f * w) / 2) / 2;
        }
    }
    CHECK(atlas_meshes_have_uv1(sc.meshes, sc.num_meshes), "all meshes have uv1");
    o.use_uv1 = true;
    o.size = 128;
    check_atlas("cornell TEXCOORD_1", &sc, o, 128);
    o.use_uv1 = false;
    st_scene_free(&sc);

    if (st_scene_parse(spheres, strlen(spheres), "spheres.json", &sc, &err)) {
        o.size = 1024;
        check_atlas("spheres 1024", &sc, o, 1024);
        o.size = 256;
        check_atlas("spheres 256", &sc, o, 256);
        st_scene_free(&sc);
    } else {
        CHECK(0, "parse: %s", err.msg);
    }

    // Thin and tiny triangles: a sliver 1 mm wide and 2 m long, a 1 mm^2
    // triangle, and a degenerate one, next to a 1 m^2 quad.
    st_mesh m[2];
    const float c0[3] = {0, 0, 0}, u0[3] = {1, 0, 0}, v0[3] = {0, 0, 1};
    st_mesh_quad(&m[0], c0, u0, v0);
    st_mesh_quad(&m[1], c0, u0, v0);
    float pos[] = {0, 1, 0,      2, 1, 0, 0, 1.001f, 0, 5, 5, 5, 5.001f, 5,
                   5, 5, 5.001f, 5, 7, 7, 7, 7,      7, 7, 7, 7, 7};
    float nrm[27];
    for (int i = 0; i < 9; i++)
        nrm[3 * i] = 0, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 1;
    memcpy(m[1].positions, pos, 0); // keep the quad's arrays; replace below
    free(m[1].positions);
    free(m[1].normals);
    free(m[1].indices);
    m[1].positions = malloc(sizeof pos);
    m[1].normals = malloc(sizeof nrm);
    m[1].indices = malloc(9 * sizeof(uint32_t));
    memcpy(m[1].positions, pos, sizeof pos);
    memcpy(m[1].normals, nrm, sizeof nrm);
    for (uint32_t i = 0; i < 9; i++)
        m[1].indices[i] = i;
    m[1].num_vertices = 9;
    m[1].num_triangles = 3;
    o.size = 64;
    atlas a;
    if (atlas_build(&a, m, 2, &o, &err)) {
        double tri_area = 0.5 * 2 * 0.001 + 0.5 * 0.001 * 0.001;
        CHECK(a.uncovered_tris == 0, "thin/tiny triangles each own a texel (%ld uncovered)",
              a.uncovered_tris);
        CHECK_REL(a.texel_area_sum, 1.0 + tri_area, 1e-4, 0);
        CHECK(a.overlap_texels == 0, "thin: %ld overlaps", a.overlap_texels);
        atlas_free(&a);
    } else {
        CHECK(0, "thin: %s", err.msg);
    }
    st_mesh_free(&m[0]);
    st_mesh_free(&m[1]);

    // Too many charts for the atlas: a clear input error.
    if (st_scene_parse(spheres, strlen(spheres), "spheres.json", &sc, &err)) {
        o.size = 64;
        o.chart_angle_deg = 1;
        CHECK(!atlas_build(&a, sc.meshes, sc.num_meshes, &o, &err) && err.kind == ST_ERR_INPUT &&
                  strstr(err.msg, "atlas_size"),
              "overfull atlas fails with an input error: %s", err.msg);
        st_scene_free(&sc);
    }
    return st_test_summary("test_atlas_build");
}
