// exact_edges' shadow boundaries (shaders/toth/visibility.glsl,
// toth_exact_boundary) evaluated on the GPU by a compute shader built from the
// real shader files: a view ray crosses the shadow of a square occluder (two
// triangles sharing a diagonal) cast by a point light and by a sun, where the
// boundary lies in closed form on the plane through the light (a sun: its
// direction) and the square's edge. The located boundary must lie within
// 1/16384 of the step of it, 32x tighter than the 8 exact halvings the search
// replaced ((b - a) / 512 at worst, 0.0012 of the step at the positions here),
// also where the shadowed end sits behind the other triangle, whose shadow
// ends at the diagonal first.
#include "st_test.h" // first: it defines _GNU_SOURCE
#include "st_gl.h"
#include "st_shader.h"
#include "glsl_program.h"
#include <math.h>

// Isotropic phase, no extinction: the integrand is 1 / (4 pi) everywhere, so
// the lit part times 4 pi is the lit length in the step's parameter.
static const char *MAIN =
    "layout(local_size_x = 1) in;\n"
    "layout(std430, binding = 0) writeonly buffer Out { float res[]; };\n"
    "uniform vec3 ro, rd;\n"
    "uniform float rs, ra, rb, rva;\n"
    "void main() {\n"
    "    toth_eq e = toth_light_frame(ro, rd, rs, 0);\n"
    "    vec3 lit = toth_exact_boundary(0, e, ro, rd, ra, rb, rva, 8, -2, vec3(0.0));\n"
    "    res[0] = lit.x * 12.566370614359172;\n"
    "}\n";

static void uni3(GLuint p, const char *name, const double *v) {
    glUniform3f(glGetUniformLocation(p, name), (float)v[0], (float)v[1], (float)v[2]);
}

static void uni1(GLuint p, const char *name, double v) {
    glUniform1f(glGetUniformLocation(p, name), (float)v);
}

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

// The square |x|, |z| <= 1 at y = 3 as two triangles sharing the diagonal
// x = z, in one BVH leaf (framework/st_bvh.h's layout: node = (min,
// first), (max, count); triangle = v0, e1, e2).
static void bind_square(GLuint bufs[2]) {
    float nodes[8] = {-1, 3, -1, 0, 1, 3, 1, 0};
    int first = 0, count = 2;
    memcpy(&nodes[3], &first, 4);
    memcpy(&nodes[7], &count, 4);
    float tris[24] = {
        -1, 3, -1, 0, 2, 0, 0, 0, 2, 0, 2, 0, // (-1,-1) (1,-1) (1,1): x >= z
        -1, 3, -1, 0, 2, 0, 2, 0, 0, 0, 2, 0, // (-1,-1) (1,1) (-1,1): x <= z
    };
    toth_glsl_bind_bvh(bufs, nodes, sizeof nodes, tris, sizeof tris);
}

typedef struct {
    const char *what;
    int sun;
    double t0, t1; // the step along the ray (t); its angles follow
    int lit_first; // lit at t0 (else at t1)
    double edge_x; // the square's edge whose shadow bounds the step: x = edge_x
} bcase;

