// The origin offset of the reference's shadow rays (st_ref_offset): a surface
// point whose shadow ray passes a blocker's edge a few 1e-5 m on the open
// side is lit, one as far on the other side is dark, and large flat surfaces
// lit at grazing angles show no self-shadowing, each against the closed form
// rho/pi I cos/d^2. The former offset (1e-5 x the scene's diagonal along the
// normal, 2.8e-4 m in the first scene) moved the ray ~1e-4 m toward the
// blocker and darkened the lit points.
#include "ref_test_util.h"

// The scene's geometry; on failure the test fails and the scene is freed.
static bool build(st_ref_geometry *g, st_scene *s) {
    st_err err = {0};
    if (st_ref_geometry_build(g, s, &err)) return true;
    CHECK(0, "geometry: %s", err.msg);
    st_scene_free(s);
    return false;
}

// Direct light at the floor point below (x, z), seen from above.
static double direct_at(const st_ref_geometry *g, double x, double z, double p_out[3]) {
    const double o[3] = {x, 1.0, z}, d[3] = {0, -1, 0};
    st_ref_surface s = st_ref_intersect(g, o, d, 0.0, INFINITY);
    p_out[0] = p_out[1] = p_out[2] = NAN;
    if (!s.hit) return NAN;
    memcpy(p_out, s.p, sizeof s.p);
    double out[3];
    st_ref_direct(g, &s, NULL, out);
    return out[0];
}

static double closed_form(const double p[3], const double light[3], double I, double rho) {
    double L[3] = {light[0] - p[0], light[1] - p[1], light[2] - p[2]};
    double d2 = L[0] * L[0] + L[1] * L[1] + L[2] * L[2];
    return rho / ST_PI * I * (L[1] / sqrt(d2)) / d2; // floor normal +y
}

// A 20 m floor, a blocker plate at y = 2 over x < 0.5, a light at (2, 4, 0).
// The shadow ray from (x, 0, 0) crosses y = 2 at (x + 2) / 2: the floor point
// x = -1 + 2 s passes the plate's edge at s (> 0: through the gap).
static void shadow_edge(void) {
    const double cam[3] = {0, 3, 3}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0}, light[3] = {2, 4, 0};
    const double I = 5.0, rho = 0.5;
    st_scene s;
    scene_init(&s, 16, 16, cam, tgt, up, 60, 100);
    add_light(&s, light, I);
    add_quad(&s, (double[]){-10, 0, -10}, (double[]){0, 0, 20}, (double[]){20, 0, 0}, rho, 0);
    add_quad(&s, (double[]){-10, 2, -10}, (double[]){0, 0, 20}, (double[]){10.5, 0, 0}, 0.5, 0);
    st_ref_geometry g;
    if (!build(&g, &s)) return;
    const double sides[] = {2e-5, 5e-5, 1e-3, -2e-5, -5e-5, -1e-3};
    for (int k = 0; k < 6; k++) {
        for (int q = 0; q < 5; q++) { // a few z: different triangles, different rounding
            double z = -3.0 + 1.5 * q, p[3];
            double got = direct_at(&g, -1.0 + 2.0 * sides[k], z, p);
            double cross = (p[0] + 2.0) / 2.0 - 0.5; // where the exact ray passes the edge
            double want = cross > 0 ? closed_form(p, light, I, rho) : 0.0;
            printf("  edge %+.0e m (z %.1f): %.9g, closed form %.9g\n", cross, z, got, want);
            CHECK(fabs(got - want) <= 1e-9 * fabs(want),
                  "floor point %.0e m from the shadow's edge (z %.1f): %.9g, expected %.9g", cross,
                  z, got, want);
        }
    }
    st_ref_geometry_free(&g);
    st_scene_free(&s);
}

// No self-shadowing: a 2 km floor (two triangles) under a light 10 m up,
// points out to 900 m (coordinates with float ulps of 6e-5, light 0.6 degrees
// above the horizon) and on the diagonal the triangles share. Seen from its
// front, and seen from the back of a double-sided floor facing down: there
// the filter's back-side rule does not drop a self-hit, only the offset
// avoids it.
static void grazing_plane(bool back) {
    const double cam[3] = {0, 3, 3}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0}, light[3] = {3, 10, -2};
    const double I = 100.0, rho = 0.5;
    st_scene s;
    scene_init(&s, 16, 16, cam, tgt, up, 60, 100);
    add_light(&s, light, I);
    const double c[3] = {-1000, 0, -1000}, u[3] = {0, 0, 2000}, v[3] = {2000, 0, 0};
    st_mesh *m = back ? add_quad(&s, c, v, u, rho, 0) : add_quad(&s, c, u, v, rho, 0);
    m->double_sided = back;
    st_ref_geometry g;
    if (!build(&g, &s)) return;
    int bad = 0, n = 0;
    for (int a = -9; a <= 9; a++)
        for (int b = 0; b < 3; b++) {
            // b = 0, 1: both diagonals of the quad (one is the shared edge)
            double x = 100.0 * a + 0.37, z = b == 0 ? x : b == 1 ? -x : 31.0 * a - 7.3, p[3];
            double got = direct_at(&g, x, z, p), want = closed_form(p, light, I, rho);
            n++;
            if (!(fabs(got - want) <= 1e-9 * want)) {
                bad++;
                fprintf(stderr, "  (%.2f, %.2f): %.9g, expected %.9g\n", x, z, got, want);
            }
        }
    printf("  grazing plane (%s): %d of %d points self-shadowed or wrong\n",
           back ? "back, double-sided" : "front", bad, n);
    CHECK(bad == 0, "%s: %d of %d floor points differ from the closed form",
          back ? "back, double-sided" : "front", bad, n);
    st_ref_geometry_free(&g);
    st_scene_free(&s);
}

int main(void) {
    shadow_edge();
    grazing_plane(false);
    grazing_plane(true);
    return st_test_summary("reference_offset");
}
