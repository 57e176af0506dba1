// The world's registry of module GPU memory (st_targets.h).
#include "st_targets.h"
#include "st_list.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

int st_targets_find(const st_targets *s, const char *name) {
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->t[i].name, name)) return i;
    return -1;
}

int st_targets_written(const st_targets *s, const char *writes) {
    for (int i = 0; i < s->n; i++)
        if (s->t[i].desc.type != GL_TEXTURE_1D && st_list_has(writes, s->t[i].name)) return i;
    return -1;
}

static bool desc_equal(const st_target_desc *a, const st_target_desc *b) {
    return a->format == b->format && a->scale == b->scale && a->depth == b->depth &&
           a->border_zero == b->border_zero && a->type == b->type && a->width == b->width &&
           a->height == b->height && a->divisor == b->divisor && a->layers == b->layers &&
           a->levels == b->levels && a->filter == b->filter && a->wrap == b->wrap;
}

static bool module_name(const char *name) {
    return strlen(name) < ST_NAME_MAX && strchr(name, '.') && name[0] != '.';
}

bool st_targets_declare(st_targets *s, const char *name, const st_target_desc *d, st_err *err) {
    if (!module_name(name))
        return st_fail(err, ST_ERR_RUNTIME, "target '%s': not a \"<module>.<name>\" name", name);
    int i = st_targets_find(s, name);
    if (!d) { // forget it
        if (i < 0) return true;
        st_target_destroy(&s->t[i].t);
        memmove(&s->t[i], &s->t[i + 1], (size_t)(s->n - i - 1) * sizeof s->t[0]);
        s->n--;
        s->gen++;
        return true;
    }
    if (d->type == GL_TEXTURE_CUBE_MAP_ARRAY && d->width != d->height)
        return st_fail(err, ST_ERR_RUNTIME, "target '%s': cube faces must be square (%dx%d)", name,
                       d->width, d->height);
    if (i < 0) {
        if (s->n == ST_MAX_TARGETS)
            return st_fail(err, ST_ERR_RUNTIME, "too many targets (max %d)", ST_MAX_TARGETS);
        i = s->n++;
        memset(&s->t[i], 0, sizeof s->t[i]);
        snprintf(s->t[i].name, ST_NAME_MAX, "%s", name);
        s->gen++;
    } else if (!desc_equal(&s->t[i].desc, d)) {
        st_target_destroy(&s->t[i].t); // re-created at the next use
        s->gen++;
    }
    s->t[i].desc = *d;
    return true;
}

// The size a description asks for on a screen of sw x sh.
static void desc_size(const st_target_desc *d, int sw, int sh, int *w, int *h) {
    if (d->width > 0) {
        *w = d->width;
        *h = d->height > 0 ? d->height : 1;
    } else if (d->divisor > 1) {
        *w = (sw + d->divisor - 1) / d->divisor;
        *h = (sh + d->divisor - 1) / d->divisor;
    } else {
        double scale = d->scale > 0 ? d->scale : 1;
        *w = (int)lround(sw * scale);
        *h = (int)lround(sh * scale);
    }
    *w = *w < 1 ? 1 : *w;
    *h = *h < 1 || d->type == GL_TEXTURE_1D ? 1 : *h;
}

bool st_targets_ensure(st_targets *s, int i, int sw, int sh, st_err *err) {
    st_target *t = &s->t[i].t;
    int w, h;
    desc_size(&s->t[i].desc, sw, sh, &w, &h);
    if (t->color[0] && t->width == w && t->height == h) return true;
    st_target_destroy(t);
    if (!st_target_create_desc(t, &s->t[i].desc, w, h, err)) {
        st_err_prefix(err, "target '%s': ", s->t[i].name);
        return false;
    }
    char depth[ST_NAME_MAX + 8];
    snprintf(depth, sizeof depth, "%s (depth)", s->t[i].name);
    glObjectLabel(GL_TEXTURE, t->color[0], -1, s->t[i].name);
    if (t->fbo) glObjectLabel(GL_FRAMEBUFFER, t->fbo, -1, s->t[i].name);
    if (t->depth) glObjectLabel(GL_TEXTURE, t->depth, -1, depth);
    return st_gl_check(s->t[i].name, err);
}

// Bytes of a buffer's storage; a buffer texture has none of its own.
static size_t object_bytes(GLenum identifier, GLuint obj) {
    GLint64 n = 0;
    if (identifier == GL_BUFFER) glGetNamedBufferParameteri64v(obj, GL_BUFFER_SIZE, &n);
    return (size_t)n;
}

// Deletes a buffer or buffer texture the registry owns.
static void delete_object(GLenum identifier, GLuint obj) {
    if (identifier == GL_BUFFER) glDeleteBuffers(1, &obj);
    if (identifier == GL_TEXTURE) glDeleteTextures(1, &obj);
}

