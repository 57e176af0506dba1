// Benchmark (not a test): the thesis' Table 1 on this machine, beside the
// precomputed transfer. Prints markdown tables.
//   bench_table1 [--frames F] [--sizes 512,1024] [--samples 10,50,...]
//                [--transfer-sizes 512] [--size PX] SCENE.json
// Per-frame gather (mode=gather with the thesis' options: estimator=thesis,
// visibility off, uniform sampling, one bounce; accumulation on with
// tolerance 0, so the gather runs every frame): per atlas size and N the
// median over F frames (after one warm-up frame) of the whole frame, wall
// and process CPU time.
// Transfer (mode=transfer, the defaults): per atlas size the first frame
// (atlas, G-buffer, precompute, first relight), the precompute as the plugin
// reports it, and the median relight (light moved, converged image) over F
// moves, wall and CPU. llvmpipe runs on the CPU: the CPU time is the work,
// the wall time depends on what else runs on the machine.
#define _POSIX_C_SOURCE 200809L // clock_gettime
#include "st_gl.h"
#include "st_world.h"
#include "gi_bench.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

// One frame, finished; wall and CPU ms.
static bool frame(st_world *w, double *wall, double *cpu) {
    st_err err = {0};
    double t0 = st_now_ms(), c0 = st_cpu_ms();
    if (!st_world_frame(w, &err)) {
        fprintf(stderr, "frame: %s\n", err.msg);
        return false;
    }
    glFinish();
    if (wall) *wall = st_now_ms() - t0;
    if (cpu) *cpu = st_cpu_ms() - c0;
    return true;
}

static st_world *open_world(const char *path, int px, st_scene *sc, st_err *err) {
    memset(sc, 0, sizeof *sc);
    if (!st_scene_load(path, sc, err)) return NULL;
    sc->width = sc->height = px;
    st_world_opts o = {.timing = true};
    return st_world_create(sc, &o, err);
}

static bool gather_cell(const char *path, int px, int atlas, int n, int frames, double out[2]) {
    st_err err = {0};
    st_scene sc;
    st_world *w = open_world(path, px, &sc, &err);
    // mode=gather (1), estimator=thesis (1), sampling=uniform (0).
    const char *keys[] = {"mode",        "estimator", "sampling",   "visibility", "bounces",
                          "progressive", "tolerance", "max_frames", "atlas_size", "samples"};
    const double vals[] = {1, 1, 0, 0, 1, 1, 0, 65536, atlas, n};
    for (int k = 0; w && k < 10; k++)
        if (!st_world_set_param(w, "atlas_gi", keys[k], vals[k], &err)) {
            st_world_destroy(w);
            w = NULL;
        }
    if (!w) {
        fprintf(stderr, "%s: %s\n", path, err.msg);
        st_scene_free(&sc);
        return false;
    }
    double *tw = malloc((size_t)frames * sizeof *tw), *tc = malloc((size_t)frames * sizeof *tc);
    bool ok = tw && tc && frame(w, NULL, NULL); // atlas, G-buffer, shaders; first gather
    for (int f = 0; ok && f < frames; f++)
        ok = frame(w, &tw[f], &tc[f]);
    if (ok) {
        out[0] = st_median_d(tw, frames);
        out[1] = st_median_d(tc, frames);
    }
    free(tw);
    free(tc);
    st_world_destroy(w);
    st_scene_free(&sc);
    return ok;
}

