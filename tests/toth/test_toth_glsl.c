// toth's GLSL evaluated on the GPU by compute shaders built from the real
// shader files (shaders/common/physics.glsl, shaders/toth/march.glsl):
// every phase function integrates to 1 over the sphere, the GLSL mirrors
// framework/st_physics.c, and the march loop integrates a constant source as
// docs/physics.md documents (energy exact at 4 steps, the thesis' Riemann sums
// 3.480 and 0.997), also when its steps are split over interleaved pixels.
#include "st_test.h" // first: it defines _GNU_SOURCE
#include "st_gl.h"
#include "st_physics.h"
#include "st_shader.h"
#include "glsl_program.h"

// Builds a compute program from `file` (preprocessed with its includes), a
// prototype section inserted before the file and a body appended after it.
static GLuint build(const char *file, const char *before, const char *after) {
    char *src = toth_glsl_source(file);
    if (!src) return 0;
    // The preprocessor's output starts with #version and #defines; the
    // included files begin at the first #line.
    char *cut = strstr(src, "#line");
    size_t head = cut ? (size_t)(cut - src) : 0;
    size_t n = strlen(src) + strlen(before) + strlen(after) + 64;
    char *full = malloc(n);
    snprintf(full, n, "%.*s%s\n%s\n#line 1 31\n%s\n", (int)head, src, before, src + head, after);
    free(src);
    return toth_glsl_program(full, file);
}

static GLuint ssbo(size_t bytes, const void *data, GLuint binding) {
    GLuint b;
    glCreateBuffers(1, &b);
    glNamedBufferData(b, (GLsizeiptr)bytes, data, GL_DYNAMIC_COPY);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, b);
    return b;
}

// ---- phase functions --------------------------------------------------------

static const char *PHASE_MAIN =
    "layout(local_size_x = 64) in;\n"
    "layout(std430, binding = 0) readonly buffer In { float mu[]; };\n"
    "layout(std430, binding = 1) writeonly buffer Out { float val[]; };\n"
    "uniform int kind, count;\n"
    "uniform float g;\n"
    "void main() {\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    if (i < uint(count)) val[i] = st_phase(kind, mu[i], g);\n"
    "}\n";

// Nodes for Simpson's rule on [-1, 1], graded toward both ends where HG
// peaks: [-1/2, 1/2], then [1/2, 3/4], ..., [1 - 2^-15, 1 - 2^-16], [1 - 2^-16,
// 1] (and mirrored), 256 intervals each. Every node is a float exactly (the
// last pieces step by 2^-24, the float spacing below 1), so the shader sees
// exactly the cosines the quadrature weights.
enum { PIECE = 256, LEVELS = 16, NPIECES = 2 * LEVELS + 1, NNODES = NPIECES * (PIECE + 1) };

static void phase_nodes(float *mu, double *w) {
    double lo[NPIECES], hi[NPIECES];
    int k = 0;
    lo[k] = -0.5, hi[k] = 0.5, k++;
    for (int l = 1; l <= LEVELS; l++) {
        double a = 1.0 - ldexp(1.0, -l), b = l == LEVELS ? 1.0 : 1.0 - ldexp(1.0, -l - 1);
        lo[k] = a, hi[k] = b, k++;
        lo[k] = -b, hi[k] = -a, k++;
    }
    for (int p = 0; p < NPIECES; p++) {
        double h = (hi[p] - lo[p]) / PIECE;
        for (int i = 0; i <= PIECE; i++) {
            mu[p * (PIECE + 1) + i] = (float)(lo[p] + i * h);
            w[p * (PIECE + 1) + i] = h / 3.0 * (i == 0 || i == PIECE ? 1 : (i & 1) ? 4 : 2);
        }
    }
}