bool st_targets_track(st_targets *s, const char *name, GLenum identifier, GLuint obj, st_err *err) {
    if (!module_name(name))
        return st_fail(err, ST_ERR_RUNTIME, "object '%s': not a \"<module>.<name>\" name", name);
    if (identifier != GL_BUFFER && identifier != GL_TEXTURE)
        return st_fail(err, ST_ERR_RUNTIME,
                       "object '%s': only buffers and buffer textures are tracked (declare "
                       "textures as targets)",
                       name);
    int i = 0;
    while (i < s->nk && strcmp(s->k[i].name, name))
        i++;
    if (i == s->nk) {
        if (s->nk == ST_MAX_TRACKED)
            return st_fail(err, ST_ERR_RUNTIME, "too many tracked objects (max %d)",
                           ST_MAX_TRACKED);
        s->nk++;
        snprintf(s->k[i].name, ST_NAME_MAX, "%s", name);
    } else if (s->k[i].owned && s->k[i].obj != obj) { // the registry's object, replaced
        delete_object(s->k[i].identifier, s->k[i].obj);
    }
    // The caller's object (st_targets_buffer marks its own after): a slot
    // that untrack vacated keeps the old entry's bytes, `owned` included.
    s->k[i].owned = false;
    s->k[i].identifier = identifier;
    s->k[i].obj = obj;
    s->k[i].bytes = object_bytes(identifier, obj);
    glObjectLabel(identifier, obj, -1, name);
    return st_gl_check(name, err);
}

void st_targets_untrack(st_targets *s, const char *name) {
    for (int i = 0; i < s->nk; i++) {
        if (strcmp(s->k[i].name, name)) continue;
        if (s->k[i].owned) delete_object(s->k[i].identifier, s->k[i].obj);
        memmove(&s->k[i], &s->k[i + 1], (size_t)(s->nk - i - 1) * sizeof s->k[0]);
        s->nk--;
        return;
    }
}

static int tracked(const st_targets *s, const char *name) {
    for (int i = 0; i < s->nk; i++)
        if (!strcmp(s->k[i].name, name)) return i;
    return -1;
}

// Tracks a new object as the registry's own (deleted on failure too).
static GLuint own(st_targets *s, const char *name, GLenum identifier, GLuint obj, st_err *err) {
    st_targets_untrack(s, name);
    if (!st_targets_track(s, name, identifier, obj, err)) {
        delete_object(identifier, obj);
        return 0;
    }
    s->k[tracked(s, name)].owned = true;
    return obj;
}

GLuint st_targets_object(const st_targets *s, const char *name, GLenum identifier) {
    int i = tracked(s, name);
    return i >= 0 && s->k[i].identifier == identifier ? s->k[i].obj : 0;
}

GLuint st_targets_buffer(st_targets *s, const char *name, size_t bytes, const void *data,
                         st_err *err) {
    size_t storage = bytes ? bytes : 1; // GL has no empty storage
    int i = tracked(s, name);
    if (i >= 0 && s->k[i].owned && s->k[i].identifier == GL_BUFFER && s->k[i].bytes == storage) {
        if (data && bytes) glNamedBufferSubData(s->k[i].obj, 0, (GLsizeiptr)bytes, data);
        return s->k[i].obj;
    }
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, (GLsizeiptr)storage, bytes ? data : NULL, GL_DYNAMIC_STORAGE_BIT);
    return own(s, name, GL_BUFFER, b, err);
}

GLuint st_targets_buffer_texture(st_targets *s, const char *name, GLuint buf, GLenum format,
                                 st_err *err) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
    glTextureBuffer(t, format, buf);
    return own(s, name, GL_TEXTURE, t, err);
}

static bool owned_by(const char *name, const char *module) {
    size_t l = strlen(module);
    return !strncmp(name, module, l) && name[l] == '.';
}

void st_targets_free(st_targets *s, const char *module) {
    for (int i = s->n - 1; i >= 0; i--) {
        if (module && !owned_by(s->t[i].name, module)) continue;
        st_target_destroy(&s->t[i].t);
        memmove(&s->t[i], &s->t[i + 1], (size_t)(s->n - i - 1) * sizeof s->t[0]);
        s->n--;
        s->gen++;
    }
    for (int i = s->nk - 1; i >= 0; i--)
        if (!module || owned_by(s->k[i].name, module)) st_targets_untrack(s, s->k[i].name);
}

void st_targets_entry(const char *name, const st_target *t, st_mem_entry *e) {
    memset(e, 0, sizeof *e);
    snprintf(e->name, sizeof e->name, "%s", name);
    const char *dot = strchr(name, '.');
    snprintf(e->owner, sizeof e->owner, "%.*s", dot ? (int)(dot - name) : (int)strlen(name), name);
    e->kind = t->type == GL_TEXTURE_1D               ? "1D"
              : t->type == GL_TEXTURE_2D_ARRAY       ? "2D array"
              : t->type == GL_TEXTURE_CUBE_MAP_ARRAY ? "cube array"
                                                     : "2D";
    char n[16] = "";
    if (t->num_color > 1) snprintf(n, sizeof n, "%dx", t->num_color);
    snprintf(e->format, sizeof e->format, "%s%s%s", n,
             t->num_color ? st_format_name(t->color_format) : "-", t->depth ? "+D32F" : "");
    e->width = t->width, e->height = t->height, e->layers = t->layers, e->levels = t->levels;
    e->bytes = t->bytes;
}
