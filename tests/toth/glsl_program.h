// The toth GLSL unit tests' compute programs: the shader file preprocessed
// with its includes, then a program from that plus the test's kernel, with
// the compile log reported as a test failure.
#ifndef TOTH_GLSL_PROGRAM_H
#define TOTH_GLSL_PROGRAM_H
#include "st_test.h"
#include "st_gl.h"
#include "st_shader.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// `file` with its includes, as a compute stage (NULL: a failed check).
static char *toth_glsl_source(const char *file) {
    char names[32][128];
    int num = 0;
    st_err err = {0};
    char *src =
        st_shader_preprocess_stage(file, "ST_MAX_LIGHTS 8\n", GL_COMPUTE_SHADER, names, &num, &err);
    CHECK(src != NULL, "preprocess %s: %s", file, err.msg);
    return src;
}

// Takes and frees `full`.
static GLuint toth_glsl_program(char *full, const char *file) {
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
    const char *srcs[] = {full};
    glShaderSource(sh, 1, srcs, NULL);
    glCompileShader(sh);
    free(full);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        CHECK(0, "compile %s: %s", file, log);
        glDeleteShader(sh);
        return 0;
    }
    GLuint prog = glCreateProgram();
    glAttachShader(prog, sh);
    glLinkProgram(prog);
    glDeleteShader(sh);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    CHECK(ok, "link %s", file);
    return prog;
}

// `file` with its includes, then the test's kernel `after` (its lines
// numbered from 1 in source string 31, so a compile error names the kernel).
static inline GLuint toth_glsl_program_after(const char *file, const char *after) {
    char *src = toth_glsl_source(file);
    if (!src) return 0;
    size_t n = strlen(src) + strlen(after) + 64;
    char *full = malloc(n);
    snprintf(full, n, "%s\n#line 1 31\n%s\n", src, after);
    free(src);
    return toth_glsl_program(full, file);
}

// The scene's BVH for shaders/common/bvh.glsl (bindings 6 and 7; the layout
// of framework/st_bvh.h: node = (min, first), (max, count); triangle =
// v0, e1, e2), from the test's arrays.
static inline void toth_glsl_bind_bvh(GLuint bufs[2], const float *nodes, size_t nodes_size,
                                      const float *tris, size_t tris_size) {
    glCreateBuffers(2, bufs);
    glNamedBufferData(bufs[0], (GLsizeiptr)nodes_size, nodes, GL_STATIC_DRAW);
    glNamedBufferData(bufs[1], (GLsizeiptr)tris_size, tris, GL_STATIC_DRAW);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, bufs[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, bufs[1]);
}

// A headless context and the program of shaders/toth/visibility.glsl with
// the test's kernel, in use, with a 16-byte result buffer `out` at binding 0
// and the frame uniforms the equi-angular frame reads (h_min), an isotropic
// phase and one light. NULL (a failed check) when the context or the
// program fails; the context is then destroyed.
static inline st_context *toth_glsl_visibility_test(const char *kernel, GLuint *prog, GLuint *out) {
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    CHECK(ctx != NULL, "headless context: %s", err.msg);
    if (!ctx) return NULL;
    *prog = toth_glsl_program_after("toth/visibility.glsl", kernel);
    if (!*prog) {
        st_context_destroy(ctx);
        return NULL;
    }
    glCreateBuffers(1, out);
    glNamedBufferData(*out, 16, NULL, GL_DYNAMIC_COPY);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, *out);
    glUseProgram(*prog);
    glUniform1f(glGetUniformLocation(*prog, "st_fov_y"), 1.0f);
    glUniform2f(glGetUniformLocation(*prog, "st_resolution"), 1000.0f, 1000.0f);
    glUniform1f(glGetUniformLocation(*prog, "st_near"), 0.1f);
    glUniform1i(glGetUniformLocation(*prog, "st_phase_kind"), 0);
    glUniform1i(glGetUniformLocation(*prog, "st_num_lights"), 1);
    return ctx;
}
#endif
