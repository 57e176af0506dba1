// strahl plot: the time-against-error plot of bench CSVs (gnuplot), also
// drawn by `strahl bench --plot`. Curves are named by what varies between
// them ("interleave 1, full"), the first swept parameter runs along each
// curve; the Pareto front, a brute-force baseline and the plugins' defaults
// are marked; the legend sits below the plot; both axes are log scales with
// units.
#define _GNU_SOURCE
#include "cmd_common.h"
#include "plot_csv.h"
#include "st_file.h"
#include "st_cmd.h"
#include "st_module.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

#define MAX_ROWS ST_PLOT_MAX_ROWS
#define MAX_CURVES 64

typedef st_plot_row prow;
typedef st_plot_table ptable;

static const char help_text[] =
    "usage: strahl plot BENCH.csv... -o OUT.png|OUT.svg [--baseline MODULE.PARAM=V,...] [--title "
    "T]\n"
    "Draws the log-log plot of frame time against error from strahl bench CSVs (also\n"
    "concatenated shards): one curve per combination of the parameters that vary,\n"
    "named by them, the first swept parameter along each curve; the Pareto front\n"
    "(settings no faster setting beats in error); the plugins' defaults; a baseline.\n"
    "Each point is labelled with its swept value. Hollow points: the reference is too\n"
    "noisy to resolve that row's error (ref_noise_warning = 1). A log axis has no 0: an\n"
    "error of 0 is a triangle at the axis floor, a quarter of the smallest positive error.\n"
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

// "interleave 1, resolution full": the parameters (other than the first)
// whose values differ between rows, each with its name.
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
        // "resolution half", never a bare "half": the legend names what varies.
        const char *param = strchr(r->name[k], '.') + 1;
        len += (size_t)snprintf(out + len, n - len, "%s%s %s", len ? ", " : "", param, r->value[k]);
    }
    if (!out[0]) snprintf(out, n, "%s", r->name[0]); // one curve: "toth.samples"
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

// Single-quoted gnuplot string: ' doubles, and nothing else is special
// inside (no backquote command or @macro substitution, no backslash
// escapes). A newline would end the command, so control characters, refused
// on input already, become spaces here too.
static void gp_str(FILE *f, const char *s) {
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'') fputc('\'', f);
        fputc((unsigned char)*s < 0x20 || *s == 0x7f ? ' ' : *s, f);
    }
    fputc('\'', f);
}

