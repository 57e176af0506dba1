#define _POSIX_C_SOURCE 200809L
#include "cmd_common.h"
#include "st_world.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

bool st_parse_size(const char *s, int *w, int *h) {
    char *e;
    errno = 0;
    long a = strtol(s, &e, 10);
    if (e == s || *e != 'x' || errno) return false;
    const char *s2 = e + 1;
    long b = strtol(s2, &e, 10);
    if (e == s2 || *e || errno) return false;
    if (a < 1 || b < 1 || a > 16384 || b > 16384) return false;
    *w = (int)a;
    *h = (int)b;
    return true;
}

bool st_parse_int(const char *s, long lo, long hi, long *out) {
    char *e;
    errno = 0;
    long v = strtol(s, &e, 10);
    if (e == s || *e || errno || v < lo || v > hi) return false;
    *out = v;
    return true;
}

// The scene options of this command line (one per process).
static st_scene_opts scene_opts;
static bool overlay;
static char enable_list[1024], disable_list[1024];

bool st_cmd_scene_option(const char *arg) {
    if (!strcmp(arg, "--allow-outside-assets"))
        scene_opts.flags |= ST_ASSETS_ANYWHERE;
    else if (!strcmp(arg, "--auto-camera"))
        scene_opts.flags |= ST_AUTO_CAMERA;
    else if (!strcmp(arg, "--overlay"))
        overlay = true;
    else
        return false;
    return true;
}

bool st_cmd_scene_value(const char *opt, const char *v, bool *known, st_err *err) {
    bool en = !strcmp(opt, "--enable");
    *known = en || !strcmp(opt, "--disable");
    if (!*known) return true;
    char *list = en ? enable_list : disable_list;
    size_t l = strlen(list);
    if (!v[0] || l + strlen(v) + 2 > sizeof enable_list)
        return st_fail(err, ST_ERR_INPUT,
                       "%s '%s': expected MODULE[,MODULE...] (at most %zu bytes)", opt, v,
                       sizeof enable_list - 2);
    snprintf(list + l, sizeof enable_list - l, "%s%s", l ? "," : "", v);
    return true;
}

bool st_cmd_walk_args(const st_argv_spec *spec, void *ctx, int argc, char **argv,
                      const char **scene, bool *help, st_err *err) {
    *help = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool known = false;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(spec->help, stdout);
            *help = true;
            return true;
        } else if (i + 1 < argc && (!st_cmd_scene_value(a, argv[i + 1], &known, err) ||
                                    (!known && !spec->value(ctx, a, argv[i + 1], &known, err)))) {
            return false;
        } else if (known) {
            i++;
        } else if (spec->flag(ctx, a) || st_cmd_scene_option(a)) {
        } else if (a[0] == '-' || *scene) {
            return st_fail(err, ST_ERR_INPUT, "unexpected argument '%s'%s", a, spec->usage);
        } else {
            *scene = a;
        }
    }
    return true;
}

bool st_load_scene_with(const char *path, char **sets, int num_sets, int width, int height,
                        st_scene *scene, st_err *err) {
    if (!st_scene_load_ex(path, &scene_opts, scene, err)) return false;
    if (overlay) scene->inscatter_overlay = true;
    // Switched before --set so that a parameter of an enabled module is set.
    if (!st_scene_switch_modules(scene, enable_list, disable_list, err)) {
        st_scene_free(scene);
        return false;
    }
    for (int i = 0; i < num_sets; i++) {
        if (!st_scene_set(scene, sets[i], err)) { // its message names the --set
            st_scene_free(scene);
            return false;
        }
    }
    if (width > 0) {
        scene->width = width;
        scene->height = height;
    }
    return true;
}

const char *st_printable(const char *s, char *buf, size_t n) {
    size_t l = 0;
    for (; s && *s && l + 5 < n; s++) {
        unsigned char c = (unsigned char)*s;
        if (c < 0x20 || c == 0x7f)
            l += (size_t)snprintf(buf + l, n - l, "\\x%02x", c);
        else
            buf[l++] = (char)c;
    }
    if (n) buf[l < n ? l : n - 1] = 0;
    return buf;
}

