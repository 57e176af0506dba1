#define _POSIX_C_SOURCE 200809L
#include "st_shader.h"
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_FILES 32

static bool has_common(const char *dir) {
    char p[1100];
    struct stat st;
    snprintf(p, sizeof p, "%s/common", dir);
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

const char *st_shader_root(void) {
    static char root[1024];
    if (root[0]) return root;
    const char *env = getenv("STRAHL_SHADER_PATH");
    char installed[1100] = "";
    if (st_install_prefix()[0])
        snprintf(installed, sizeof installed, "%s/share/strahl/shaders", st_install_prefix());
    const char *cands[] = {env, installed, ST_SHADER_SOURCE_DIR, ST_SHADER_INSTALL_DIR};
    for (int i = 0; i < 4; i++) {
        if (cands[i] && cands[i][0] && has_common(cands[i])) {
            snprintf(root, sizeof root, "%s", cands[i]);
            return root;
        }
    }
    snprintf(root, sizeof root, "%s", ST_SHADER_SOURCE_DIR);
    return root;
}

// Plugin shader folders (st_shader_add_dir): prefix -> directory.
#define MAX_DIRS 32
static struct { char prefix[64], dir[1024]; } g_dirs[MAX_DIRS];
static int g_num_dirs;

bool st_shader_add_dir(const char *prefix, const char *dir) {
    if (strlen(prefix) >= sizeof g_dirs[0].prefix || strlen(dir) >= sizeof g_dirs[0].dir)
        return false;
    int i = 0;
    while (i < g_num_dirs && strcmp(g_dirs[i].prefix, prefix))
        i++;
    if (i == MAX_DIRS) return false;
    if (i == g_num_dirs) g_num_dirs++;
    snprintf(g_dirs[i].prefix, sizeof g_dirs[i].prefix, "%s", prefix);
    snprintf(g_dirs[i].dir, sizeof g_dirs[i].dir, "%s", dir);
    return true;
}

// The file for a shader path "dir/file": a plugin's own folder, else the root.
static void shader_file(char *out, size_t n, const char *path) {
    const char *slash = strchr(path, '/');
    for (int i = 0; slash && i < g_num_dirs; i++) {
        size_t l = strlen(g_dirs[i].prefix);
        if ((size_t)(slash - path) == l && !strncmp(path, g_dirs[i].prefix, l)) {
            snprintf(out, n, "%s/%s", g_dirs[i].dir, slash + 1);
            return;
        }
    }
    snprintf(out, n, "%s/%s", st_shader_root(), path);
}

typedef struct {
    char *buf;
    size_t len, cap;
} sbuf;

static bool sb_put(sbuf *b, const char *s, size_t n) {
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (b->len + n + 1 > cap)
            cap *= 2;
        char *nb = realloc(b->buf, cap);
        if (!nb) return false;
        b->buf = nb;
        b->cap = cap;
    }
    memcpy(b->buf + b->len, s, n);
    b->len += n;
    b->buf[b->len] = 0;
    return true;
}

static bool sb_printf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
#include <stdarg.h>
static bool sb_printf(sbuf *b, const char *fmt, ...) {
    char tmp[2048];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    return n >= 0 && sb_put(b, tmp, (size_t)n < sizeof tmp ? (size_t)n : sizeof tmp - 1);
}

static int file_id(const char *path, char names[][128], int *num) {
    for (int i = 0; i < *num; i++)
        if (!strcmp(names[i], path)) return i;
    if (*num >= MAX_FILES) return -1;
    snprintf(names[*num], 128, "%s", path);
    return (*num)++;
}

