// Pass statistics (runs, skips, culls, timing samples) and the GPU memory
// report (every allocation of the world as a row).
#include "st_world_state.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

st_pass_stats *st_stats_entry(st_world *w, const char *module, const char *pass) {
    for (int i = 0; i < w->num_stats; i++)
        if (!strcmp(w->stats[i].module, module) && !strcmp(w->stats[i].pass, pass))
            return &w->stats[i];
    if (w->num_stats == w->cap_stats) {
        int cap = w->cap_stats ? w->cap_stats * 2 : 16;
        st_pass_stats *n = realloc(w->stats, (size_t)cap * sizeof *n);
        if (!n) return NULL;
        w->stats = n;
        w->cap_stats = cap;
    }
    st_pass_stats *s = &w->stats[w->num_stats++];
    memset(s, 0, sizeof *s);
    snprintf(s->module, sizeof s->module, "%s", module);
    snprintf(s->pass, sizeof s->pass, "%s", pass);
    return s;
}

int st_world_num_pass_stats(const st_world *w) {
    return w->num_stats;
}
const st_pass_stats *st_world_pass_stats(const st_world *w, int i) {
    return &w->stats[i];
}
void st_world_reset_stats(st_world *w) {
    for (int i = 0; i < w->num_stats; i++) {
        st_pass_stats *s = &w->stats[i];
        s->runs = s->skipped = s->culled = 0;
        s->num_samples = 0;
    }
}

void st_world_reset_samples(st_world *w) {
    for (int i = 0; i < w->num_stats; i++)
        w->stats[i].num_samples = 0;
}

static int cmp_d(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double st_median_d(const double *v, int n) {
    if (n <= 0) return 0;
    double *t = malloc((size_t)n * sizeof *t);
    if (!t) return 0;
    memcpy(t, v, (size_t)n * sizeof *t);
    qsort(t, (size_t)n, sizeof *t, cmp_d);
    double m = n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
    free(t);
    return m;
}

double st_median_f(const float *v, int n) {
    if (n <= 0) return 0;
    double *d = malloc((size_t)n * sizeof *d);
    if (!d) return 0;
    for (int i = 0; i < n; i++)
        d[i] = v[i];
    double m = st_median_d(d, n);
    free(d);
    return m;
}

static int add_row(st_mem_entry *out, int max, int n, const st_mem_entry *e) {
    if (out && n < max) out[n] = *e;
    return n + 1;
}

static int module_rows(st_world *w, const char *owner, st_mem_entry *out, int max, int n) {
    st_targets *s = &w->targets;
    st_mem_entry e;
    for (int i = 0; i < s->n; i++) {
        st_targets_entry(s->t[i].name, &s->t[i].t, &e);
        if (strcmp(e.owner, owner)) continue;
        if (!s->t[i].t.color[0]) // declared, not used yet
            snprintf(e.format, sizeof e.format, "%s", st_format_name(s->t[i].desc.format));
        n = add_row(out, max, n, &e);
    }
    for (int i = 0; i < s->nk; i++) {
        memset(&e, 0, sizeof e);
        snprintf(e.name, sizeof e.name, "%s", s->k[i].name);
        snprintf(e.owner, sizeof e.owner, "%.*s", (int)strcspn(e.name, "."), e.name);
        if (strcmp(e.owner, owner)) continue;
        snprintf(e.format, sizeof e.format, "-");
        e.kind = s->k[i].identifier == GL_BUFFER ? "buffer" : "buffer texture";
        e.bytes = s->k[i].bytes;
        n = add_row(out, max, n, &e);
    }
    return n;
}

int st_world_memory(st_world *w, st_mem_entry *out, int max) {
    int n = 0;
    st_mem_entry e;
    const st_target *cam[5] = {&w->cam.scene, &w->cam.post[0], &w->cam.post[1], &w->cam.accum[0],
                               &w->cam.accum[1]};
    const char *names[5] = {"camera.scene", "camera.post0", "camera.post1", "camera.accum0",
                            "camera.accum1"};
    for (int i = 0; i < (w->cam.accum[0].fbo ? 5 : 3); i++) {
        st_targets_entry(names[i], cam[i], &e);
        n = add_row(out, max, n, &e);
    }
    const st_buffer *geo[2] = {&w->type.vbo, &w->type.ibo};
    const char *gnames[2] = {"world.vertices", "world.indices"};
    for (int i = 0; i < 2; i++) {
        memset(&e, 0, sizeof e);
        snprintf(e.name, sizeof e.name, "%s", gnames[i]);
        snprintf(e.owner, sizeof e.owner, "world");
        snprintf(e.format, sizeof e.format, "-");
        e.kind = "buffer";
        e.bytes = geo[i]->size;
        n = add_row(out, max, n, &e);
    }
    // The medium's density grid (st_medium_gpu.c): one R32F texel per voxel.
    if (w->medium.grid) {
        memset(&e, 0, sizeof e);
        snprintf(e.name, sizeof e.name, "medium.density"); // its GL label
        snprintf(e.owner, sizeof e.owner, "world");
        snprintf(e.format, sizeof e.format, "R32F");
        e.kind = "3D";
        e.width = w->medium.size[0], e.height = w->medium.size[1], e.layers = w->medium.size[2];
        e.levels = 1;
        e.bytes = (size_t)e.width * e.height * e.layers * sizeof(float);
        n = add_row(out, max, n, &e);
    }
    for (int m = 0; m < w->num_mods; m++)
        n = module_rows(w, w->mods[m]->p->name, out, max, n);
    return n;
}

size_t st_world_memory_bytes(st_world *w) {
    st_mem_entry rows[ST_MAX_TARGETS + ST_MAX_TRACKED + 8];
    int n = st_world_memory(w, rows, (int)(sizeof rows / sizeof rows[0]));
    size_t sum = 0;
    for (int i = 0; i < n; i++)
        sum += rows[i].bytes;
    return sum;
}
