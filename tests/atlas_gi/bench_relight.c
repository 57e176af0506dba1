// Benchmark (not a test): time from "a light moved" to the converged image
// with atlas_gi's precomputed transfer, against a frame of the same scene
// with direct light only (shadow_map, no atlas_gi) after the same move, both
// worlds alive in one process and measured interleaved (medians of N moves),
// plus the transfer's precompute statistics. Then a few more moves with
// atlas_gi.profile=true for the relight's steps (the GPU waits between them
// make those moves slower; they are not in the medians above).
//   bench_relight SCENE.json [SIZE] [MOVES] [ATLAS]   (ATLAS 0: the scene's)
#define _POSIX_C_SOURCE 200809L // clock_gettime
#include "st_gl.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

// Process CPU time (ms): llvmpipe's work on all its threads, less inflated
// than the wall time when other jobs share the cores.
static bool open_world(const char *path, int size, int atlas, bool gi, st_scene *sc, st_world **w,
                       st_err *err) {
    if (!st_scene_load(path, sc, err)) return false;
    sc->width = sc->height = size;
    if (!gi) { // direct light only: drop atlas_gi (its settings leak; a benchmark)
        int k = 0;
        for (int i = 0; i < sc->num_modules; i++)
            if (strcmp(sc->modules[i].name, "atlas_gi")) sc->modules[k++] = sc->modules[i];
        sc->num_modules = k;
    }
    st_world_opts o = {.timing = true};
    *w = st_world_create(sc, &o, err);
    if (*w && gi && atlas > 0 && !st_world_set_param(*w, "atlas_gi", "atlas_size", atlas, err))
        return false;
    return *w != NULL;
}

static void light_pos(const float *base, int m, float *p) {
    p[0] = base[0] + 0.3f * (float)cos(m * 2.4);
    p[1] = base[1] - 0.05f * (float)(m % 3);
    p[2] = base[2] + 0.3f * (float)sin(m * 2.4);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: bench_relight SCENE.json [SIZE] [MOVES] [ATLAS]\n");
        return 2;
    }
    int size = argc > 2 ? atoi(argv[2]) : 256, moves = argc > 3 ? atoi(argv[3]) : 9;
    if (moves < 1 || moves > 200) moves = 9;
    int atlas = argc > 4 ? atoi(argv[4]) : 0;
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    st_scene sg = {0}, sd = {0};
    st_world *wg = NULL, *wd = NULL;
    if (!ctx || !open_world(argv[1], size, atlas, true, &sg, &wg, &err) ||
        !open_world(argv[1], size, 0, false, &sd, &wd, &err)) {
        fprintf(stderr, "bench_relight: %s\n", err.msg);
        return 1;
    }
    if (!sg.num_lights) {
        fprintf(stderr, "bench_relight: %s has no light to move\n", argv[1]);
        return 2;
    }
    double t0 = st_now_ms();
    if (!st_world_frame(wg, &err) || !st_world_frame(wd, &err)) {
        fprintf(stderr, "bench_relight: %s\n", err.msg);
        return 1;
    }
    glFinish();
    double first = st_now_ms() - t0;
    st_progress pr = {0};
    st_world_progress(wg, &pr);
    double *tg = calloc((size_t)moves, sizeof *tg), *td = calloc((size_t)moves, sizeof *td);
    double *cg = calloc((size_t)moves, sizeof *cg), *cd = calloc((size_t)moves, sizeof *cd);
    float base[3], inten[3];
    memcpy(base, sg.lights[0].position, sizeof base);
    memcpy(inten, sg.lights[0].intensity, sizeof inten);
    int frames_max = 0;
    for (int m = 0; m < moves; m++) {
        float p[3];
        light_pos(base, m, p);
        for (int k = 0; k < 2; k++) {
            st_world *w = k ? wd : wg;
            if (!st_world_set_light(w, 0, p, inten, &err)) return 1;
            double s = st_now_ms(), sc = st_cpu_ms();
            int f = 0;
            // Frames until converged (one with the transfer).
            do {
                if (!st_world_frame(w, &err)) return 1;
                f++;
            } while (k == 0 && st_world_progress(w, &pr) && !pr.converged && f < 10000);
            glFinish();
            (k ? td : tg)[m] = st_now_ms() - s;
            (k ? cd : cg)[m] = st_cpu_ms() - sc;
            if (!k && f > frames_max) frames_max = f;
        }
    }
    // Per-pass medians over the moves (CPU-side ms; llvmpipe runs on the CPU),
    // before the profiled moves below.
    for (int k = 0; k < 2; k++)
        for (int i = 0; i < st_world_num_pass_stats(k ? wd : wg); i++) {
            const st_pass_stats *ps = st_world_pass_stats(k ? wd : wg, i);
            fprintf(stderr, "  %s %s.%s: %u runs, median cpu %.2f ms, gpu %.2f ms\n",
                    k ? "direct-only" : "relight", ps->module, ps->pass, ps->runs,
                    st_median_f(ps->cpu_ms, ps->num_samples),
                    st_median_f(ps->gpu_ms, ps->num_samples));
        }
    // The relight's steps: a few more moves with the GPU waits of profile=true.
    if (!st_world_set_param(wg, "atlas_gi", "profile", 1, &err)) return 1;
    for (int m = 0; m < 9; m++) {
        float p[3];
        light_pos(base, moves + m, p);
        if (!st_world_set_light(wg, 0, p, inten, &err) || !st_world_frame(wg, &err)) return 1;
    }
    glFinish();
    st_world_progress(wg, &pr);
    double mg = st_median_d(tg, moves), md = st_median_d(td, moves);
    double mcg = st_median_d(cg, moves), mcd = st_median_d(cd, moves);
    printf("{\"scene\": \"%s\", \"size\": %d, \"moves\": %d, \"first_frame_ms\": %.1f, "
           "\"relight_ms_median\": %.2f, "
           "\"direct_only_ms_median\": %.2f, \"ratio\": %.2f, \"relight_cpu_ms_median\": %.2f, "
           "\"direct_only_cpu_ms_median\": %.2f, \"cpu_ratio\": %.2f, \"frames_per_relight\": %d, "
           "\"info\": \"%s\"}\n",
           argv[1], size, moves, first, mg, md, mg / md, mcg, mcd, mcg / mcd, frames_max, pr.info);
    free(tg);
    free(td);
    free(cg);
    free(cd);
    st_world_destroy(wg);
    st_world_destroy(wd);
    st_scene_free(&sg);
    st_scene_free(&sd);
    st_context_destroy(ctx);
    return 0;
}