// Appends `path` (relative to the root) to out; depth guards include cycles.
static bool include_file(sbuf *out, const char *path, char names[][128], int *num, int depth,
                         st_err *err) {
    if (depth > 16) return st_fail(err, ST_ERR_INPUT, "shaders/%s: includes nested too deep", path);
    int id = file_id(path, names, num);
    if (id < 0) return st_fail(err, ST_ERR_INPUT, "shaders/%s: too many included files", path);
    char full[1200];
    shader_file(full, sizeof full, path);
    char *src = st_read_file(full, NULL, err);
    if (!src) return false;
    if (!sb_printf(out, "#line 1 %d\n", id)) goto oom;
    int line = 1;
    for (char *p = src; *p;) {
        char *eol = strchr(p, '\n');
        size_t n = eol ? (size_t)(eol - p) : strlen(p);
        const char *q = p;
        while (q < p + n && isspace((unsigned char)*q))
            q++;
        if (!strncmp(q, "#version", 8) && depth == 0) {
            // Kept by the caller as the first line; skipped here.
        } else if (!strncmp(q, "#include", 8)) {
            const char *a = strchr(q, '"'), *b = a ? strchr(a + 1, '"') : NULL;
            if (!a || !b || b > p + n) {
                free(src);
                return st_fail(err, ST_ERR_INPUT, "shaders/%s:%d: malformed #include", path, line);
            }
            char inc[128];
            snprintf(inc, sizeof inc, "%.*s", (int)(b - a - 1), a + 1);
            if (!include_file(out, inc, names, num, depth + 1, err)) {
                st_err_prefix(err, "shaders/%s:%d: included from here: ", path, line);
                free(src);
                return false;
            }
            if (!sb_printf(out, "#line %d %d\n", line + 1, id)) goto oom;
        } else {
            if (!sb_put(out, p, n) || !sb_put(out, "\n", 1)) goto oom;
        }
        line++;
        p = eol ? eol + 1 : p + n;
    }
    free(src);
    return true;
oom:
    free(src);
    return st_fail(err, ST_ERR_RUNTIME, "out of memory");
}

char *st_shader_preprocess(const char *path, const char *defines, char names[][128], int *num_names,
                           st_err *err) {
    return st_shader_preprocess_stage(path, defines, 0, names, num_names, err);
}

char *st_shader_preprocess_stage(const char *path, const char *defines, GLenum stage,
                                 char names[][128], int *num_names, st_err *err) {
    sbuf out = {0};
    *num_names = 0;
    if (!sb_printf(&out, "#version 450 core\n")) goto oom;
    const char *stage_def = stage == GL_VERTEX_SHADER     ? "ST_VERTEX"
                            : stage == GL_GEOMETRY_SHADER ? "ST_GEOMETRY"
                            : stage == GL_FRAGMENT_SHADER ? "ST_FRAGMENT"
                            : stage == GL_COMPUTE_SHADER  ? "ST_COMPUTE"
                                                          : NULL;
    if (stage_def && !sb_printf(&out, "#define %s 1\n", stage_def)) goto oom;
    if (defines) {
        for (const char *p = defines; *p;) {
            const char *eol = strchr(p, '\n');
            size_t n = eol ? (size_t)(eol - p) : strlen(p);
            if (n > 8 && !strncmp(p, "#include", 8)) {
                // Module includes go into fragment and compute stages only.
                if (stage != GL_VERTEX_SHADER && stage != GL_GEOMETRY_SHADER) {
                    const char *a = memchr(p, '"', n),
                               *b = a ? memchr(a + 1, '"', n - (size_t)(a + 1 - p)) : NULL;
                    if (!a || !b) {
                        free(out.buf);
                        st_fail(err, ST_ERR_INPUT, "malformed include in defines: %.*s", (int)n, p);
                        return NULL;
                    }
                    char inc[128];
                    snprintf(inc, sizeof inc, "%.*s", (int)(b - a - 1), a + 1);
                    if (!include_file(&out, inc, names, num_names, 1, err)) {
                        free(out.buf);
                        return NULL;
                    }
                }
            } else if (n && (!sb_put(&out, "#define ", 8) || !sb_put(&out, p, n) ||
                             !sb_put(&out, "\n", 1))) {
                goto oom;
            }
            p = eol ? eol + 1 : p + n;
        }
    }
    if (!include_file(&out, path, names, num_names, 0, err)) {
        free(out.buf);
        return NULL;
    }
    return out.buf;
oom:
    free(out.buf);
    st_fail(err, ST_ERR_RUNTIME, "out of memory");
    return NULL;
}