int st_report(const char *cmd, const st_err *err) {
    fprintf(stderr, "strahl %s: %s\n", cmd, err->msg);
    return st_err_exit_code(err);
}

bool st_warn_reference_noise(const char *cmd, const char *ref_path, const st_metrics *m,
                             int ref_spp) {
    if (!st_metrics_noise_dominates(m)) return false;
    double noise = m->ref_noise_rms[3], err = m->rmse_debiased[3];
    fprintf(
        stderr,
        "strahl %s: warning: %s: the reference's noise (rms standard error %.3g) is more than a "
        "third of the error it measures (debiased rmse %.3g, raw %.3g)",
        cmd, ref_path, noise, err, m->rmse[3]);
    // The standard error falls as 1/sqrt(spp): a third of err needs spp (3 noise / err)^2.
    if (ref_spp > 0 && err > 0) {
        double want = ceil(ref_spp * (3 * noise / err) * (3 * noise / err));
        fprintf(stderr, "; render it with at least %.0f spp (it has %d)", fmin(want, 1e9), ref_spp);
    }
    fputc('\n', stderr);
    return true;
}

void st_progress_begin(st_progress_bar *p, const char *label, const char *unit, int total) {
    *p = (st_progress_bar){
        .label = label, .unit = unit, .total = total, .tty = isatty(STDERR_FILENO) == 1};
    p->t0 = p->last = st_now_ms();
}

static void progress_draw(st_progress_bar *p, int done, const char *item, bool final) {
    double el = (st_now_ms() - p->t0) / 1000.0;
    double frac = p->total > 0 ? (double)done / p->total : 1.0;
    char bar[31];
    int fill = (int)(frac * 30);
    for (int k = 0; k < 30; k++)
        bar[k] = k < fill ? '#' : '.';
    bar[30] = 0;
    // \r and clear to the end of the line: the item text changes length.
    fprintf(stderr, "\r\033[K%s [%s] %d/%d %s, %.1f s", p->label, bar, done, p->total, p->unit, el);
    if (!final && done > 0) fprintf(stderr, ", %.1f s left", el / frac - el);
    if (!final && done == 0) fprintf(stderr, ", ETA after the first");
    if (item && !final) fprintf(stderr, "  %.60s", item);
    if (final) fputc('\n', stderr);
    fflush(stderr);
    p->drawn = true;
}

void st_progress_update(st_progress_bar *p, int done, const char *item) {
    if (!p->tty) return;
    double now = st_now_ms();
    // A changed item is drawn at once (bench: one per setting), rows 4x/s.
    if (now - p->t0 < 1000.0 && !item) return;
    if (!item && now - p->last < 250.0) return;
    p->last = now;
    progress_draw(p, done, item, false);
}

void st_progress_end(st_progress_bar *p, int done, const char *extra) {
    if (p->tty) {
        if (p->drawn) progress_draw(p, done, NULL, true);
        return;
    }
    fprintf(stderr, "strahl %s: %d %s in %.1f s%s%s\n", p->label, done, p->unit,
            (st_now_ms() - p->t0) / 1000.0, extra && extra[0] ? ", " : "", extra ? extra : "");
}

const char *st_exr_filter(const st_exr_meta *meta) {
    return meta->filter[0] ? meta->filter : "point";
}

bool st_warn_filter_mismatch(const char *cmd, const char *a_path, const st_exr_meta *a,
                             const char *b_path, const st_exr_meta *b) {
    char pa[64], pb[64]; // attributes are file content: escaped
    const char *fa = st_printable(st_exr_filter(a), pa, sizeof pa),
               *fb = st_printable(st_exr_filter(b), pb, sizeof pb);
    if (!strcmp(fa, fb)) return false;
    fprintf(stderr,
            "strahl %s: warning: %s has pixel filter '%s'%s, %s has '%s'%s: edges differ by "
            "the filter, not the method (render both with one --filter)\n",
            cmd, a_path, fa, a->filter[0] ? "" : " (no strahl.filter attribute)", b_path, fb,
            b->filter[0] ? "" : " (no strahl.filter attribute)");
    return true;
}
