// strahl plot: the time-against-error plot of bench CSVs (gnuplot), also
// drawn by `strahl bench --plot`. Curves are named by what varies between
// them ("interleave 1, full"), the first swept parameter runs along each
// curve; the Pareto front, a brute-force baseline and the plugins' defaults
// are marked; the legend sits below the plot; both axes are log scales with
// units.
#define _GNU_SOURCE
#include "cmd_common.h"
#include "st_cmd.h"
#include "st_module.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define MAX_ROWS 4096
#define MAX_PARAMS 8
#define MAX_CURVES 64

typedef struct {
    char scene[128];
    int np;
    char name[MAX_PARAMS][64]; // "toth.samples"
    char value[MAX_PARAMS][64];
    double ms, err, x;
    int curve;
    bool is_default, is_baseline;
} prow;

typedef struct {
    prow *rows;
    int n;
    char metric[64];
} ptable;

static const char help_text[] =
    "usage: strahl plot BENCH.csv... -o OUT.png|OUT.svg [--baseline MODULE.PARAM=V,...] [--title "
    "T]\n"
    "Draws the log-log plot of frame time against error from strahl bench CSVs (also\n"
    "concatenated shards): one curve per combination of the parameters that vary,\n"
    "named by them, the first swept parameter along each curve; the Pareto front\n"
    "(settings no faster setting beats in error); the plugins' defaults; a baseline.\n"
    "  -o OUT.png|OUT.svg        output (required; written atomically)\n"
    "  --baseline M.P=V,...      mark the setting with these values, e.g. the brute-force\n"
    "                            one (default: none)\n"
    "  --title T                 plot title (default: MODULE on SCENE)\n"
    "  -h, --help                this text\n"
    "example:\n"
    "  strahl plot toth.csv -o toth.png --baseline "
    "toth.samples=256,toth.interleave=1,toth.resolution=full\n";

static bool is_number(const char *s) {
    char *e;
    strtod(s, &e);
    return e != s && !*e;
}

// Splits a CSV line into at most max fields (in place).
static int split(char *line, char **f, int max) {
    int n = 0;
    for (char *p = line; p && n < max;) {
        f[n++] = p;
        p = strchr(p, ',');
        if (p) *p++ = 0;
    }
    return n;
}

static bool read_csv(const char *path, ptable *t, st_err *err) {
    FILE *f = fopen(path, "r");
    if (!f) return st_fail(err, ST_ERR_INPUT, "%s: cannot open", path);
    char line[8192];
    int ln = 0;
    while (fgets(line, sizeof line, f)) {
        ln++;
        line[strcspn(line, "\r\n")] = 0;
        if (!line[0]) continue;
        char *fld[32];
        int nf = split(line, fld, 32);
        if (!strcmp(fld[0], "scene")) { // a header (shard 1, or a concatenation)
            if (nf > 8 && !strncmp(fld[8], "error_", 6))
                snprintf(t->metric, sizeof t->metric, "%s", fld[8] + 6);
            continue;
        }
        if (nf < 9) {
            fclose(f);
            return st_fail(err, ST_ERR_INPUT,
                           "%s:%d: expected a strahl bench row (9 or more fields)", path, ln);
        }
        if (t->n == MAX_ROWS) {
            fclose(f);
            return st_fail(err, ST_ERR_INPUT, "%s: more than %d rows", path, MAX_ROWS);
        }
        prow *r = &t->rows[t->n];
        memset(r, 0, sizeof *r);
        const char *slash = strrchr(fld[0], '/');
        snprintf(r->scene, sizeof r->scene, "%s", slash ? slash + 1 : fld[0]);
        char *dot = strrchr(r->scene, '.');
        if (dot && !strcmp(dot, ".json")) *dot = 0;
        char *e1, *e2;
        r->ms = strtod(fld[5], &e1);
        r->err = strtod(fld[8], &e2);
        if (*e1 || *e2 || !(r->ms > 0) || !isfinite(r->err)) {
            fclose(f);
            return st_fail(err, ST_ERR_INPUT, "%s:%d: bad frame time '%s' or error '%s'", path, ln,
                           fld[5], fld[8]);
        }
        for (char *tok = strtok(fld[1], " "); tok && r->np < MAX_PARAMS; tok = strtok(NULL, " ")) {
            char *eq = strchr(tok, '=');
            if (!eq) continue;
            snprintf(r->name[r->np], 64, "%.*s", (int)(eq - tok), tok);
            snprintf(r->value[r->np], 64, "%s", eq + 1);
            r->np++;
        }
        if (!r->np) {
            fclose(f);
            return st_fail(err, ST_ERR_INPUT, "%s:%d: setting '%s' has no MODULE.PARAM=VALUE", path,
                           ln, fld[1]);
        }
        r->x = is_number(r->value[0]) ? atof(r->value[0]) : 0;
        t->n++;
    }
    fclose(f);
    return true;
}