int main(void) {
    GLuint prog = 0;
    GLuint out = 0;
    st_context *ctx = toth_glsl_visibility_test(MAIN, &prog, &out);
    if (!ctx) return st_test_summary("toth_boundary");
    GLuint bvh[2];
    bind_square(bvh);
    // A shadow map that would call every point lit (a huge bias, no map
    // bound), should anything ask it: every verdict comes from the BVH.
    glUniform1f(glGetUniformLocation(prog, "st_shadow_res"), 512.0f);
    glUniform1f(glGetUniformLocation(prog, "st_shadow_bias"), 1e9f);
    glUniform1i(glGetUniformLocation(prog, "st_shadow_sun_slot[0]"), -1);
    glUniform1i(glGetUniformLocation(prog, "st_shadow_suns"), 1); // not the cubes' unit
    const double P[3] = {0.3, 5.0, 0.1}, L[3] = {0.0, 1.0, 0.0};  // light; toward the sun
    const double O[3] = {-4.0, 1.0, 0.2}, D[3] = {1.0, 0.0, 0.0}, S = 12.0;
    // Along y = 1, z = 0.2 the square shadows t in [1.7, 5.7] from the point
    // light and [3, 5] from the sun; the diagonal's shadow crosses the ray at
    // t = 4 and 4.2.
    const bcase cases[] = {
        {"point light, entering the shadow", 0, 1.2, 2.4, 1, -1.0},
        {"point light, leaving it behind the other triangle", 0, 3.5, 6.6, 0, 1.0},
        {"sun, entering the shadow", 1, 2.6, 3.3, 1, -1.0},
        {"sun, leaving it behind the other triangle", 1, 3.6, 5.4, 0, 1.0},
    };
    uni3(prog, "ro", O);
    uni3(prog, "rd", D);
    uni1(prog, "rs", S);
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const bcase *k = &cases[c];
        glUniform1i(glGetUniformLocation(prog, "st_light_type[0]"), k->sun ? 1 : 0);
        double travel[3] = {-L[0], -L[1], -L[2]}, shape[3] = {0.0, 0.0, 100.0};
        uni3(prog, "st_light_dir[0]", travel);
        uni3(prog, "st_light_shape[0]", shape);
        uni3(prog, "st_light_pos[0]", P);
        // The boundary: where the ray meets the plane through the edge
        // (x = edge_x, y = 3, z free) and the light (a sun: its direction).
        double p0[3] = {k->edge_x, 3.0, -1.0}, p1[3] = {k->edge_x, 3.0, 1.0}, m[3];
        if (k->sun) {
            double ed[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
            cross3(ed, L, m);
        } else {
            double u[3] = {p0[0] - P[0], p0[1] - P[1], p0[2] - P[2]};
            double v[3] = {p1[0] - P[0], p1[1] - P[1], p1[2] - P[2]};
            cross3(u, v, m);
        }
        double rel[3] = {p0[0] - O[0], p0[1] - O[1], p0[2] - O[2]};
        double tb = dot3(m, rel) / dot3(m, D);
        // Angles: a sun's parameter is t; a point light's is the
        // equi-angular angle from the ray start (toth_eq_frame).
        double h = 0.0, a = 0.0;
        if (!k->sun) {
            double lr[3] = {P[0] - O[0], P[1] - O[1], P[2] - O[2]}, cx[3];
            cross3(lr, D, cx);
            h = sqrt(dot3(cx, cx));
            a = -dot3(lr, D);
        }
#define ANGLE(t) (k->sun ? (t) : atan2(h * (t), h * h + a * ((t) + a)))
        double da = ANGLE(k->t0), db = ANGLE(k->t1), xb = ANGLE(tb);
        CHECK(da < xb && xb < db, "%s: the boundary (t %.4f) lies inside the step", k->what, tb);
        uni1(prog, "ra", da);
        uni1(prog, "rb", db);
        uni1(prog, "rva", k->lit_first ? 1.0 : 0.0);
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        float lit = 0;
        glGetNamedBufferSubData(out, 0, sizeof lit, &lit);
        double x = k->lit_first ? (double)(float)da + lit : (double)(float)db - lit;
        double err_step = fabs(x - xb) / (db - da);
        CHECK(err_step < 1.0 / 16384.0,
              "%s: boundary at %.7f, closed form %.7f: %.2g of the step (8 halvings: up to %.2g)",
              k->what, x, xb, err_step, 1.0 / 512.0);
        printf("%s: boundary %.2g of the step off\n", k->what, err_step);
#undef ANGLE
    }
    CHECK(glGetError() == GL_NO_ERROR, "no GL error");
    glDeleteBuffers(2, bvh);
    glDeleteBuffers(1, &out);
    glDeleteProgram(prog);
    st_context_destroy(ctx);
    return st_test_summary("toth_boundary");
}
