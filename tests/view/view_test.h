// Helpers for the strahl view tests: every test program re-runs itself under
// xvfb-run (a virtual X server, Mesa llvmpipe through GLX), runs scripted
// viewer sessions, and reads back their screenshots and stats JSON.
#ifndef ST_VIEW_TEST_H
#define ST_VIEW_TEST_H
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "st_test_render.h"
#include "st_list.h"
#include "st_module.h"
#include <cjson/cJSON.h>
#include <errno.h>

// Re-executes the test under `xvfb-run -a -s "-screen 0 1024x768x24"` unless
// it already runs there. A missing xvfb-run is a failure, never a skip.
static inline void st_view_under_xvfb(char **argv) {
    if (getenv("ST_VIEW_UNDER_XVFB")) return;
    if (system("command -v xvfb-run >/dev/null 2>&1") != 0) {
        fprintf(stderr,
                "FAIL: xvfb-run not found. The viewer tests need a virtual X server: install the "
                "Debian package 'xvfb' (tools/setup.sh does). They are not skipped.\n");
        exit(1);
    }
    setenv("ST_VIEW_UNDER_XVFB", "1", 1);
    // -a starts its search for a free display at -n; spread by pid so tests
    // started together by ctest -j do not race for the same number.
    char num[16];
    snprintf(num, sizeof num, "%d", 100 + (int)(getpid() % 2000));
    execlp("xvfb-run", "xvfb-run", "-a", "-n", num, "-s", "-screen 0 1024x768x24", argv[0],
           (char *)NULL);
    fprintf(stderr, "FAIL: cannot run xvfb-run: %s\n", strerror(errno));
    exit(1);
}

// Runs `strahl view SCENE --script SCRIPT --filter point EXTRA`, output
// captured in log (point: screenshots equal the st_test_render images; a
// `--filter box` in EXTRA overrides it).
static inline int st_view_run(const char *scene, const char *script, const char *extra, char *log,
                              size_t n) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s view %s --script %s --filter point %s", ST_TEST_STRAHL, scene,
             script, extra ? extra : "");
    return st_test_capture(log, n, cmd);
}

// The digit key that switches `module` in the viewer (its position in the
// sorted list of installed modules, 1..9 then 0), or 0 if it has none.
static inline char st_view_module_key(const char *module) {
    char names[64][ST_NAME_MAX];
    int n = st_plugin_list(names, 64);
    for (int i = 0; i < n && i < 10; i++)
        if (!strcmp(names[i], module)) return (char)('0' + (i + 1) % 10);
    return 0;
}

// The god-ray techniques the G key cycles, by name, before `before` (NULL:
// all): installed plugins that only add light to the image, by the rule of
// tools/view/view_kinds.c written out again (no regular_include, provide
// nothing, no enum parameter with an "indirect" choice).
static inline int st_view_godray_modules(char out[][ST_NAME_MAX], int max, const char *before) {
    char names[64][ST_NAME_MAX];
    int n = st_plugin_list(names, 64), k = 0;
    for (int i = 0; i < n && k < max; i++) {
        if (before && strcmp(names[i], before) >= 0) continue;
        st_plugin_lib *lib = st_plugin_open(names[i], &(st_err){0});
        if (!lib) continue;
        const st_plugin *p = st_plugin_desc(lib);
        bool display = false;
        for (int q = 0; q < p->num_params && !display; q++)
            for (int c = 0; p->params[q].type == ST_PARAM_ENUM &&
                            c < st_param_num_choices(&p->params[q]) && !display;
                 c++) {
                char ch[ST_NAME_MAX];
                st_param_choice(&p->params[q], c, ch, sizeof ch);
                display = !strcmp(ch, "indirect");
            }
        // A capability others may require makes a provider; ST_CAP_INSCATTER
        // (toth, froxel) only says what the technique adds.
        bool provider = false;
        char cap[ST_NAME_MAX];
        for (const char *r = p->provides; (r = st_list_next(r, cap, NULL));)
            provider |= cap[0] && strcmp(cap, ST_CAP_INSCATTER);
        bool godray = !(p->regular_include && p->regular_include[0]) && !provider && !display;
        st_plugin_close(lib);
        if (godray) snprintf(out[k++], ST_NAME_MAX, "%.*s", ST_NAME_MAX - 1, names[i]);
    }
    return k;
}

static inline int st_view_installed(const char *module) {
    char names[64][ST_NAME_MAX];
    int n = st_plugin_list(names, 64);
    for (int i = 0; i < n; i++)
        if (!strcmp(names[i], module)) return 1;
    return 0;
}

static inline cJSON *st_view_json(const char *path) {
    char *text = NULL;
    st_err err = {0};
    text = st_read_file(path, NULL, &err);
    if (!text) {
        fprintf(stderr, "%s\n", err.msg);
        return NULL;
    }
    cJSON *j = cJSON_Parse(text);
    free(text);
    if (!j) fprintf(stderr, "%s: not JSON\n", path);
    return j;
}

