// strahl merge: shards of one reference, rendered with different --seed,
// averaged into one image weighted by their spp (read from the EXR headers).
// Each shard's mean m_i of n_i samples has standard error s_i; the merged
// mean sum(n_i m_i) / N (N = sum n_i) has variance sum(n_i^2 s_i^2) / N^2.
#define _POSIX_C_SOURCE 200809L
#include "cmd_common.h"
#include "st_cmd.h"
#include "st_file.h"
#include "st_image.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define MAX_SHARDS 256

static const char help_text[] =
    "usage: strahl merge SHARD.exr SHARD.exr... -o OUT.exr\n"
    "Averages shards of one `strahl reference` render (same scene, size and options,\n"
    "different --seed) weighted by their spp; the standard-error channels combine as\n"
    "s = sqrt(sum n_i^2 s_i^2) / sum n_i. The output records the summed spp and all\n"
    "seeds, so it can be merged again with further shards.\n"
    "  -o OUT.exr   output (required; written atomically; may be one of the inputs)\n"
    "  -h, --help   this text\n"
    "Shards must come from strahl reference (the spp, seed and config header\n"
    "attributes); a seed used twice or another config is an error (default: none).\n"
    "example:\n"
    "  for k in 1 2 3 4; do strahl reference scene.json -o s$k.exr --spp 64 --seed $k; done\n"
    "  strahl merge s1.exr s2.exr s3.exr s4.exr -o ref.exr   # 256 spp\n";

static int bad(const char *fmt, const char *a, const char *b) {
    st_err err = {0};
    st_fail(&err, ST_ERR_INPUT, fmt, a, b);
    return st_report("merge", &err);
}

#define MAX_SEEDS 2048

// The strahl.seeds attribute of a shard: comma-separated decimal integers
// (digits only: no sign, space or 0x; "01" is 1), each at most 2^64 - 1.
// Seeds are compared as numbers, so one seed written two ways still counts
// twice. Appends to seeds[*n]; a seed already there (this shard or an
// earlier one) is an error naming it.
static bool parse_seeds(const char *shard, const char *text, unsigned long long *seeds, int *n,
                        int first_of_shard, st_err *err) {
    for (const char *p = text;;) {
        size_t len = strcspn(p, ",");
        char tok[32];
        bool digits = len > 0 && len < sizeof tok;
        for (size_t i = 0; digits && i < len; i++)
            digits = p[i] >= '0' && p[i] <= '9';
        if (!digits) {
            char all[1024], one[256], cut[48];
            snprintf(cut, sizeof cut, "%.*s", (int)(len < 40 ? len : 40), p);
            snprintf(all, sizeof all, "%.200s", text);
            return st_fail(err, ST_ERR_INPUT, "%s: strahl.seeds '%s': '%s' is not a decimal seed",
                           shard, st_printable(all, one, sizeof one),
                           st_printable(cut, all, sizeof all));
        }
        memcpy(tok, p, len);
        tok[len] = 0;
        errno = 0;
        unsigned long long v = strtoull(tok, NULL, 10);
        if (errno)
            return st_fail(err, ST_ERR_INPUT, "%s: strahl.seeds: seed %s is larger than 2^64 - 1",
                           shard, tok);
        for (int i = 0; i < *n; i++)
            if (seeds[i] == v)
                return st_fail(err, ST_ERR_INPUT,
                               "%s: seed %llu is %s; shards need different --seed (else they "
                               "are the same samples)",
                               shard, v,
                               i >= first_of_shard ? "in the shard twice"
                                                   : "in an earlier shard too");
        if (*n == MAX_SEEDS)
            return st_fail(err, ST_ERR_INPUT, "%s: more than %d seeds in all", shard, MAX_SEEDS);
        seeds[(*n)++] = v;
        if (!p[len]) return true;
        p += len + 1;
    }
}

// Radiance and its standard error are finite and non-negative in a shard of
// strahl reference; anything else would poison the mean. Names the shard.
static bool check_shard(const char *shard, const st_image *img, const st_image *se, st_err *err) {
    static const char *const ch[] = {"R", "G", "B"};
    for (int pass = 0; pass < 2; pass++) {
        const st_image *m = pass ? se : img;
        const char *what = pass ? "standard error stderr." : "radiance ";
        size_t n = (size_t)m->width * m->height * 3;
        for (size_t i = 0; i < n; i++) {
            float v = m->data[i];
            if (isfinite(v) && v >= 0) continue;
            size_t px = i / 3;
            return st_fail(err, ST_ERR_INPUT,
                           "%s: %s%s is %.9g at pixel (%zu, %zu); not a shard "
                           "of strahl reference",
                           shard, what, ch[i % 3], v, px % (size_t)m->width, px / (size_t)m->width);
        }
    }
    return true;
}

// The running merge: sums over the shards read so far.
typedef struct merge {
    st_image sum;     // the output: R, G, B, stderr.R/G/B
    double *acc;      // per value: sum n_i m_i, then sum n_i^2 s_i^2
    st_exr_meta *all; // the first shard's header, spp and seeds made the merged ones
    unsigned long long *seeds;
    int nseeds;
    long long total; // spp
} merge;

