// The toth GLSL unit tests' last step: a compute program from a complete
// source (the shader file preprocessed plus the test's kernel), with the
// compile log reported as a test failure. Takes and frees `full`.
#ifndef TOTH_GLSL_PROGRAM_H
#define TOTH_GLSL_PROGRAM_H
#include "st_test.h"
#include "st_gl.h"
#include <stdlib.h>

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
