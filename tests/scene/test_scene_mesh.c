// Procedural meshes: quad normal and winding, box normals (outward/inward,
// checked against the box centre), areas against the analytic values,
// sphere counts, normals and area.
#include "st_test.h"
#include "st_scene.h"

static void sub(const float *a, const float *b, double *o) {
    for (int k = 0; k < 3; k++)
        o[k] = (double)a[k] - b[k];
}
static void cross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Geometric (winding) normal of triangle t, unnormalized: |n| = 2 * area.
static void tri_normal(const st_mesh *m, uint32_t t, double *n) {
    const uint32_t *i = m->indices + 3 * t;
    double e1[3], e2[3];
    sub(m->positions + 3 * i[1], m->positions + 3 * i[0], e1);
    sub(m->positions + 3 * i[2], m->positions + 3 * i[0], e2);
    cross(e1, e2, n);
}

static double area(const st_mesh *m) {
    double a = 0, n[3];
    for (uint32_t t = 0; t < m->num_triangles; t++) {
        tri_normal(m, t, n);
        a += 0.5 * sqrt(dot(n, n));
    }
    return a;
}

// Every triangle winds CCW seen from the side its vertex normals point to.
static bool winding_matches_normals(const st_mesh *m) {
    for (uint32_t t = 0; t < m->num_triangles; t++) {
        double n[3], vn[3];
        tri_normal(m, t, n);
        for (int k = 0; k < 3; k++)
            vn[k] = m->normals[3 * m->indices[3 * t] + k];
        if (!(dot(n, vn) > 0)) return false;
    }
    return true;
}

static void test_quad(void) {
    const float c[3] = {1, 2, 3}, u[3] = {2, 0, 0}, v[3] = {0.5f, 0, -3};
    st_mesh m;
    st_mesh_quad(&m, c, u, v);
    CHECK(m.num_triangles == 2 && m.num_vertices == 4, "quad counts %u %u", m.num_triangles,
          m.num_vertices);
    // u x v = (0*-3 - 0*0, 0*0.5 - 2*-3, 0) = (0, 6, 0) -> +y.
    for (uint32_t i = 0; i < 4; i++) {
        CHECK_REL(m.normals[3 * i + 0], 0.0, 0, 1e-7);
        CHECK_REL(m.normals[3 * i + 1], 1.0, 0, 1e-7);
        CHECK_REL(m.normals[3 * i + 2], 0.0, 0, 1e-7);
    }
    CHECK(winding_matches_normals(&m), "quad winds CCW seen from its normal");
    CHECK_REL(area(&m), 6.0, 1e-6, 0); // |u x v|
    CHECK(m.uv1 == NULL, "quad has no uv1");
    CHECK(m.model[0] == 1 && m.model[5] == 1 && m.model[10] == 1 && m.model[15] == 1 &&
              m.model[12] == 0,
          "identity model");
    CHECK(m.positions[0] == 1 && m.positions[1] == 2 && m.positions[2] == 3,
          "first vertex is the corner");
    // An oblique quad: normal is normalize(u x v) = (1,1,1)/sqrt(3) for u=(1,-1,0), v=(0,1,-1).
    const float u2[3] = {1, -1, 0}, v2[3] = {0, 1, -1};
    st_mesh q;
    st_mesh_quad(&q, c, u2, v2);
    for (int k = 0; k < 3; k++)
        CHECK_REL(q.normals[k], 1 / sqrt(3.0), 1e-6, 0);
    CHECK(winding_matches_normals(&q), "oblique quad winding");
    st_mesh_free(&q);
    st_mesh_free(&m);
    CHECK(m.positions == NULL && m.num_triangles == 0, "free zeroes");
}