// Whether the value of `name` (MODULE.PARAM) equals the plugin's default.
static bool equals_default(const char *name, const char *value) {
    char module[64];
    const char *dot = strchr(name, '.');
    if (!dot) return false;
    snprintf(module, sizeof module, "%.*s", (int)(dot - name), name);
    st_err err = {0};
    st_plugin_lib *lib = st_plugin_open(module, &err);
    if (!lib) return false;
    const st_plugin *p = st_plugin_desc(lib);
    bool eq = false;
    for (int k = 0; k < p->num_params; k++) {
        const st_param_def *d = &p->params[k];
        if (strcmp(d->name, dot + 1)) continue;
        char def[64];
        st_param_format(d, d->def, def, sizeof def);
        eq =
            !strcmp(def, value) || (is_number(def) && is_number(value) && atof(def) == atof(value));
    }
    st_plugin_close(lib);
    return eq;
}

// "interleave 1, full": the parameters (other than the first) whose values
// differ between rows; numbers and booleans keep the parameter's name.
static void curve_label(const ptable *t, const prow *r, bool multi_scene, char *out, size_t n) {
    size_t len = 0;
    out[0] = 0;
    if (multi_scene) len += (size_t)snprintf(out, n, "%s", r->scene);
    for (int k = 1; k < r->np && len < n; k++) {
        bool varies = false;
        for (int i = 0; i < t->n && !varies; i++)
            for (int q = 0; q < t->rows[i].np; q++)
                if (!strcmp(t->rows[i].name[q], r->name[k]) &&
                    strcmp(t->rows[i].value[q], r->value[k]))
                    varies = true;
        if (!varies) continue;
        const char *param = strchr(r->name[k], '.') + 1;
        const char *v = r->value[k];
        bool named = is_number(v) || !strcmp(v, "true") || !strcmp(v, "false");
        len += (size_t)snprintf(out + len, n - len, "%s%s%s%s", len ? ", " : "", named ? param : "",
                                named ? " " : "", v);
    }
    if (!out[0]) snprintf(out, n, "%.*s", (int)strcspn(r->name[0], "."), r->name[0]);
}

static int cmp_ms(const void *a, const void *b) {
    const prow *x = *(prow *const *)a, *y = *(prow *const *)b;
    return (x->ms > y->ms) - (x->ms < y->ms);
}
static int cmp_x(const void *a, const void *b) {
    const prow *x = *(prow *const *)a, *y = *(prow *const *)b;
    if (x->curve != y->curve) return x->curve - y->curve;
    return (x->x > y->x) - (x->x < y->x);
}

// Single-quoted gnuplot string: ' doubles.
static void gp_str(FILE *f, const char *s) {
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'') fputc('\'', f);
        fputc(*s, f);
    }
    fputc('\'', f);
}