static void test_phase(void) {
    GLuint prog = build("common/physics.glsl", "", PHASE_MAIN);
    if (!prog) return;
    static float mu[NNODES], val[NNODES];
    static double w[NNODES];
    phase_nodes(mu, w);
    GLuint in = ssbo(sizeof mu, mu, 0), outb = ssbo(sizeof val, NULL, 1);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "count"), NNODES);
    const struct {
        int kind;
        double g;
    } cases[] = {{0, 0},   {1, 0},     {2, -0.9},   {2, 0},  {2, 0.5},
                 {2, 0.9}, {2, 0.999}, {2, -0.999}, {2, 1.5}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        glUniform1i(glGetUniformLocation(prog, "kind"), cases[c].kind);
        glUniform1f(glGetUniformLocation(prog, "g"), (float)cases[c].g);
        glDispatchCompute((NNODES + 63) / 64, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(outb, 0, sizeof val, val);
        double integral = 0, worst = 0;
        int finite = 1;
        for (int i = 0; i < NNODES; i++) {
            finite &= isfinite(val[i]) && val[i] >= 0;
            integral += 2.0 * ST_PI * w[i] * val[i];
            // The C model at the same (float) cosine, g as the shader saw it.
            double want = st_phase_eval((st_phase_kind)cases[c].kind, mu[i], (float)cases[c].g);
            worst = fmax(worst, fabs(val[i] - want) / want);
        }
        printf("  phase kind %d g %6.3f: integral %.7f, worst rel. difference to C %.2e\n",
               cases[c].kind, cases[c].g, integral, worst);
        CHECK(finite, "kind %d g %g: finite and >= 0", cases[c].kind, cases[c].g);
        CHECK(fabs(integral - 1.0) < 1e-3, "kind %d g %g integrates to %.6f", cases[c].kind,
              cases[c].g, integral);
        CHECK(worst < 1e-4, "kind %d g %g: GLSL vs C worst %.3g", cases[c].kind, cases[c].g, worst);
    }
    // g > 0 is brightest looking into the light: cos = +1.
    float two[2] = {1.0f, -1.0f};
    glNamedBufferSubData(in, 0, sizeof two, two);
    glUniform1i(glGetUniformLocation(prog, "count"), 2);
    glUniform1i(glGetUniformLocation(prog, "kind"), 2);
    glUniform1f(glGetUniformLocation(prog, "g"), 0.5f);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(outb, 0, sizeof two, val);
    CHECK(val[0] > 20 * val[1], "HG g=0.5: forward %.4g vs backward %.4g", val[0], val[1]);
    glDeleteBuffers(1, &in);
    glDeleteBuffers(1, &outb);
    glDeleteProgram(prog);
}

// ---- the march loop with a constant source ---------------------------------

static const char *CONST_PROTO = "vec3 toth_source(vec3 x, vec3 dir, float min_d2);\n";
static const char *MARCH_MAIN =
    "vec3 toth_source(vec3 x, vec3 dir, float min_d2) { return vec3(1.0, 2.0, 0.5); }\n"
    "layout(local_size_x = 1) in;\n"
    // per job: n, first, stride, integrator | u, length, sigma_t, -
    "layout(std430, binding = 0) readonly buffer In { ivec4 ji[]; };\n"
    "layout(std430, binding = 2) readonly buffer InF { vec4 jf[]; };\n"
    "layout(std430, binding = 1) writeonly buffer Out { vec4 res[]; };\n"
    "void main() {\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    ivec4 a = ji[i];\n"
    "    vec4 b = jf[i];\n"
    "    float u = b.x < 0.0 ? st_step_sample_offset(a.w) : b.x;\n"
    "    res[i] = vec4(toth_march(vec3(0.0), vec3(0.0, 0.0, -1.0), b.y, a.x, a.y, a.z, u, a.w, "
    "vec3(b.z)), 0.0);\n"
    "}\n";

typedef struct {
    int n, first, stride, integrator;
    float u, length, sigma_t, pad;
} job;

