// The toth GLSL unit tests' compute programs: the shader file preprocessed
// with its includes, then a program from that plus the test's kernel, with
// the compile log reported as a test failure.
#ifndef TOTH_GLSL_PROGRAM_H
#define TOTH_GLSL_PROGRAM_H
#include "st_test.h"
#include "st_gl.h"
#include "st_shader.h"
#include <stdlib.h>

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
#endif
