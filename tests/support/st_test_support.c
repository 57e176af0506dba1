// See st_test_support.h.
#include "st_test_support.h"
#include "st_test_render.h"

st_context *st_test_context(void) {
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        fprintf(stderr, "FAIL: headless GL context: %s\n", err.msg);
        exit(1);
    }
    return ctx;
}

cJSON *st_test_stats_json(const char *scene, const char *out, const char *extra, int *rc) {
    static char buf[1 << 16];
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s render %s -o %s --stats=json %s 2>/dev/null", ST_TEST_STRAHL,
             scene, out, extra ? extra : "");
    *rc = st_test_capture(buf, sizeof buf, cmd);
    return cJSON_Parse(buf);
}

int st_test_shadow_state(const double p[3], double jitter, const double lp[3], const double bmin[3],
                         const double bmax[3]) {
    int in = 0;
    const double off[5][2] = {{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int k = 0; k < 5; k++) {
        double q[3] = {p[0] + off[k][0] * jitter, 0, p[2] + off[k][1] * jitter};
        double d[3] = {lp[0] - q[0], lp[1] - q[1], lp[2] - q[2]};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int c = 0; c < 3; c++)
            d[c] /= len;
        double t = st_test_ray_box(q, d, bmin, bmax);
        in += t >= 0 && t < len;
    }
    return in == 5 ? 1 : in == 0 ? 0 : -1;
}