static bool draw(ptable *t, const char *out, const char *baseline, const char *title, st_err *err) {
    if (!t->n) return st_fail(err, ST_ERR_INPUT, "%s: no rows to plot", out);
    bool multi_scene = false;
    for (int i = 1; i < t->n; i++)
        multi_scene |= strcmp(t->rows[i].scene, t->rows[0].scene) != 0;
    char labels[MAX_CURVES][256];
    int nc = 0;
    for (int i = 0; i < t->n; i++) {
        prow *r = &t->rows[i];
        char l[256];
        curve_label(t, r, multi_scene, l, sizeof l);
        int c = 0;
        while (c < nc && strcmp(labels[c], l))
            c++;
        if (c == nc) {
            if (nc == MAX_CURVES)
                return st_fail(err, ST_ERR_INPUT, "%s: more than %d curves", out, MAX_CURVES);
            snprintf(labels[nc++], sizeof labels[0], "%s", l);
        }
        r->curve = c;
        r->is_default = true;
        for (int k = 0; k < r->np && r->is_default; k++)
            r->is_default = equals_default(r->name[k], r->value[k]);
        if (baseline && baseline[0]) {
            // Every "M.P=V" of the baseline is one of the row's assignments.
            char copy[512];
            snprintf(copy, sizeof copy, "%s", baseline);
            r->is_baseline = true;
            for (char *tok = strtok(copy, ","); tok && r->is_baseline; tok = strtok(NULL, ",")) {
                bool found = false;
                for (int k = 0; k < r->np && !found; k++) {
                    char a[130];
                    snprintf(a, sizeof a, "%s=%s", r->name[k], r->value[k]);
                    found = !strcmp(a, tok);
                }
                r->is_baseline = found;
            }
        }
    }
    prow *sorted[MAX_ROWS];
    for (int i = 0; i < t->n; i++)
        sorted[i] = &t->rows[i];
    char dat[1200], gp[1200], tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp-%d", out, (int)getpid());
    snprintf(dat, sizeof dat, "%s.dat", tmp);
    snprintf(gp, sizeof gp, "%s.gp", tmp);
    FILE *d = fopen(dat, "w");
    if (!d) return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write plot data", dat);
    // Blocks (gnuplot `index`): one per curve, then the front, the baseline, the defaults.
    qsort(sorted, (size_t)t->n, sizeof sorted[0], cmp_x);
    for (int c = 0, i = 0; c < nc; c++) {
        fprintf(d, "# %s\n", labels[c]);
        for (; i < t->n && sorted[i]->curve == c; i++)
            fprintf(d, "%.9g %.9g\n", sorted[i]->ms, sorted[i]->err);
        fprintf(d, "\n\n");
    }
    // The front of each scene (times and errors of different scenes do not
    // compete), as separate line segments of one block.
    qsort(sorted, (size_t)t->n, sizeof sorted[0], cmp_ms);
    fprintf(d, "# Pareto front\n");
    for (int i = 0; i < t->n; i++) {
        bool first = true;
        for (int k = 0; k < i && first; k++)
            first = strcmp(sorted[k]->scene, sorted[i]->scene) != 0;
        if (!first) continue;
        double best = INFINITY;
        for (int k = i; k < t->n; k++)
            if (!strcmp(sorted[k]->scene, sorted[i]->scene) && sorted[k]->err < best) {
                best = sorted[k]->err;
                fprintf(d, "%.9g %.9g\n", sorted[k]->ms, sorted[k]->err);
            }
        fputc('\n', d); // a blank line breaks the line between scenes
    }
    // gnuplot skips empty blocks in its index count: write only those with points.
    int nb = 0, nd = 0;
    for (int i = 0; i < t->n; i++) {
        nb += t->rows[i].is_baseline;
        nd += t->rows[i].is_default;
    }
    if (nb) fprintf(d, "\n\n# baseline\n");
    for (int i = 0; i < t->n; i++)
        if (t->rows[i].is_baseline) fprintf(d, "%.9g %.9g\n", t->rows[i].ms, t->rows[i].err);
    if (nd) fprintf(d, "\n\n# defaults\n");
    for (int i = 0; i < t->n; i++)
        if (t->rows[i].is_default) fprintf(d, "%.9g %.9g\n", t->rows[i].ms, t->rows[i].err);
    bool dok = fclose(d) == 0;

    FILE *f = dok ? fopen(gp, "w") : NULL;
    if (!f) {
        unlink(dat);
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write gnuplot script", gp);
    }
    const char *dot = strrchr(out, '.');
    bool svg = dot && !strcasecmp(dot, ".svg");
    const char *m = t->metric[0] ? t->metric : "error";
    bool unitless = !strcmp(m, "relmse");
    char ylabel[256], def_title[256], along[64];
    snprintf(ylabel, sizeof ylabel, "%s against the reference %s (log scale)", m,
             unitless ? "[1]" : "[W sr^-1 m^-2]");
    const prow *r0 = &t->rows[0];
    snprintf(along, sizeof along, "%s",
             strchr(r0->name[0], '.') ? strchr(r0->name[0], '.') + 1 : r0->name[0]);
    snprintf(def_title, sizeof def_title, "%.*s on %s (along each curve: %s)",
             (int)strcspn(r0->name[0], "."), r0->name[0],
             multi_scene ? "several scenes" : r0->scene, along);
    fprintf(f, "set terminal %s size 900,700 font ',10'\nset output ", svg ? "svg" : "pngcairo");
    gp_str(f, tmp);
    fprintf(f, "\nset logscale xy\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\nset format "
               "x '%%g'\n"
               "set format y '%%g'\nset xlabel 'median frame time [ms] (log scale)'\nset ylabel ");
    gp_str(f, ylabel);
    fprintf(f, " noenhanced\nset title ");
    gp_str(f, title && title[0] ? title : def_title);
    fprintf(f, " noenhanced\nset key outside below center horizontal Left reverse width 1 "
               "noenhanced\nset offsets graph 0.05, graph "
               "0.05, graph 0.1, graph 0.1\nplot ");
    for (int c = 0; c < nc; c++) {
        gp_str(f, dat);
        fprintf(f, " index %d using 1:2 with linespoints lw 1.5 pt 7 ps 0.7 title ", c);
        gp_str(f, labels[c]);
        fprintf(f, ", \\\n     ");
    }
    gp_str(f, dat);
    fprintf(f, " index %d using 1:2 with steps lw 2 dt 2 lc rgb 'black' title 'Pareto front'", nc);
    if (nb) {
        fprintf(f, ", \\\n     ");
        gp_str(f, dat);
        fprintf(f, " index %d using 1:2 with points pt 6 ps 3 lw 2 lc rgb '#d62728' title ",
                nc + 1);
        char bl[600];
        snprintf(bl, sizeof bl, "baseline (%s)", baseline);
        gp_str(f, bl);
    }
    if (nd) {
        fprintf(f, ", \\\n     ");
        gp_str(f, dat);
        fprintf(f,
                " index %d using 1:2 with points pt 4 ps 3 lw 2 lc rgb '#2ca02c' title 'plugin "
                "defaults'",
                nc + 1 + (nb > 0));
    }
    fputc('\n', f);
    if (fclose(f) != 0) {
        unlink(dat);
        unlink(gp);
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write gnuplot script", gp);
    }
    // gnuplot's chatter (e.g. "empty x range" for a single point) goes to a
    // log that is shown only when it fails.
    char log[1300], cmd[4000];
    snprintf(log, sizeof log, "%s.log", tmp);
    snprintf(cmd, sizeof cmd, "gnuplot '%s' >'%s' 2>&1", gp, log);
    int rc = system(cmd);
    unlink(gp);
    unlink(dat);
    if (rc != 0) {
        char msg[512] = "";
        FILE *lf = fopen(log, "r");
        if (lf) {
            size_t got = fread(msg, 1, sizeof msg - 1, lf);
            msg[got] = 0;
            msg[strcspn(msg, "\n")] = 0;
            fclose(lf);
        }
        unlink(log);
        unlink(tmp);
        return st_fail(err, ST_ERR_RUNTIME,
                       "gnuplot failed drawing %s (is gnuplot-nox installed?)%s%s", out,
                       msg[0] ? ": " : "", msg);
    }
    unlink(log);
    if (rename(tmp, out) != 0) {
        unlink(tmp);
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write", out);
    }
    return true;
}