// Runs gnuplot (posix_spawnp, no shell) with the script on its stdin and its
// stdout, the image, into out_fd; its messages go to log_fd.
static bool run_gnuplot(const char *script, size_t len, int out_fd, int log_fd, st_err *err) {
    int p[2];
    if (pipe2(p, O_CLOEXEC) != 0)
        return st_fail(err, ST_ERR_RUNTIME, "cannot start gnuplot: %s", strerror(errno));
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, p[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&fa, out_fd, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&fa, log_fd, STDERR_FILENO);
    char *const argv[] = {"gnuplot", NULL};
    pid_t pid;
    int rc = posix_spawnp(&pid, "gnuplot", &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    close(p[0]);
    if (rc != 0) {
        close(p[1]);
        return st_fail(err, ST_ERR_RUNTIME, "cannot run gnuplot (is gnuplot-nox installed?): %s",
                       strerror(rc));
    }
    // gnuplot may exit before reading everything: EPIPE, not a signal.
    struct sigaction ign = {.sa_handler = SIG_IGN}, old;
    sigaction(SIGPIPE, &ign, &old);
    bool wrote = true;
    for (size_t at = 0; at < len;) {
        ssize_t w = write(p[1], script + at, len - at);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            wrote = false;
            break;
        }
        at += (size_t)w;
    }
    close(p[1]);
    sigaction(SIGPIPE, &old, NULL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (!wrote || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return st_fail(err, ST_ERR_RUNTIME, "gnuplot failed");
    return true;
}

// Every "M.P=V" of the baseline is one of the row's assignments.
static bool is_baseline(const prow *r, const char *baseline) {
    char copy[512];
    snprintf(copy, sizeof copy, "%s", baseline);
    bool all = true;
    for (char *tok = strtok(copy, ","); tok && all; tok = strtok(NULL, ",")) {
        bool found = false;
        for (int k = 0; k < r->np && !found; k++) {
            char a[130];
            snprintf(a, sizeof a, "%s=%s", r->name[k], r->value[k]);
            found = !strcmp(a, tok);
        }
        all = found;
    }
    return all;
}

// Each row's curve (one per label), and whether it is the plugin defaults or
// the baseline.
static bool assign_curves(ptable *t, const char *out, const char *baseline, bool multi_scene,
                          char (*labels)[256], int *nc, st_err *err) {
    *nc = 0;
    for (int i = 0; i < t->n; i++) {
        prow *r = &t->rows[i];
        char l[256];
        curve_label(t, r, multi_scene, l, sizeof l);
        int c = 0;
        while (c < *nc && strcmp(labels[c], l))
            c++;
        if (c == *nc) {
            if (*nc == MAX_CURVES)
                return st_fail(err, ST_ERR_INPUT, "%s: more than %d curves", out, MAX_CURVES);
            snprintf(labels[(*nc)++], 256, "%s", l);
        }
        r->curve = c;
        r->is_default = true;
        for (int k = 0; k < r->np && r->is_default; k++)
            r->is_default = equals_default(r->name[k], r->value[k]);
        if (baseline && baseline[0]) r->is_baseline = is_baseline(r, baseline);
    }
    return true;
}

// A log axis has no 0: an error of 0 (a reference noisier than the error it
// measures gives one) is drawn at this floor, a quarter of the smallest
// positive error (1e-3 without one), with its own marker.
static double error_floor(const ptable *t) {
    double m = INFINITY;
    for (int i = 0; i < t->n; i++)
        if (t->rows[i].err > 0 && t->rows[i].err < m) m = t->rows[i].err;
    return isfinite(m) ? m / 4 : 1e-3;
}

static double shown_err(const prow *r, double floor_y) {
    return r->err > 0 ? r->err : floor_y;
}

// Filled circle; hollow where the reference is too noisy to resolve the
// error; a triangle (down) for an error of 0 drawn at the floor.
static int point_type(const prow *r) {
    bool zero = !(r->err > 0);
    return r->noisy_ref ? (zero ? 10 : 6) : (zero ? 11 : 7);
}

// The swept value as a point label: it sits between double quotes in the
// datablock, so only letters, digits and . + - _ pass.
static void point_label(const prow *r, char *out, size_t n) {
    size_t k = 0;
    for (const char *v = r->value[0]; *v && k + 1 < n; v++)
        out[k++] = (isalnum((unsigned char)*v) || strchr(".+-_", *v)) ? *v : '_';
    out[k] = 0;
}

// The data as a gnuplot datablock: one block (gnuplot `index`) per curve
// (time, error, point type, label), then the front, the baseline, the
// defaults (*nb, *nd: their points).
static void write_data(FILE *d, ptable *t, int nc, double fy, int *nb, int *nd) {
    prow *sorted[MAX_ROWS];
    for (int i = 0; i < t->n; i++)
        sorted[i] = &t->rows[i];
    fprintf(d, "$data << EOD\n");
    qsort(sorted, (size_t)t->n, sizeof sorted[0], cmp_x);
    for (int c = 0, i = 0; c < nc; c++) {
        for (; i < t->n && sorted[i]->curve == c; i++) {
            char label[64];
            point_label(sorted[i], label, sizeof label);
            fprintf(d, "%.9g %.9g %d \"%s\"\n", sorted[i]->ms, shown_err(sorted[i], fy),
                    point_type(sorted[i]), label);
        }
        fprintf(d, "\n\n");
    }
    // The front of each scene (times and errors of different scenes do not
    // compete), as separate line segments of one block.
    qsort(sorted, (size_t)t->n, sizeof sorted[0], cmp_ms);
    for (int i = 0; i < t->n; i++) {
        bool first = true;
        for (int k = 0; k < i && first; k++)
            first = strcmp(sorted[k]->scene, sorted[i]->scene) != 0;
        if (!first) continue;
        double best = INFINITY;
        for (int k = i; k < t->n; k++)
            if (!strcmp(sorted[k]->scene, sorted[i]->scene) && sorted[k]->err < best) {
                best = sorted[k]->err;
                fprintf(d, "%.9g %.9g\n", sorted[k]->ms, shown_err(sorted[k], fy));
            }
        fputc('\n', d); // a blank line breaks the line between scenes
    }
    // gnuplot skips empty blocks in its index count: write only those with points.
    *nb = *nd = 0;
    for (int i = 0; i < t->n; i++) {
        *nb += t->rows[i].is_baseline;
        *nd += t->rows[i].is_default;
    }
    if (*nb) fprintf(d, "\n\n");
    for (int i = 0; i < t->n; i++)
        if (t->rows[i].is_baseline)
            fprintf(d, "%.9g %.9g\n", t->rows[i].ms, shown_err(&t->rows[i], fy));
    if (*nd) fprintf(d, "\n\n");
    for (int i = 0; i < t->n; i++)
        if (t->rows[i].is_default)
            fprintf(d, "%.9g %.9g\n", t->rows[i].ms, shown_err(&t->rows[i], fy));
    fprintf(d, "EOD\n");
}

// One point, or points of one time or one error, give gnuplot an empty
// range on a log axis: widen it by 1.5x each way.
static void write_ranges(FILE *f, const ptable *t, double fy) {
    double x0 = INFINITY, x1 = 0, y0 = INFINITY, y1 = 0;
    for (int i = 0; i < t->n; i++) {
        double y = shown_err(&t->rows[i], fy);
        x0 = fmin(x0, t->rows[i].ms);
        x1 = fmax(x1, t->rows[i].ms);
        y0 = fmin(y0, y);
        y1 = fmax(y1, y);
    }
    // Such a range may hold no decade: a tic at the value itself names it.
    if (x0 == x1)
        fprintf(f, "set xrange [%.9g:%.9g]\nset xtics add (%.9g)\n", x0 / 1.5, x1 * 1.5, x0);
    if (y0 == y1)
        fprintf(f, "set yrange [%.9g:%.9g]\nset ytics add (%.9g)\n", y0 / 1.5, y1 * 1.5, y0);
}

// The terminal, axes and title.
static void write_setup(FILE *f, const ptable *t, const char *out, const char *title,
                        bool multi_scene) {
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
    snprintf(def_title, sizeof def_title,
             "%.*s on %s (along each curve: %s, each point labelled with its value)",
             (int)strcspn(r0->name[0], "."), r0->name[0],
             multi_scene ? "several scenes" : r0->scene, along);
    fprintf(f, "set terminal %s size 900,700 font ',10'\n", svg ? "svg" : "pngcairo");
    fprintf(f, "set logscale xy\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\nset format "
               "x '%%g'\n"
               "set format y '%%g'\nset xlabel 'median frame time [ms] (log scale)'\nset ylabel ");
    gp_str(f, ylabel);
    fprintf(f, " noenhanced\nset title ");
    gp_str(f, title && title[0] ? title : def_title);
    fprintf(f, " noenhanced\nset key outside below center horizontal Left reverse width 1 "
               "noenhanced\nset offsets graph 0.05, graph "
               "0.05, graph 0.1, graph 0.1\n");
}

// Legend entries for the markers that carry a meaning of their own: hollow
// (the reference is too noisy) and the triangle (error 0 at the floor).
static void write_marker_keys(FILE *f, const ptable *t, double fy) {
    bool noisy = false, zero = false;
    for (int i = 0; i < t->n; i++) {
        noisy |= t->rows[i].noisy_ref;
        zero |= !(t->rows[i].err > 0);
    }
    if (noisy)
        fprintf(f, ", \\\n     keyentry with points pt 6 ps 0.9 lc rgb 'black' title 'hollow: the "
                   "reference is too noisy to resolve this error (ref_noise_warning)'");
    if (zero)
        fprintf(f,
                ", \\\n     keyentry with points pt 11 ps 0.9 lc rgb 'black' title 'error 0, "
                "drawn at the axis floor %.3g'",
                fy);
}

// The plot command: per curve its line, its points (pt from the data) and
// their labels; the front, the baseline and the defaults.
static void write_plot(FILE *f, char (*labels)[256], int nc, int nb, int nd, const char *baseline) {
    fprintf(f, "plot ");
    for (int c = 0; c < nc; c++) {
        fprintf(f, "$data index %d using 1:2 with lines lt %d lw 1.5 title ", c, c + 1);
        gp_str(f, labels[c]);
        fprintf(f,
                ", \\\n     $data index %d using 1:2:3 with points lt %d pt variable ps 0.9 "
                "notitle, \\\n     $data index %d using 1:2:4 with labels tc lt %d offset char "
                "0.5,0.5 left font ',7' noenhanced notitle, \\\n     ",
                c, c + 1, c, c + 1);
    }
    fprintf(f, "$data index %d using 1:2 with steps lw 2 dt 2 lc rgb 'black' title 'Pareto front'",
            nc);
    if (nb) {
        fprintf(f, ", \\\n     ");
        fprintf(f, "$data index %d using 1:2 with points pt 6 ps 3 lw 2 lc rgb '#d62728' title ",
                nc + 1);
        char bl[600];
        snprintf(bl, sizeof bl, "baseline (%s)", baseline);
        gp_str(f, bl);
    }
    if (nd) {
        fprintf(f, ", \\\n     ");
        fprintf(
            f,
            "$data index %d using 1:2 with points pt 4 ps 3 lw 2 lc rgb '#2ca02c' title 'plugin "
            "defaults'",
            nc + 1 + (nb > 0));
    }
}

// gnuplot's error from its messages: the last line that is not a warning
// ("Warning: empty x range" may come first and is not why it failed), its
// leading blanks and control characters gone; "" when there is none.
static void gnuplot_error(FILE *log, char *msg, size_t n) {
    static char text[16384];
    rewind(log);
    size_t got = fread(text, 1, sizeof text - 1, log);
    text[got] = 0;
    msg[0] = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        while (*line == ' ' || *line == '\t')
            line++;
        if (!*line || strstr(line, "Warning:") || strstr(line, "warning:") || *line == '^')
            continue;
        size_t k = 0;
        for (; line[k] && k + 1 < n; k++)
            msg[k] = (unsigned char)line[k] < 0x20 || line[k] == 0x7f ? ' ' : line[k];
        msg[k] = 0;
    }
}

// Runs gnuplot on the script into `out` (atomically). gnuplot's chatter
// (e.g. "empty x range" for a single point) goes to an anonymous temporary
// file that is shown only when it fails.
static bool plot_to(const char *script, size_t script_len, const char *out, st_err *err) {
    st_outfile o;
    FILE *log = tmpfile();
    if (!log || !st_out_begin(&o, out, err)) {
        if (log) fclose(log);
        if (!log) return st_fail(err, ST_ERR_RUNTIME, "cannot create a temporary file");
        return false;
    }
    bool ok = run_gnuplot(script, script_len, o.fd, fileno(log), err);
    if (!ok) {
        char msg[512];
        gnuplot_error(log, msg, sizeof msg);
        st_out_abort(&o);
        fclose(log);
        return st_fail(err, ST_ERR_RUNTIME, "gnuplot failed drawing %s%s%s", out,
                       msg[0] ? ": " : "", msg);
    }
    fclose(log);
    return st_out_commit(&o, err);
}

static bool draw(ptable *t, const char *out, const char *baseline, const char *title, st_err *err) {
    bool multi_scene = false;
    for (int i = 1; i < t->n; i++)
        multi_scene |= strcmp(t->rows[i].scene, t->rows[0].scene) != 0;
    char labels[MAX_CURVES][256];
    int nc = 0, nb = 0, nd = 0;
    if (!assign_curves(t, out, baseline, multi_scene, labels, &nc, err)) return false;
    // The script goes to gnuplot's stdin with the data inline (a datablock)
    // and the image comes back on its stdout: no path reaches gnuplot.
    char *script = NULL;
    size_t script_len = 0;
    FILE *f = open_memstream(&script, &script_len);
    if (!f) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    const double fy = error_floor(t);
    write_data(f, t, nc, fy, &nb, &nd);
    if (baseline && baseline[0] && !nb) {
        fclose(f);
        free(script);
        return st_fail(err, ST_ERR_INPUT, "--baseline %s: no row of the CSV has this setting",
                       baseline);
    }
    write_setup(f, t, out, title, multi_scene);
    write_ranges(f, t, fy);
    write_plot(f, labels, nc, nb, nd, baseline);
    write_marker_keys(f, t, fy);
    fputc('\n', f);
    if (fclose(f) != 0) {
        free(script);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    }
    bool ok = plot_to(script, script_len, out, err);
    free(script);
    return ok;
}

bool st_plot_check_baseline(const char *baseline, st_err *err) {
    if (!baseline) return true;
    if (!baseline[0] || strlen(baseline) > 500 || st_plot_has_control(baseline))
        return st_fail(err, ST_ERR_INPUT,
                       "--baseline: expected MODULE.PARAM=VALUE,... (at most 500 characters, no "
                       "control characters)");
    for (const char *p = baseline; *p;) {
        size_t n = strcspn(p, ",");
        const char *dot = memchr(p, '.', n), *eq = memchr(p, '=', n);
        if (!dot || !eq || dot > eq || dot == p || eq == dot + 1 || eq + 1 == p + n)
            return st_fail(err, ST_ERR_INPUT, "--baseline %s: '%.*s' is not MODULE.PARAM=VALUE",
                           baseline, (int)n, p);
        p += n + (p[n] == ',');
        if (p[-1] == ',' && !*p)
            return st_fail(err, ST_ERR_INPUT, "--baseline %s: empty setting after ','", baseline);
    }
    return true;
}

bool st_plot_check_title(const char *title, st_err *err) {
    if (title && st_plot_has_control(title))
        return st_fail(err, ST_ERR_INPUT,
                       "--title: contains a control character (a newline?); give one line");
    return true;
}

bool st_plot_csv(const char *const *csvs, int n, const char *out, const char *metric,
                 const char *baseline, const char *title, st_err *err) {
    static const char *const exts[] = {"png", "svg", NULL};
    const char *inputs[65];
    int ni = 0;
    for (; ni < n && ni < 64; ni++)
        inputs[ni] = csvs[ni];
    inputs[ni] = NULL;
    if (!st_check_output("-o", out, exts, inputs, err) || !st_plot_check_baseline(baseline, err) ||
        !st_plot_check_title(title, err))
        return false;
    ptable t = {.rows = calloc(MAX_ROWS, sizeof(prow))};
    if (!t.rows) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    if (metric) snprintf(t.metric, sizeof t.metric, "%s", metric);
    bool ok = true;
    for (int i = 0; i < n && ok; i++)
        ok = st_plot_read_csv(csvs[i], &t, err);
    if (ok && !t.n)
        ok = st_fail(err, ST_ERR_INPUT, "%s%s: no rows to plot (only headers or nothing)", csvs[0],
                     n > 1 ? " and the other CSVs" : "");
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
