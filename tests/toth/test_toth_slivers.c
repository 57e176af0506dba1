// Steps that hold more than one shadow boundary (shaders/toth/visibility.glsl),
// evaluated on the GPU by a compute shader built from the real shader files,
// with exact_edges' rays deciding every lookup: two squares side by side
// (two triangles each, sharing a diagonal) under a point light cast two
// shadows onto a view ray with a lit gap between them, as a window's mullion
// does. The lit part of the step must be the closed form's (the angles the
// gap and the stretch past the second shadow subtend) to 1e-4 rad:
//  - a step whose ends both lie in shadow, one in each square's, with its
//    midpoint in the second shadow (toth_vis_step_exact): the midpoint alone
//    called the whole step shadowed and lost the gap;
//  - a step from the first shadow to past the second (toth_vis_probed), whose
//    probes see the second shadow: one boundary search per step found one
//    of its three boundaries and lost the gap (godrays_window 320x240 at 24
//    steps: 3-4% of a pixel's light).
// The shadow cube is written here from the squares (the distance to them
// per texel, 128 x 128 per face): the probes see both shadows, lookups near
// an edge are undecided and take exact rays (shadow_map.refine's rule).
#include "st_test.h" // first: it defines _GNU_SOURCE
#include "st_gl.h"
#include "st_shader.h"
#include "glsl_program.h"
#include <math.h>

// Isotropic phase, no extinction: the integrand is 1 / (4 pi) everywhere, so
// the lit part times 4 pi is the lit angle.
static const char *MAIN =
    "layout(local_size_x = 1) in;\n"
    "layout(std430, binding = 0) writeonly buffer Out { float res[]; };\n"
    "uniform vec3 ro, rd;\n"
    "uniform float rs, ra, rb, rva, rvb;\n"
    "uniform int mode;\n"
    "void main() {\n"
    "    toth_eq e = toth_light_frame(ro, rd, rs, 0);\n"
    "    vec3 w = vec3((rb - ra) / 12.566370614359172);\n"
    "    vec3 lit = mode == 0\n"
    "        ? toth_vis_step_exact(0, e, ro, rd, ra, rb, rva, rvb, true, true, 4, w, vec3(0.0))\n"
    "        : toth_vis_probed(true, 0, e, ro, rd, ra, rb, rva, rvb, true, true, 4, w, "
    "vec3(0.0));\n"
    "    res[0] = lit.x * 12.566370614359172;\n"
    "}\n";

// Two squares at y = 3, z in [-1, 1]: x in [-1.5, -0.3] and [0.2, 2.5],
// each as two triangles sharing its diagonal, in one BVH leaf
// (framework/st_bvh.h's layout: node = (min, first), (max, count);
// triangle = v0, e1, e2).
static void bind_squares(GLuint bufs[2]) {
    float nodes[8] = {-1.5f, 3, -1, 0, 2.5f, 3, 1, 0};
    int first = 0, count = 4;
    memcpy(&nodes[3], &first, 4);
    memcpy(&nodes[7], &count, 4);
    const float sq[2][2] = {{-1.5f, -0.3f}, {0.2f, 2.5f}};
    float tris[48];
    for (int s = 0; s < 2; s++) {
        float x0 = sq[s][0], wx = sq[s][1] - sq[s][0];
        float t[24] = {
            x0, 3, -1, 0, wx, 0, 0, 0, wx, 0, 2, 0, // (x0,-1) (x1,-1) (x1,1)
            x0, 3, -1, 0, wx, 0, 2, 0, 0,  0, 2, 0, // (x0,-1) (x1,1) (x0,1)
        };
        memcpy(&tris[24 * s], t, sizeof t);
    }
    toth_glsl_bind_bvh(bufs, nodes, sizeof nodes, tris, sizeof tris);
}

// The light, the view ray o + t (1, 0, 0), and its equi-angular angle at t
// (toth_eq_frame: the angle from the ray start seen from the light).
static const double P[3] = {0.0, 5.0, 0.0}, O[3] = {-5.0, 1.0, 0.2};

// The light's shadow cube (a cube map array of one layer): per texel the
// distance from the light to the squares along its centre direction (GL's
// face orientations), far where it misses them.
enum { FACE = 128 };
static GLuint shadow_cube(void) {
    float *d = malloc(sizeof(float) * FACE * FACE * 6);
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < FACE; j++)
            for (int i = 0; i < FACE; i++) {
                double sc = 2.0 * (i + 0.5) / FACE - 1.0, tc = 2.0 * (j + 0.5) / FACE - 1.0;
                double v[6][3] = {{1, -tc, -sc}, {-1, -tc, sc}, {sc, 1, tc},
                                  {sc, -1, -tc}, {sc, -tc, 1},  {-sc, -tc, -1}};
                double *r = v[f], n = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
                double dist = 1e9;
                if (r[1] < 0) {
                    double t = (3.0 - P[1]) / (r[1] / n), x = P[0] + t * r[0] / n,
                           z = P[2] + t * r[2] / n;
                    bool in = fabs(z) <= 1 && ((x >= -1.5 && x <= -0.3) || (x >= 0.2 && x <= 2.5));
                    if (in) dist = t;
                }
                d[(f * FACE + j) * FACE + i] = (float)dist;
            }
    GLuint tex;
    glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &tex);
    glTextureStorage3D(tex, 1, GL_R32F, FACE, FACE, 6);
    glTextureSubImage3D(tex, 0, 0, 0, 0, FACE, FACE, 6, GL_RED, GL_FLOAT, d);
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    free(d);
    return tex;
}