// Checks shard k (its channels, header, seeds, size and config against the
// first) and adds it to the sums.
static bool add_shard(merge *g, int k, const char *path, const char *first, st_err *err) {
    static const char *const rgb[] = {"R", "G", "B"};
    st_image img = {0}, se = {0};
    st_exr_meta *m = calloc(1, sizeof *m);
    bool ok = m && st_image_read_exr_channels(path, rgb, 3, &img, err) &&
              st_image_read_exr_stderr(path, &se, err) && st_image_read_exr_meta(path, m, err);
    if (!m) st_fail(err, ST_ERR_RUNTIME, "out of memory");
    if (ok && !se.data)
        ok = st_fail(err, ST_ERR_INPUT,
                     "%s: no stderr.R/G/B channels (not written by strahl reference)", path);
    if (ok && (!m->has_spp || !m->seeds[0]))
        ok = st_fail(err, ST_ERR_INPUT,
                     "%s: no spp/strahl.seeds header attributes (not written by strahl reference)",
                     path);
    if (ok && m->spp <= 0)
        ok = st_fail(err, ST_ERR_INPUT, "%s: spp is %d, expected at least 1", path, m->spp);
    ok = ok && check_shard(path, &img, &se, err) &&
         parse_seeds(path, m->seeds, g->seeds, &g->nseeds, g->nseeds, err);
    const size_t count = (size_t)img.width * img.height * 3;
    if (ok && k == 0) {
        *g->all = *m;
        g->acc = calloc(2 * count, sizeof *g->acc);
        if (!g->acc || !st_image_alloc(&g->sum, img.width, img.height, 6, err))
            ok = st_fail(err, ST_ERR_RUNTIME, "out of memory");
    } else if (ok && (img.width != g->sum.width || img.height != g->sum.height)) {
        ok = st_fail(err, ST_ERR_INPUT, "%s is %dx%d, %s is %dx%d", path, img.width, img.height,
                     first, g->sum.width, g->sum.height);
    } else if (ok && strcmp(m->config, g->all->config)) {
        char a[1100], b[1100]; // the attributes are file content: escaped
        ok = st_fail(err, ST_ERR_INPUT,
                     "%s was rendered as '%s', %s as '%s': not shards of one render", path,
                     st_printable(m->config, a, sizeof a), first,
                     st_printable(g->all->config, b, sizeof b));
    } else if (ok && strcmp(st_exr_filter(m), st_exr_filter(g->all))) {
        char a[64], b[64];
        ok = st_fail(err, ST_ERR_INPUT,
                     "%s was rendered with the %s pixel filter, %s with %s: not shards of one "
                     "render",
                     path, st_printable(st_exr_filter(m), a, sizeof a), first,
                     st_printable(st_exr_filter(g->all), b, sizeof b));
    }
    if (ok) g->total += m->spp;
    if (ok && g->total > 2147483647LL)
        ok = st_fail(err, ST_ERR_INPUT, "%s: more than 2^31 - 1 spp in total", path);
    const double w = ok ? m->spp : 0;
    for (size_t i = 0; ok && i < count; i++) {
        g->acc[i] += w * img.data[i];
        g->acc[count + i] += w * w * (double)se.data[i] * se.data[i];
    }
    st_image_free(&img);
    st_image_free(&se);
    free(m);
    return ok;
}

// The merged mean and standard error, spp and seeds (canonical: "01" ->
// "1"), written to out.
static bool write_merged(merge *g, const char *out, st_err *err) {
    const size_t px = (size_t)g->sum.width * g->sum.height;
    for (size_t i = 0; i < px; i++)
        for (int c = 0; c < 3; c++) {
            g->sum.data[6 * i + c] = (float)(g->acc[3 * i + c] / g->total);
            g->sum.data[6 * i + 3 + c] = (float)(sqrt(g->acc[3 * px + 3 * i + c]) / g->total);
        }
    g->all->spp = (int)g->total;
    size_t l = 0;
    char *seeds = g->all->seeds;
    seeds[0] = 0;
    for (int i = 0; i < g->nseeds; i++) {
        int w = snprintf(seeds + l, sizeof g->all->seeds - l, "%s%llu", i ? "," : "", g->seeds[i]);
        if (w < 0 || (size_t)w >= sizeof g->all->seeds - l)
            return st_fail(err, ST_ERR_INPUT, "too many seeds to record in the header of %s", out);
        l += (size_t)w;
    }
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    return st_image_write_exr_meta(out, &g->sum, names, g->all, err);
}

int st_cmd_merge(int argc, char **argv) {
    const char *in[MAX_SHARDS], *out = NULL;
    int n = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(help_text, stdout);
            return ST_EXIT_OK;
        } else if (!strcmp(a, "-o") && i + 1 < argc) {
            out = argv[++i];
        } else if (a[0] == '-') {
            return bad("unexpected argument '%s'%s (see strahl merge --help)", a, "");
        } else if (n == MAX_SHARDS) {
            return bad("%s: more than 256 shards%s", a, "");
        } else {
            in[n++] = a;
        }
    }
    if (!out) return bad("missing -o OUT.exr%s%s", "", "");
    if (n < 1) return bad("no shards to merge%s%s", "", "");
    static const char *const exts[] = {"exr", NULL};
    st_err err = {0};
    // The output may be one of the shards (merging into a reference): it is
    // written, atomically, only after every shard has been read.
    if (!st_check_output("-o", out, exts, NULL, &err)) return st_report("merge", &err);
    merge g = {.all = calloc(1, sizeof *g.all), .seeds = calloc(MAX_SEEDS, sizeof *g.seeds)};
    bool ok = g.all && g.seeds;
    if (!ok) st_fail(&err, ST_ERR_RUNTIME, "out of memory");
    for (int k = 0; ok && k < n; k++)
        ok = add_shard(&g, k, in[k], in[0], &err);
    ok = ok && write_merged(&g, out, &err);
    if (ok)
        printf("strahl merge: %s (%dx%d, %lld spp from %d shard(s))\n", out, g.sum.width,
               g.sum.height, g.total, n);
    st_image_free(&g.sum);
    free(g.acc);
    free(g.all);
    free(g.seeds);
    return ok ? ST_EXIT_OK : st_report("merge", &err);
}