// State of a pass in a stats file ("ran", "skipped", "culled"), "absent" if
// the pass was not in the frame, "?" if the file is unreadable. `pass` may
// be a prefix ("cube" matches "cube[0]").
static inline const char *st_view_pass_state(cJSON *stats, const char *module, const char *pass) {
    static char state[32];
    if (!stats) return "?";
    cJSON *passes = cJSON_GetObjectItem(stats, "passes"), *p;
    cJSON_ArrayForEach(p, passes) {
        const char *m = cJSON_GetStringValue(cJSON_GetObjectItem(p, "module"));
        const char *ps = cJSON_GetStringValue(cJSON_GetObjectItem(p, "pass"));
        if (m && ps && !strcmp(m, module) && !strncmp(ps, pass, strlen(pass))) {
            snprintf(state, sizeof state, "%s",
                     cJSON_GetStringValue(cJSON_GetObjectItem(p, "state")));
            return state;
        }
    }
    return "absent";
}

// Counts the passes of `module` in a given state.
static inline int st_view_count(cJSON *stats, const char *module, const char *state) {
    int n = 0;
    cJSON *p;
    if (!stats) return -1;
    cJSON_ArrayForEach(p, cJSON_GetObjectItem(stats, "passes")) {
        const char *m = cJSON_GetStringValue(cJSON_GetObjectItem(p, "module"));
        const char *s = cJSON_GetStringValue(cJSON_GetObjectItem(p, "state"));
        n += m && s && !strcmp(m, module) && !strcmp(s, state);
    }
    return n;
}

static inline double st_view_pass_num(cJSON *stats, const char *module, const char *pass,
                                      const char *key) {
    cJSON *p;
    if (!stats) return NAN;
    cJSON_ArrayForEach(p, cJSON_GetObjectItem(stats, "passes")) {
        const char *m = cJSON_GetStringValue(cJSON_GetObjectItem(p, "module"));
        const char *ps = cJSON_GetStringValue(cJSON_GetObjectItem(p, "pass"));
        if (m && ps && !strcmp(m, module) && !strncmp(ps, pass, strlen(pass)))
            return cJSON_GetNumberValue(cJSON_GetObjectItem(p, key));
    }
    return NAN;
}

static inline const char *st_view_str(cJSON *stats, const char *key) {
    const char *s = stats ? cJSON_GetStringValue(cJSON_GetObjectItem(stats, key)) : NULL;
    return s ? s : "?";
}

// Largest |a - b| over all channels; +inf if the sizes differ.
static inline double st_view_max_diff(const st_image *a, const st_image *b) {
    if (!a->data || !b->data || a->width != b->width || a->height != b->height ||
        a->channels != b->channels)
        return INFINITY;
    double m = 0;
    for (size_t k = 0; k < (size_t)a->width * a->height * a->channels; k++) {
        double d = fabs((double)a->data[k] - b->data[k]);
        if (!(d <= m)) m = d; // NaN counts as the largest
    }
    return m;
}

// Pixels whose mean over RGB differs by more than tol.
static inline int st_view_count_diff(const st_image *a, const st_image *b, double tol) {
    if (!a->data || !b->data || a->width != b->width || a->height != b->height) return -1;
    int n = 0;
    for (int j = 0; j < a->height; j++)
        for (int i = 0; i < a->width; i++) {
            const float *p = st_image_px(a, i, j), *q = st_image_px(b, i, j);
            n += fabs((p[0] + p[1] + p[2]) - (q[0] + q[1] + q[2])) / 3 > tol;
        }
    return n;
}

// Mean over RGB and the pixels of a rectangle [i0, i1) x [j0, j1).
static inline double st_view_mean(const st_image *img, int i0, int j0, int i1, int j1) {
    double s = 0;
    int n = 0;
    if (!img->data) return NAN;
    for (int j = j0; j < j1; j++)
        for (int i = i0; i < i1; i++, n++) {
            const float *p = st_image_px(img, i, j);
            s += (p[0] + p[1] + p[2]) / 3;
        }
    return n ? s / n : NAN;
}

static inline int st_view_read(const char *dir, const char *name, st_image *img) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.exr", dir, name);
    memset(img, 0, sizeof *img);
    return st_test_read(path, img);
}

// Width and height from a PNG header (0 if it is not a PNG).
static inline void st_view_png_size(const char *path, int *w, int *h) {
    unsigned char b[24] = {0};
    FILE *f = fopen(path, "rb");
    *w = *h = 0;
    if (!f) return;
    size_t got = fread(b, 1, sizeof b, f);
    fclose(f);
    if (got < 24 || memcmp(b, "\x89PNG", 4)) return;
    *w = b[16] << 24 | b[17] << 16 | b[18] << 8 | b[19];
    *h = b[20] << 24 | b[21] << 16 | b[22] << 8 | b[23];
}

#endif
