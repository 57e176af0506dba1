// atlas_gi, profile=true: the G-buffer's and the relight's steps timed (wall
// and process CPU time, after waiting for the GPU) and their medians over the
// last AG_PROF_MAX relights, for --stats.
#include "agi.h"
#include <stdio.h>

static const char *const prof_names[AG_PROF_STEPS] = {"G-buffer", "reduce", "links", "push",
                                                      "resolve"};

void agi_prof_mark(agi *g, double (*acc)[AG_PROF_STEPS], int step) {
    if (!ip(g, P_PROFILE)) return;
    glFinish();
    double t[2] = {st_now_ms(), st_cpu_ms()};
    for (int i = 0; i < 2; i++) {
        if (acc) acc[i][step] += t[i] - g->prof_t[i];
        g->prof_t[i] = t[i];
    }
}

void agi_prof_keep(agi *g, double (*ms)[AG_PROF_STEPS]) {
    if (!ip(g, P_PROFILE)) return;
    int k = g->prof_n % AG_PROF_MAX;
    for (int c = 0; c < 2; c++)
        for (int i = 0; i < AG_PROF_STEPS; i++)
            g->prof[c][i][k] = (float)ms[c][i];
    g->prof_n++;
}

void agi_prof_info(const agi *g, char *out, int n, size_t size) {
    int np = g->prof_n < AG_PROF_MAX ? g->prof_n : AG_PROF_MAX;
    for (int i = 0; i < AG_PROF_STEPS && np && n > 0 && (size_t)n < size; i++)
        n += snprintf(
            out + n, size - (size_t)n, "%s%s %.2f / %.2f",
            i ? ", " : "; relight steps (median ms wall / process CPU, profile): ", prof_names[i],
            st_median_f(g->prof[0][i], np), st_median_f(g->prof[1][i], np));
}
