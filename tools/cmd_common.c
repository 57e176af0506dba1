#include "cmd_common.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

bool st_load_scene_with(const char *path, char **sets, int num_sets, int width, int height,
                        st_scene *scene, st_err *err) {
    if (!st_scene_load(path, scene, err)) return false;
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

int st_report(const char *cmd, const st_err *err) {
    fprintf(stderr, "strahl %s: %s\n", cmd, err->msg);
    return st_err_exit_code(err);
}
