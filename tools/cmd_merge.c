// strahl merge: shards of one reference, rendered with different --seed,
// averaged into one image weighted by their spp (read from the EXR headers).
// Each shard's mean m_i of n_i samples has standard error s_i; the merged
// mean sum(n_i m_i) / N (N = sum n_i) has variance sum(n_i^2 s_i^2) / N^2.
#define _POSIX_C_SOURCE 200809L
#include "cmd_common.h"
#include "st_cmd.h"
#include "st_image.h"
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

// Whether the comma-separated seed lists x and y share a seed; names it.
static bool seeds_overlap(const char *x, const char *y, char *which, size_t n) {
    for (const char *p = x; *p;) {
        size_t len = strcspn(p, ",");
        for (const char *q = y; *q;) {
            size_t l2 = strcspn(q, ",");
            if (l2 == len && !strncmp(p, q, len)) {
                snprintf(which, n, "%.*s", (int)len, p);
                return true;
            }
            q += l2 + (q[l2] == ',');
        }
        p += len + (p[len] == ',');
    }
    return false;
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
    const char *dot = strrchr(out, '.');
    if (!dot || strcasecmp(dot, ".exr")) return bad("-o %s: the output is an .exr%s", out, "");

    static const char *const rgb[] = {"R", "G", "B"};
    st_err err = {0};
    st_image sum = {0}, img = {0}, se = {0};
    st_exr_meta *all = calloc(1, sizeof *all), *m = calloc(1, sizeof *m);
    double *acc = NULL; // per value: sum n_i m_i, then sum n_i^2 s_i^2
    long long total = 0;
    int rc = ST_EXIT_OK;
    if (!all || !m) {
        st_fail(&err, ST_ERR_RUNTIME, "out of memory");
        goto fail;
    }
    for (int k = 0; k < n; k++) {
        if (!st_image_read_exr_channels(in[k], rgb, 3, &img, &err) ||
            !st_image_read_exr_stderr(in[k], &se, &err) || !st_image_read_exr_meta(in[k], m, &err))
            goto fail;
        if (!se.data) {
            st_fail(&err, ST_ERR_INPUT,
                    "%s: no stderr.R/G/B channels (not written by strahl reference)", in[k]);
            goto fail;
        }
        if (m->spp <= 0 || !m->seeds[0]) {
            st_fail(&err, ST_ERR_INPUT,
                    "%s: no spp/strahl.seeds header attributes (not written by strahl reference)",
                    in[k]);
            goto fail;
        }
        const size_t count = (size_t)img.width * img.height * 3;
        if (k == 0) {
            *all = *m;
            acc = calloc(2 * count, sizeof *acc);
            if (!acc || !st_image_alloc(&sum, img.width, img.height, 6, &err)) {
                st_fail(&err, ST_ERR_RUNTIME, "out of memory");
                goto fail;
            }
        } else {
            char seed[64];
            if (img.width != sum.width || img.height != sum.height) {
                st_fail(&err, ST_ERR_INPUT, "%s is %dx%d, %s is %dx%d", in[k], img.width,
                        img.height, in[0], sum.width, sum.height);
                goto fail;
            }
            if (strcmp(m->config, all->config)) {
                st_fail(&err, ST_ERR_INPUT,
                        "%s was rendered as '%s', %s as '%s': not shards of one render", in[k],
                        m->config, in[0], all->config);
                goto fail;
            }
            if (seeds_overlap(m->seeds, all->seeds, seed, sizeof seed)) {
                st_fail(&err, ST_ERR_INPUT,
                        "%s: seed %s is in an earlier shard too; shards need different --seed "
                        "(else they are the "
                        "same samples)",
                        in[k], seed);
                goto fail;
            }
            size_t l = strlen(all->seeds);
            if (l + strlen(m->seeds) + 2 > sizeof all->seeds) {
                st_fail(&err, ST_ERR_INPUT, "%s: too many seeds to record in the header", in[k]);
                goto fail;
            }
            all->seeds[l] = ',';
            memcpy(all->seeds + l + 1, m->seeds, strlen(m->seeds) + 1); // fits: checked above
        }
        total += m->spp;
        if (total > 2147483647LL) {
            st_fail(&err, ST_ERR_INPUT, "%s: more than 2^31 - 1 spp in total", in[k]);
            goto fail;
        }
        const double w = m->spp;
        for (size_t i = 0; i < count; i++) {
            acc[i] += w * img.data[i];
            acc[count + i] += w * w * (double)se.data[i] * se.data[i];
        }
        st_image_free(&img);
        st_image_free(&se);
    }
    const size_t px = (size_t)sum.width * sum.height;
    for (size_t i = 0; i < px; i++)
        for (int c = 0; c < 3; c++) {
            sum.data[6 * i + c] = (float)(acc[3 * i + c] / total);
            sum.data[6 * i + 3 + c] = (float)(sqrt(acc[3 * px + 3 * i + c]) / total);
        }
    all->spp = (int)total;
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    if (!st_image_write_exr_meta(out, &sum, names, all, &err)) goto fail;
    printf("strahl merge: %s (%dx%d, %lld spp from %d shard(s))\n", out, sum.width, sum.height,
           total, n);
    goto done;
fail:
    rc = st_report("merge", &err);
done:
    st_image_free(&img);
    st_image_free(&se);
    st_image_free(&sum);
    free(acc);
    free(all);
    free(m);
    return rc;
}