static double angle(double t) {
    double lr[3] = {P[0] - O[0], P[1] - O[1], P[2] - O[2]};
    double h = sqrt(lr[1] * lr[1] + lr[2] * lr[2]), a = -lr[0];
    return atan2(h * t, h * h + a * (t + a));
}

typedef struct {
    const char *what;
    int mode;         // 0: toth_vis_step_exact, 1: toth_vis_probed
    double t0, t1;    // the step along the ray
    double va, vb;    // its ends' visibility
    double lit[2][2]; // the lit stretches inside it (t)
} scase;

int main(void) {
    GLuint prog = 0;
    GLuint out = 0;
    st_context *ctx = toth_glsl_visibility_test(MAIN, &prog, &out);
    if (!ctx) return st_test_summary("toth_slivers");
    GLuint bvh[2], cube = shadow_cube();
    bind_squares(bvh);
    glBindTextureUnit(0, cube);
    glUniform1i(glGetUniformLocation(prog, "st_light_type[0]"), 0);
    glUniform3f(glGetUniformLocation(prog, "st_light_pos[0]"), (float)P[0], (float)P[1],
                (float)P[2]);
    glUniform1i(glGetUniformLocation(prog, "st_shadow_cubes"), 0);
    glUniform1f(glGetUniformLocation(prog, "st_shadow_res"), (float)FACE);
    glUniform1f(glGetUniformLocation(prog, "st_shadow_bias"), 1.5f);
    glUniform1i(glGetUniformLocation(prog, "st_shadow_pcf"), 0);
    glUniform1i(glGetUniformLocation(prog, "st_shadow_refine"), 1);
    glUniform1i(glGetUniformLocation(prog, "st_shadow_suns"), 1); // not the cubes' unit
    glUniform1i(glGetUniformLocation(prog, "toth_exact"), 1);
    glUniform1i(glGetUniformLocation(prog, "toth_probes"), 3);
    glUniform3f(glGetUniformLocation(prog, "ro"), (float)O[0], (float)O[1], (float)O[2]);
    glUniform3f(glGetUniformLocation(prog, "rd"), 1.0f, 0.0f, 0.0f);
    glUniform1f(glGetUniformLocation(prog, "rs"), 12.0f);
    // Along y = 1, z = 0.2 the squares shadow t in [2, 4.4] and [5.4, 10]
    // (twice their x from the light's foot x = 0, offset by 5).
    const scase cases[] = {
        {"both ends shadowed, midpoint in the second shadow",
         0,
         3.0,
         8.5,
         0,
         0,
         {{4.4, 5.4}, {0, 0}}},
        {"from the first shadow to past the second",
         1,
         3.0,
         11.0,
         0,
         1,
         {{4.4, 5.4}, {10.0, 11.0}}},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const scase *k = &cases[c];
        double da = angle(k->t0), db = angle(k->t1), want = 0.0;
        for (int j = 0; j < 2; j++)
            want += angle(k->lit[j][1]) - angle(k->lit[j][0]);
        glUniform1i(glGetUniformLocation(prog, "mode"), k->mode);
        glUniform1f(glGetUniformLocation(prog, "ra"), (float)da);
        glUniform1f(glGetUniformLocation(prog, "rb"), (float)db);
        glUniform1f(glGetUniformLocation(prog, "rva"), (float)k->va);
        glUniform1f(glGetUniformLocation(prog, "rvb"), (float)k->vb);
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        float lit = -1;
        glGetNamedBufferSubData(out, 0, sizeof lit, &lit);
        CHECK(fabs(lit - want) < 1e-4, "%s: lit %.6f rad of the step's %.4f, closed form %.6f",
              k->what, lit, db - da, want);
        printf("%s: lit %.6f rad, closed form %.6f\n", k->what, lit, want);
    }
    CHECK(glGetError() == GL_NO_ERROR, "no GL error");
    glDeleteBuffers(2, bvh);
    glDeleteBuffers(1, &out);
    glDeleteTextures(1, &cube);
    glDeleteProgram(prog);
    st_context_destroy(ctx);
    return st_test_summary("toth_slivers");
}