// Rewrites driver log lines "ID:LINE(COL): msg" (Mesa) or "ID(LINE) : msg"
// (NVIDIA) as "shaders/FILE:LINE: msg".
static void format_log(char *dst, size_t n, const char *log, char names[][128], int num) {
    size_t w = 0;
    dst[0] = 0;
    for (const char *p = log; *p && w + 1 < n;) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char *end;
        long id = strtol(p, &end, 10);
        long line = -1;
        const char *rest = p;
        if (end != p && (*end == ':' || *end == '(')) {
            char *e2;
            line = strtol(end + 1, &e2, 10);
            if (e2 != end + 1) {
                rest = e2;
                while (*rest == ')' || *rest == '(' || isdigit((unsigned char)*rest) ||
                       *rest == ' ')
                    rest++;
                if (*rest == ':') rest++;
                while (*rest == ' ')
                    rest++;
            } else {
                line = -1;
            }
        }
        int k;
        if (line >= 0 && id >= 0 && id < num)
            k = snprintf(dst + w, n - w, "shaders/%s:%ld: %.*s\n", names[id], line,
                         (int)(len - (size_t)(rest - p)), rest);
        else
            k = snprintf(dst + w, n - w, "%.*s\n", (int)len, p);
        if (k < 0) break;
        w += (size_t)k < n - w ? (size_t)k : n - w - 1;
        p = eol ? eol + 1 : p + len;
    }
    // Drop the trailing newline so the message is one block without a blank end.
    while (w > 0 && dst[w - 1] == '\n')
        dst[--w] = 0;
}

// Compiles one stage from source; `names` maps #line file ids to files for
// the error message (none for sources that are not files).
static GLuint compile_source(GLenum type, const char *src, char names[][128], int num,
                             const char *what, st_err *err) {
    GLuint s = glCreateShader(type);
    const char *srcs[] = {src};
    glShaderSource(s, 1, srcs, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = {0}, msg[900];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        format_log(msg, sizeof msg, log, names, num);
        glDeleteShader(s);
        st_fail(err, ST_ERR_INPUT, "shader compile failed%s%s: %s", what ? " in " : "",
                what ? what : "", msg);
        return 0;
    }
    return s;
}

static GLuint compile(GLenum type, const char *path, const char *defines, st_err *err) {
    char names[MAX_FILES][128];
    int num = 0;
    char *src = st_shader_preprocess_stage(path, defines, type, names, &num, err);
    if (!src) return 0;
    GLuint s = compile_source(type, src, names, num, NULL, err);
    free(src);
    return s;
}

static GLuint link_program(GLuint *shaders, int n, const char *what, st_err *err) {
    GLuint p = glCreateProgram();
    for (int i = 0; i < n; i++)
        glAttachShader(p, shaders[i]);
    glLinkProgram(p);
    for (int i = 0; i < n; i++)
        glDeleteShader(shaders[i]);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048] = {0};
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        glDeleteProgram(p);
        st_fail(err, ST_ERR_INPUT, "shader link failed (%s): %s", what, log);
        return 0;
    }
    return p;
}

GLuint st_program_from_source(const char *vs, const char *fs, const char *what, st_err *err) {
    GLuint s[2];
    if (!(s[0] = compile_source(GL_VERTEX_SHADER, vs, NULL, 0, what, err))) return 0;
    if (!(s[1] = compile_source(GL_FRAGMENT_SHADER, fs, NULL, 0, what, err))) {
        glDeleteShader(s[0]);
        return 0;
    }
    return link_program(s, 2, what, err);
}

static GLuint build(const st_shader *sh, st_err *err) {
    GLuint s[3];
    int n = 0;
    if (sh->cs[0]) {
        if (!(s[0] = compile(GL_COMPUTE_SHADER, sh->cs, sh->defines, err))) return 0;
        return link_program(s, 1, sh->cs, err);
    }
    if (!(s[n++] = compile(GL_VERTEX_SHADER, sh->vs, sh->defines, err)) ||
        (sh->gs[0] && !(s[n++] = compile(GL_GEOMETRY_SHADER, sh->gs, sh->defines, err))) ||
        !(s[n++] = compile(GL_FRAGMENT_SHADER, sh->fs, sh->defines, err))) {
        for (int i = 0; i < n - 1; i++)
            glDeleteShader(s[i]);
        return 0;
    }
    char what[400];
    if (sh->gs[0])
        snprintf(what, sizeof what, "%s + %s + %s", sh->vs, sh->gs, sh->fs);
    else
        snprintf(what, sizeof what, "%s + %s", sh->vs, sh->fs);
    GLuint p = link_program(s, n, what, err);
    // Named after its files in debuggers (RenderDoc, apitrace).
    if (p) glObjectLabel(GL_PROGRAM, p, -1, what);
    return p;
}

