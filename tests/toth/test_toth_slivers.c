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
//  - a step from the first shadow to past the second (toth_vis_probed): one
//    boundary search per step found one of its three boundaries and lost the
//    gap (godrays_window 320x240 at 24 steps: 3-4% of a pixel's light).
// The map is left unbound with a bias of 1.5 times the light distance: it
// calls every point lit, only thanks to the bias, so exact_edges traces each
// lookup (shadow_map/visibility.glsl's ambiguity rule), and the probes (map
// only) see nothing.
#include "st_test.h" // first: it defines _GNU_SOURCE
#include "st_gl.h"
#include "st_shader.h"
#include "glsl_program.h"
#include <math.h>

static GLuint build(const char *file, const char *after) {
    char *src = toth_glsl_source(file);
    if (!src) return 0;
    size_t n = strlen(src) + strlen(after) + 64;
    char *full = malloc(n);
    snprintf(full, n, "%s\n#line 1 31\n%s\n", src, after);
    free(src);
    return toth_glsl_program(full, file);
}

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
// (modules/common/st_bvh.h's layout: node = (min, first), (max, count);
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
    glCreateBuffers(2, bufs);
    glNamedBufferData(bufs[0], sizeof nodes, nodes, GL_STATIC_DRAW);
    glNamedBufferData(bufs[1], sizeof tris, tris, GL_STATIC_DRAW);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, bufs[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, bufs[1]);
}

// The light, the view ray o + t (1, 0, 0), and its equi-angular angle at t
// (toth_eq_frame: the angle from the ray start seen from the light).
static const double P[3] = {0.0, 5.0, 0.0}, O[3] = {-5.0, 1.0, 0.2};

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
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    CHECK(ctx != NULL, "headless context: %s", err.msg);
    if (!ctx) return st_test_summary("toth_slivers");
    GLuint prog = build("toth/visibility.glsl", MAIN);
    if (!prog) {
        st_context_destroy(ctx);
        return st_test_summary("toth_slivers");
    }
    GLuint bvh[2], out;
    bind_squares(bvh);
    glCreateBuffers(1, &out);
    glNamedBufferData(out, 16, NULL, GL_DYNAMIC_COPY);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, out);
    glUseProgram(prog);
    glUniform1f(glGetUniformLocation(prog, "st_fov_y"), 1.0f);
    glUniform2f(glGetUniformLocation(prog, "st_resolution"), 1000.0f, 1000.0f);
    glUniform1f(glGetUniformLocation(prog, "st_near"), 0.1f);
    glUniform1i(glGetUniformLocation(prog, "st_phase_kind"), 0);
    glUniform1i(glGetUniformLocation(prog, "st_num_lights"), 1);
    glUniform1i(glGetUniformLocation(prog, "st_light_type[0]"), 0);
    glUniform3f(glGetUniformLocation(prog, "st_light_pos[0]"), (float)P[0], (float)P[1],
                (float)P[2]);
    // texel(d) = 2 d / 512: the bias 384 texels is 1.5 d (see the top).
    glUniform1f(glGetUniformLocation(prog, "st_shadow_res"), 512.0f);
    glUniform1f(glGetUniformLocation(prog, "st_shadow_bias"), 384.0f);
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
    glDeleteProgram(prog);
    st_context_destroy(ctx);
    return st_test_summary("toth_slivers");
}
