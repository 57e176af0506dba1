// The reference's shadows against an exact point-in-shadow test at the pixel
// centres (issue 34): scenes/godrays_hidden_hole.json at 512 x 512, direct
// light with the point filter. For every pixel the oracle intersects the view
// ray and the shadow segment to the light with every triangle in double
// precision (Moller-Trumbore, brute force, the seen triangle left out of its
// own shadow test: a plane cannot shadow itself), and says lit or dark; the
// reference must say the same. Pixel (100, 297) is a floor point whose exact
// shadow ray passes the hole's edge 1.3e-5 m inside the hole: the former
// offset (1e-5 x the scene's diagonal along the normal) made it dark.
#include "ref_test_util.h"
#include "st_vec3.h"

typedef struct {
    const st_ref_geometry *g;
    int mesh, tri; // the triangle left out (-1: none)
} exact_scene;

static const double *vtx(const st_ref_geometry *g, int m, uint32_t t, int k) {
    return g->pos[m] + 3 * g->desc->meshes[m].indices[3 * t + k];
}

// Moller-Trumbore in double: the ray parameter of the hit, or INFINITY.
static double tri_hit(const double o[3], const double d[3], const double *a, const double *b,
                      const double *c) {
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, p[3], q[3];
    st_cross3(p, d, e2);
    double det = st_dot3(e1, p);
    if (det == 0.0) return INFINITY;
    double s[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
    double u = st_dot3(s, p) / det;
    if (u < 0.0 || u > 1.0) return INFINITY;
    st_cross3(q, s, e1);
    double v = st_dot3(d, q) / det;
    if (v < 0.0 || u + v > 1.0) return INFINITY;
    return st_dot3(e2, q) / det;
}

// The nearest triangle along o + t d, t in (tmin, tmax): its t, *m and *t_idx.
static double nearest(const exact_scene *x, const double o[3], const double d[3], double tmin,
                      double tmax, int *m, int *t_idx) {
    double best = INFINITY;
    for (int k = 0; k < x->g->num_meshes; k++)
        for (uint32_t t = 0; t < x->g->desc->meshes[k].num_triangles; t++) {
            if (k == x->mesh && (int)t == x->tri) continue;
            double h = tri_hit(o, d, vtx(x->g, k, t, 0), vtx(x->g, k, t, 1), vtx(x->g, k, t, 2));
            if (h > tmin && h < tmax && h < best) best = h, *m = k, *t_idx = (int)t;
        }
    return best;
}

// Lit or dark by the exact test at pixel (i, j)'s centre; -1 where the
// view ray sees no surface that faces the light.
static int exact_lit(const st_ref_geometry *g, const st_scene *sc, int i, int j) {
    const st_camera_desc *cd = &sc->camera;
    double f[3], up[3], r[3], u[3], dir[3], pos[3];
    for (int k = 0; k < 3; k++)
        pos[k] = cd->position[k], f[k] = (double)cd->target[k] - pos[k], up[k] = cd->up[k];
    st_cross3(r, f, up), st_normalize3(f), st_normalize3(r), st_cross3(u, r, f);
    double th = tan(0.5 * cd->fov_y * ST_PI / 180.0), asp = (double)sc->width / sc->height;
    double x = (2.0 * (i + 0.5) / sc->width - 1.0) * th * asp;
    double y = (1.0 - 2.0 * (j + 0.5) / sc->height) * th;
    for (int k = 0; k < 3; k++)
        dir[k] = f[k] + x * r[k] + y * u[k];
    st_normalize3(dir);
    exact_scene ex = {g, -1, -1};
    int m = -1, t = -1;
    double hit = nearest(&ex, pos, dir, 0.0, INFINITY, &m, &t);
    if (!isfinite(hit)) return -1;
    const double *ng = g->ng[m] + 3 * t;
    double p[3], L[3];
    for (int k = 0; k < 3; k++)
        p[k] = pos[k] + hit * dir[k], L[k] = sc->lights[0].position[k] - p[k];
    if (st_dot3(ng, dir) >= 0.0 || st_dot3(ng, L) <= 0.0) return -1; // back face or unlit side
    ex.mesh = m, ex.tri = t;
    int m2, t2;
    return isfinite(nearest(&ex, p, L, 0.0, 1.0, &m2, &t2)) ? 0 : 1;
}

int main(void) {
    st_scene sc;
    st_err err = {0};
    const char *path = ST_TEST_SOURCE_DIR "/scenes/godrays_hidden_hole.json";
    if (!st_scene_load(path, &sc, &err)) {
        CHECK(0, "%s: %s", path, err.msg);
        return st_test_summary("reference_shadow_exact");
    }
    CHECK(sc.width == 512 && sc.height == 512 && sc.num_lights == 1, "scene %dx%d, %d lights",
          sc.width, sc.height, sc.num_lights);
    st_ref_options o = {.spp = 1, .aov = ST_REF_DIRECT, .filter = ST_FILTER_POINT};
    st_image img = {0};
    st_ref_geometry g;
    bool ok = st_ref_render(&sc, &o, &img, &err) && st_ref_geometry_build(&g, &sc, &err);
    CHECK(ok, "%s", err.msg);
    if (!ok) return st_test_summary("reference_shadow_exact");
    int wrong = 0, lit = 0, dark = 0;
    for (int j = 0; j < sc.height; j++)
        for (int i = 0; i < sc.width; i++) {
            int want = exact_lit(&g, &sc, i, j);
            if (want < 0) continue;
            int got = st_image_px(&img, i, j)[0] > 0.0f;
            want ? lit++ : dark++;
            if (got != want && wrong++ < 10)
                fprintf(stderr, "  pixel (%d, %d): reference %s, exact %s\n", i, j,
                        got ? "lit" : "dark", want ? "lit" : "dark");
        }
    printf("  %d lit and %d dark pixel centres, %d disagree\n", lit, dark, wrong);
    CHECK(lit > 10000 && dark > 10000, "%d lit, %d dark", lit, dark);
    CHECK(wrong == 0, "%d pixel centres lit or dark against the exact test", wrong);
    CHECK(exact_lit(&g, &sc, 100, 297) == 1 && st_image_px(&img, 100, 297)[0] > 0.5f,
          "pixel (100, 297): %g, exact: lit", st_image_px(&img, 100, 297)[0]);
    st_ref_geometry_free(&g);
    st_image_free(&img);
    st_scene_free(&sc);
    return st_test_summary("reference_shadow_exact");
}
