#define _POSIX_C_SOURCE 200809L
#include "plot_csv.h"
#include "st_file.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool st_plot_has_control(const char *s) {
    for (; *s; s++)
        if ((unsigned char)*s < 0x20 || *s == 0x7f) return true;
    return false;
}

// Where strahl bench writes ref_noise_warning (0-based), the last of its 21 columns.
#define NOISE_COL_DEFAULT 20

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

static bool parse_line(char *line, const char *name, int ln, st_plot_table *t, st_err *err) {
    if (st_plot_has_control(line))
        return st_fail(err, ST_ERR_INPUT, "%s:%d: control character in the line", name, ln);
    char *fld[32];
    int nf = split(line, fld, 32);
    if (!strcmp(fld[0], "scene")) { // a header (shard 1, or a concatenation)
        if (nf > 8 && !strncmp(fld[8], "error_", 6))
            snprintf(t->metric, sizeof t->metric, "%s", fld[8] + 6);
        t->noise_col = 0;
        for (int k = 0; k < nf; k++)
            if (!strcmp(fld[k], "ref_noise_warning")) t->noise_col = k + 1;
        return true;
    }
    if (nf < 9)
        return st_fail(err, ST_ERR_INPUT, "%s:%d: expected a strahl bench row (9 or more fields)",
                       name, ln);
    if (t->n == ST_PLOT_MAX_ROWS)
        return st_fail(err, ST_ERR_INPUT, "%s: more than %d rows", name, ST_PLOT_MAX_ROWS);
    st_plot_row *r = &t->rows[t->n];
    memset(r, 0, sizeof *r);
    const char *slash = strrchr(fld[0], '/');
    snprintf(r->scene, sizeof r->scene, "%s", slash ? slash + 1 : fld[0]);
    char *dot = strrchr(r->scene, '.');
    if (dot && !strcmp(dot, ".json")) *dot = 0;
    char *e1, *e2;
    r->ms = strtod(fld[5], &e1);
    r->err = strtod(fld[8], &e2);
    if (e1 == fld[5] || e2 == fld[8] || *e1 || *e2 || !(r->ms > 0) || !isfinite(r->ms) ||
        !isfinite(r->err))
        return st_fail(err, ST_ERR_INPUT, "%s:%d: bad frame time '%.64s' or error '%.64s'", name,
                       ln, fld[5], fld[8]);
    char *save = NULL;
    for (char *tok = strtok_r(fld[1], " ", &save); tok && r->np < ST_PLOT_MAX_PARAMS;
         tok = strtok_r(NULL, " ", &save)) {
        char *eq = strchr(tok, '='), *pd = strchr(tok, '.');
        if (!eq) continue;
        if (!pd || pd > eq || pd == tok || eq == pd + 1)
            return st_fail(err, ST_ERR_INPUT, "%s:%d: '%.64s' is not MODULE.PARAM=VALUE", name, ln,
                           tok);
        snprintf(r->name[r->np], 64, "%.*s", (int)(eq - tok) < 63 ? (int)(eq - tok) : 63, tok);
        snprintf(r->value[r->np], 64, "%s", eq + 1);
        r->np++;
    }
    if (!r->np)
        return st_fail(err, ST_ERR_INPUT, "%s:%d: setting '%.64s' has no MODULE.PARAM=VALUE", name,
                       ln, fld[1]);
    // Rows without a header (shards 2..N) have the column where bench writes it.
    int nc = t->noise_col ? t->noise_col - 1 : nf == NOISE_COL_DEFAULT + 1 ? NOISE_COL_DEFAULT : -1;
    r->noisy_ref = nc >= 0 && nc < nf && !strcmp(fld[nc], "1");
    r->x = is_number(r->value[0]) ? atof(r->value[0]) : 0;
    if (!isfinite(r->x)) r->x = 0;
    t->n++;
    return true;
}

bool st_plot_parse_csv(const char *text, size_t len, const char *name, st_plot_table *t,
                       st_err *err) {
    if (memchr(text, 0, len))
        return st_fail(err, ST_ERR_INPUT, "%s: a NUL byte: not a CSV text file", name);
    char line[8192];
    int ln = 0;
    for (size_t at = 0; at < len;) {
        const char *nl = memchr(text + at, '\n', len - at);
        size_t n = nl ? (size_t)(nl - (text + at)) : len - at;
        ln++;
        if (n >= sizeof line)
            return st_fail(err, ST_ERR_INPUT, "%s:%d: line longer than %zu bytes", name, ln,
                           sizeof line - 1);
        memcpy(line, text + at, n);
        line[n] = 0;
        at += n + 1;
        if (n && line[n - 1] == '\r') line[n - 1] = 0;
        if (!line[0]) continue;
        if (!parse_line(line, name, ln, t, err)) return false;
    }
    return true;
}

bool st_plot_read_csv(const char *path, st_plot_table *t, st_err *err) {
    size_t len = 0;
    char *text = st_read_input(path, ST_CAP_TEXT, "CSV file", &len, err);
    if (!text) return false;
    bool ok = st_plot_parse_csv(text, len, path, t, err);
    free(text);
    return ok;
}