static bool plot_ext_ok(const char *out) {
    const char *dot = strrchr(out, '.');
    return dot && (!strcasecmp(dot, ".png") || !strcasecmp(dot, ".svg"));
}

bool st_plot_csv(const char *const *csvs, int n, const char *out, const char *metric,
                 const char *baseline, const char *title, st_err *err) {
    if (!plot_ext_ok(out)) return st_fail(err, ST_ERR_INPUT, "%s: the plot is a .png or .svg", out);
    ptable t = {.rows = calloc(MAX_ROWS, sizeof(prow))};
    if (!t.rows) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    if (metric) snprintf(t.metric, sizeof t.metric, "%s", metric);
    bool ok = true;
    for (int i = 0; i < n && ok; i++)
        ok = read_csv(csvs[i], &t, err);
    ok = ok && draw(&t, out, baseline, title, err);
    free(t.rows);
    return ok;
}

int st_cmd_plot(int argc, char **argv) {
    const char *csvs[64], *out = NULL, *baseline = NULL, *title = NULL;
    int n = 0;
    st_err err = {0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        bool nx = i + 1 < argc;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(help_text, stdout);
            return ST_EXIT_OK;
        } else if (!strcmp(a, "-o") && nx) {
            out = argv[++i];
        } else if (!strcmp(a, "--baseline") && nx) {
            baseline = argv[++i];
        } else if (!strcmp(a, "--title") && nx) {
            title = argv[++i];
        } else if (a[0] == '-' || n == 64) {
            return st_fail(&err, ST_ERR_INPUT, "unexpected argument '%s' (see strahl plot --help)",
                           a),
                   st_report("plot", &err);
        } else {
            csvs[n++] = a;
        }
    }
    if (!n || !out)
        return st_fail(&err, ST_ERR_INPUT,
                       "usage: strahl plot BENCH.csv... -o OUT.png|OUT.svg (see --help)"),
               st_report("plot", &err);
    if (!st_plot_csv(csvs, n, out, NULL, baseline, title, &err)) return st_report("plot", &err);
    return ST_EXIT_OK;
}
