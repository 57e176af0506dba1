// Helpers shared by the atlas_gi benchmark programs (not tests).
#ifndef GI_BENCH_H
#define GI_BENCH_H
#include <stdlib.h>
#include <string.h>

// "10,50,100" -> out[] = {10, 50, 100}; returns the count (at most max).
static inline int gi_parse_list(const char *s, int *out, int max) {
    int n = 0;
    for (const char *p = s; *p && n < max;) {
        out[n++] = atoi(p);
        const char *c = strchr(p, ',');
        if (!c) break;
        p = c + 1;
    }
    return n;
}
#endif