// out: first frame wall ms, precompute s (reported), relight wall, relight CPU.
static bool transfer_row(const char *path, int px, int atlas, int moves, double out[4], char *info,
                         size_t ninfo) {
    st_err err = {0};
    st_scene sc;
    st_world *w = open_world(path, px, &sc, &err);
    if (w && !st_world_set_param(w, "atlas_gi", "atlas_size", atlas, &err)) {
        st_world_destroy(w);
        w = NULL;
    }
    if (!w || !sc.num_lights) {
        fprintf(stderr, "%s: %s\n", path, w ? "no light to move" : err.msg);
        st_world_destroy(w);
        st_scene_free(&sc);
        return false;
    }
    bool ok = frame(w, &out[0], NULL);
    st_progress pr = {0};
    st_world_progress(w, &pr);
    snprintf(info, ninfo, "%s", pr.info);
    const char *p = strstr(pr.info, "transfer precompute ");
    out[1] = p ? atof(p + strlen("transfer precompute ")) : NAN;
    double *tw = malloc((size_t)moves * sizeof *tw), *tc = malloc((size_t)moves * sizeof *tc);
    float base[3], inten[3];
    memcpy(base, sc.lights[0].position, sizeof base);
    memcpy(inten, sc.lights[0].intensity, sizeof inten);
    for (int m = 0; ok && tw && tc && m < moves; m++) {
        float q[3] = {base[0] + 0.3f * (float)cos(m * 2.4), base[1] - 0.05f * (float)(m % 3),
                      base[2] + 0.3f * (float)sin(m * 2.4)};
        ok = st_world_set_light(w, 0, q, inten, &err) && frame(w, &tw[m], &tc[m]);
    }
    if (ok && tw && tc) {
        out[2] = st_median_d(tw, moves);
        out[3] = st_median_d(tc, moves);
    }
    free(tw);
    free(tc);
    st_world_destroy(w);
    st_scene_free(&sc);
    return ok;
}

int main(int argc, char **argv) {
    int frames = 3, px = 256, sizes[8] = {512, 1024}, nsizes = 2,
        samples[16] = {10, 50, 100, 200, 400}, nsamples = 5, tsizes[8] = {512}, ntsizes = 1;
    const char *scene = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc)
            px = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sizes") && i + 1 < argc)
            nsizes = gi_parse_list(argv[++i], sizes, 8);
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc)
            nsamples = gi_parse_list(argv[++i], samples, 16);
        else if (!strcmp(argv[i], "--transfer-sizes") && i + 1 < argc)
            ntsizes = gi_parse_list(argv[++i], tsizes, 8);
        else
            scene = argv[i];
    }
    if (!scene || frames < 1 || px < 16) {
        fprintf(stderr, "usage: bench_table1 [--frames F] [--sizes 512,1024] [--samples "
                        "10,50,...] [--transfer-sizes 512] [--size PX] SCENE.json\n");
        return 2;
    }
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    printf("renderer: %s; scene %s at %dx%d; medians over %d frames / moves\n\n",
           st_context_renderer(), scene, px, px, frames);
    printf("Per-frame gather (mode=gather, estimator=thesis, visibility=false, "
           "sampling=uniform): frame ms wall / process CPU\n\n| atlas |");
    for (int k = 0; k < nsamples; k++)
        printf(" N=%d |", samples[k]);
    printf("\n|---|");
    for (int k = 0; k < nsamples; k++)
        printf("---:|");
    printf("\n");
    for (int a = 0; a < nsizes; a++) {
        printf("| %d |", sizes[a]);
        for (int k = 0; k < nsamples; k++) {
            double r[2];
            if (!gather_cell(scene, px, sizes[a], samples[k], frames, r)) return 1;
            printf(" %.0f / %.0f |", r[0], r[1]);
            fflush(stdout);
        }
        printf("\n");
    }
    printf("\nTransfer (mode=transfer, defaults): one frame is the converged image\n\n"
           "| atlas | first frame ms (wall) | precompute s | relight ms wall / CPU |\n"
           "|---|---:|---:|---:|\n");
    char info[512];
    for (int a = 0; a < ntsizes; a++) {
        double r[4] = {0};
        if (!transfer_row(scene, px, tsizes[a], frames, r, info, sizeof info)) return 1;
        printf("| %d | %.0f | %.2f | %.0f / %.0f |\n", tsizes[a], r[0], r[1], r[2], r[3]);
        fprintf(stderr, "  atlas %d: %s\n", tsizes[a], info);
        fflush(stdout);
    }
    st_context_destroy(ctx);
    return 0;
}