static st_shader *create(const char *vs, const char *gs, const char *fs, const char *cs,
                         const char *defines, st_err *err) {
    st_shader *sh = calloc(1, sizeof *sh);
    if (!sh) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    snprintf(sh->vs, sizeof sh->vs, "%s", vs ? vs : "");
    snprintf(sh->fs, sizeof sh->fs, "%s", fs ? fs : "");
    snprintf(sh->cs, sizeof sh->cs, "%s", cs ? cs : "");
    snprintf(sh->gs, sizeof sh->gs, "%s", gs ? gs : "");
    snprintf(sh->defines, sizeof sh->defines, "%s", defines ? defines : "");
    sh->program = build(sh, err);
    if (!sh->program) {
        free(sh);
        return NULL;
    }
    return sh;
}

st_shader *st_shader_load(const char *vs, const char *fs, const char *defines, st_err *err) {
    return create(vs, NULL, fs, NULL, defines, err);
}

st_shader *st_shader_load_gs(const char *vs, const char *gs, const char *fs, const char *defines,
                             st_err *err) {
    return create(vs, gs, fs, NULL, defines, err);
}

st_shader *st_shader_load_compute(const char *cs, const char *defines, st_err *err) {
    return create(NULL, NULL, NULL, cs, defines, err);
}

bool st_shader_reload(st_shader *sh, st_err *err) {
    GLuint p = build(sh, err);
    if (!p) return false;
    glDeleteProgram(sh->program);
    sh->program = p;
    sh->num_cached = 0;
    return true;
}

void st_shader_destroy(st_shader *sh) {
    if (!sh) return;
    glDeleteProgram(sh->program);
    free(sh);
}

void st_shader_use(st_shader *sh) {
    glUseProgram(sh->program);
    sh->next_unit = 0;
}

GLint st_shader_loc(st_shader *sh, const char *name) {
    for (int i = 0; i < sh->num_cached; i++)
        if (!strcmp(sh->cache[i].name, name)) return sh->cache[i].loc;
    GLint loc = glGetUniformLocation(sh->program, name);
    if (sh->num_cached < ST_SHADER_CACHE && strlen(name) < sizeof sh->cache[0].name) {
        snprintf(sh->cache[sh->num_cached].name, sizeof sh->cache[0].name, "%s", name);
        sh->cache[sh->num_cached++].loc = loc;
    }
    return loc;
}

void st_shader_texture(st_shader *sh, const char *name, GLenum target, GLuint tex) {
    GLint loc = st_shader_loc(sh, name);
    if (loc < 0) return;
    int unit = sh->next_unit++;
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(target, tex);
    glUniform1i(loc, unit);
    glActiveTexture(GL_TEXTURE0);
}

void st_shader_set_int(st_shader *sh, const char *n, int v) {
    GLint l = st_shader_loc(sh, n);
    if (l >= 0) glUniform1i(l, v);
}
void st_shader_set_float(st_shader *sh, const char *n, float v) {
    GLint l = st_shader_loc(sh, n);
    if (l >= 0) glUniform1f(l, v);
}
void st_shader_set_vec2(st_shader *sh, const char *n, float x, float y) {
    GLint l = st_shader_loc(sh, n);
    if (l >= 0) glUniform2f(l, x, y);
}
void st_shader_set_vec3(st_shader *sh, const char *n, const float *v) {
    GLint l = st_shader_loc(sh, n);
    if (l >= 0) glUniform3fv(l, 1, v);
}
void st_shader_set_mat4(st_shader *sh, const char *n, const float *m) {
    GLint l = st_shader_loc(sh, n);
    if (l >= 0) glUniformMatrix4fv(l, 1, GL_FALSE, m);
}