static void run_jobs(GLuint prog, const job *jobs, int count, float (*res)[4]) {
    int(*ji)[4] = malloc(sizeof *ji * (size_t)count);
    float(*jf)[4] = malloc(sizeof *jf * (size_t)count);
    for (int i = 0; i < count; i++) {
        ji[i][0] = jobs[i].n, ji[i][1] = jobs[i].first, ji[i][2] = jobs[i].stride,
        ji[i][3] = jobs[i].integrator;
        jf[i][0] = jobs[i].u, jf[i][1] = jobs[i].length, jf[i][2] = jobs[i].sigma_t, jf[i][3] = 0;
    }
    GLuint a = ssbo(sizeof *ji * (size_t)count, ji, 0), b = ssbo(sizeof *jf * (size_t)count, jf, 2);
    GLuint o = ssbo(sizeof *res * (size_t)count, NULL, 1);
    glUseProgram(prog);
    glDispatchCompute((GLuint)count, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(o, 0, (GLsizeiptr)(sizeof *res * (size_t)count), res);
    glDeleteBuffers(1, &a);
    glDeleteBuffers(1, &b);
    glDeleteBuffers(1, &o);
    free(ji);
    free(jf);
}

static void test_march(void) {
    GLuint prog = build("toth/march.glsl", CONST_PROTO, MARCH_MAIN);
    if (!prog) return;
    const double src[3] = {1.0, 2.0, 0.5};
    // The documented case: sigma_t 0.5, length 10, 4 steps, unjittered.
    job jobs[3] = {{4, 0, 1, ST_INTEGRATOR_ENERGY, -1, 10, 0.5f, 0},
                   {4, 0, 1, ST_INTEGRATOR_THESIS, -1, 10, 0.5f, 0},
                   {4, 0, 1, ST_INTEGRATOR_THESIS_FAR, -1, 10, 0.5f, 0}};
    float res[3][4];
    run_jobs(prog, jobs, 3, res);
    const double want[3] = {1.986524, 3.480, 0.997};
    for (int k = 0; k < 3; k++) {
        double c = st_march_constant((st_integrator)k, 1.0, 0.5, 10.0, 4);
        printf("  constant source, %s, 4 steps: GPU %.6f, C %.6f, documented %.6f\n",
               st_integrator_name((st_integrator)k), res[k][0], c, want[k]);
        CHECK(fabs(res[k][0] - c) < 2e-6 * c, "%s: GPU %.7f vs C %.7f",
              st_integrator_name((st_integrator)k), res[k][0], c);
        CHECK(fabs(res[k][0] - want[k]) < 5e-4, "%s: %.6f vs documented %.6f",
              st_integrator_name((st_integrator)k), res[k][0], want[k]);
        for (int ch = 1; ch < 3; ch++)
            CHECK_REL(res[k][ch], res[k][0] * src[ch], 1e-6, 0);
    }
    // The energy step is exact for a constant source at any step count, any
    // jitter offset and any density, the sigma_t -> 0 limit included.
    enum { NJ = 5 * 4 * 6 };
    static job many[NJ];
    static float r[NJ][4];
    const int ns[5] = {1, 2, 4, 7, 64};
    const float us[4] = {0.0f, 0.25f, 0.5f, 0.999f},
                sts[6] = {0.0f, 1e-7f, 1e-3f, 0.5f, 3.0f, 1000.0f};
    int m = 0;
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 4; b++)
            for (int c = 0; c < 6; c++)
                many[m++] = (job){ns[a], 0, 1, ST_INTEGRATOR_ENERGY, us[b], 10, sts[c], 0};
    run_jobs(prog, many, NJ, r);
    double worst = 0;
    for (int i = 0; i < NJ; i++) {
        double exact = st_march_constant(ST_INTEGRATOR_ENERGY, 1.0, many[i].sigma_t, 10.0, 1);
        worst = fmax(worst, fabs(r[i][0] - exact) / exact);
    }
    printf("  energy step, constant source, 120 cases: worst rel. error %.2e\n", worst);
    CHECK(worst < 1e-5, "energy integrator exact for a constant source: worst %.3g", worst);

    // Interleaving: the M^2 residue classes of the steps add up to the whole march.
    for (int M = 2; M <= 4; M++) {
        job parts[17];
        float pr[17][4];
        for (int k = 0; k < M * M; k++)
            parts[k] = (job){64, k, M * M, ST_INTEGRATOR_THESIS, 0.3f, 10, 0.5f, 0};
        parts[M * M] = (job){64, 0, 1, ST_INTEGRATOR_THESIS, 0.3f, 10, 0.5f, 0};
        run_jobs(prog, parts, M * M + 1, pr);
        double sum = 0;
        for (int k = 0; k < M * M; k++)
            sum += pr[k][0];
        CHECK_REL(sum, pr[M * M][0], 1e-5, 0);
    }
    glDeleteProgram(prog);
}

// ---- the step transfer against C --------------------------------------------

static void test_transfer(void) {
    const char *main_src = "layout(local_size_x = 1) in;\n"
                           "layout(std430, binding = 0) readonly buffer In { vec2 arg[]; };\n"
                           "layout(std430, binding = 1) writeonly buffer Out { float val[]; };\n"
                           "void main() { uint i = gl_GlobalInvocationID.x; val[i] = "
                           "st_step_transfer(vec3(arg[i].x), arg[i].y).x; }\n";
    GLuint prog = build("common/physics.glsl", "", main_src);
    if (!prog) return;
    const float st[] = {0.0f, 1e-9f, 1e-6f, 1e-4f, 5e-3f, 1e-2f, 2e-2f, 0.3f, 7.0f, 1e3f, 1e6f};
    const float dt[] = {1e-4f, 0.01f, 0.3f, 1.0f, 40.0f};
    enum { NS = sizeof st / sizeof st[0], ND = sizeof dt / sizeof dt[0] };
    float arg[NS * ND][2], val[NS * ND];
    for (int i = 0; i < NS; i++)
        for (int j = 0; j < ND; j++)
            arg[i * ND + j][0] = st[i], arg[i * ND + j][1] = dt[j];
    GLuint a = ssbo(sizeof arg, arg, 0), o = ssbo(sizeof val, NULL, 1);
    glUseProgram(prog);
    glDispatchCompute(NS * ND, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(o, 0, sizeof val, val);
    double worst = 0;
    for (int k = 0; k < NS * ND; k++) {
        double want = st_step_transfer(arg[k][0], arg[k][1]);
        worst = fmax(worst, fabs(val[k] - want) / want);
    }
    printf("  step transfer vs C over %d cases: worst rel. %.2e\n", NS * ND, worst);
    CHECK(worst < 2e-6, "GLSL st_step_transfer mirrors C: worst %.3g", worst);
    glDeleteBuffers(1, &a);
    glDeleteBuffers(1, &o);
    glDeleteProgram(prog);
}

int main(void) {
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    CHECK(ctx != NULL, "headless context: %s", err.msg);
    if (!ctx) return st_test_summary("toth_glsl");
    test_phase();
    test_march();
    test_transfer();
    CHECK(glGetError() == GL_NO_ERROR, "no GL error");
    st_context_destroy(ctx);
    return st_test_summary("toth_glsl");
}