static void test_box(bool inward) {
    const float mn[3] = {-1, 0, -2}, mx[3] = {2, 1, 1}, centre[3] = {0.5f, 0.5f, -0.5f};
    st_mesh m;
    st_mesh_box(&m, mn, mx, inward);
    CHECK(m.num_triangles == 12 && m.num_vertices == 24, "box counts");
    CHECK(winding_matches_normals(&m), "box winding (inward %d)", inward);
    // Each vertex normal is an axis and points away from (or toward) the centre.
    int per_axis[6] = {0};
    for (uint32_t i = 0; i < m.num_vertices; i++) {
        double d[3], n[3] = {m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]};
        sub(m.positions + 3 * i, centre, d);
        CHECK_REL(dot(n, n), 1.0, 1e-12, 0);
        CHECK(inward ? dot(n, d) < 0 : dot(n, d) > 0, "vertex %u normal direction (inward %d)", i,
              inward);
        for (int k = 0; k < 3; k++)
            if (fabs(n[k]) == 1) per_axis[2 * k + (n[k] > 0)]++;
    }
    for (int a = 0; a < 6; a++)
        CHECK(per_axis[a] == 4, "4 vertices per face direction, got %d", per_axis[a]);
    // 2 (3*1 + 1*3 + 3*3) = 30.
    CHECK_REL(area(&m), 30.0, 1e-6, 0);
    st_mesh_free(&m);
}

static void test_sphere(void) {
    const float c[3] = {1, -2, 0.5f};
    const float r = 2;
    st_mesh m;
    st_mesh_sphere(&m, c, r, 64, 128);
    CHECK(m.num_triangles == 2 * 128 * 63, "sphere triangles %u", m.num_triangles);
    CHECK(m.num_vertices == 65 * 129, "sphere vertices %u", m.num_vertices);
    CHECK(winding_matches_normals(&m), "sphere winds CCW from outside");
    double worst = 0;
    for (uint32_t i = 0; i < m.num_vertices; i++) {
        double d[3], n[3] = {m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]};
        sub(m.positions + 3 * i, c, d);
        worst = fmax(worst, fabs(sqrt(dot(d, d)) - r));
        CHECK(dot(n, d) > 0 && fabs(dot(n, n) - 1) < 1e-6, "vertex %u normal outward unit", i);
    }
    CHECK(worst < 1e-5, "vertices on the sphere, worst %g", worst);
    // Inscribed polyhedron: area slightly below 4 pi r^2 (relative error ~ 1e-3 here).
    double a = area(&m), exact = 4 * 3.14159265358979 * r * r;
    CHECK(a < exact && a > exact * 0.998, "sphere area %g vs %g", a, exact);
    for (uint32_t t = 0; t < m.num_triangles; t++) {
        double n[3];
        tri_normal(&m, t, n);
        if (!(dot(n, n) > 0)) {
            CHECK(false, "degenerate triangle %u", t);
            break;
        }
    }
    st_mesh_free(&m);
    // The 1M-triangle stress sphere of scenes/stress.json.
    st_mesh_sphere(&m, c, r, 128, 256);
    CHECK(m.num_triangles == 65024, "stress sphere triangles %u", m.num_triangles);
    st_mesh_free(&m);
}

static void test_scene_arrays(void) {
    st_scene s = {0};
    st_err e = {0};
    const float c[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 1, 0};
    for (int i = 0; i < 100; i++) {
        st_mesh m;
        st_mesh_quad(&m, c, u, v);
        CHECK(st_scene_add_mesh(&s, &m, &e), "add mesh %d: %s", i, e.msg);
        st_light_desc l = {{0, (float)i, 0}, {1, 1, 1}};
        CHECK(st_scene_add_light(&s, &l, &e), "add light");
    }
    CHECK(s.num_meshes == 100 && st_scene_triangle_count(&s) == 200, "100 quads");
    CHECK(s.num_lights == 100 && s.lights[99].position[1] == 99, "100 lights");
    st_scene_free(&s);
    CHECK(s.num_meshes == 0 && s.meshes == NULL, "freed");
}

int main(void) {
    test_quad();
    test_box(false);
    test_box(true);
    test_sphere();
    test_scene_arrays();
    return st_test_summary("test_scene_mesh");
}
