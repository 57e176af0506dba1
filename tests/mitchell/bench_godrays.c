// bench_godrays: run time against error for the image-space god-ray modules
// (not a test; built beside them). For each value of one parameter: median
// frame time over F frames with every cached pass recomputed (as `strahl
// bench --mode recompute`), the module's median GPU time, and the error of
// the shafts alone -- the image minus the same scene without medium --
// against a reference in-scatter image (`strahl reference --aov inscatter`),
// as scale-fitted RMSE because these methods are not physically scaled.
// With --converged V also the scale-fitted RMSE against the same module at
// PARAM = V (its own converged image, e.g. n = 512), relative to that
// image's RMS: what the sampling parameter buys, apart from the model's error.
//
//   bench_godrays SCENE.json INSCATTER.exr MODULE.PARAM=v1,v2,... [--frames F] [--size WxH]
//   [--converged V]
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(const char *what, const st_err *err) {
    fprintf(stderr, "bench_godrays: %s: %s\n", what, err->msg);
    return 1;
}

static double module_gpu_ms(const st_world *w, const char *module) {
    double sum = 0;
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *s = st_world_pass_stats(w, i);
        if (!strcmp(s->module, module) && s->num_samples)
            sum += st_median_f(s->gpu_ms, s->num_samples);
    }
    return sum;
}

// Warm-up, then the median of `frames` frames with every cached pass
// invalidated (shadow maps, occlusion image, mask, ... are recomputed).
static bool time_frames(st_world *w, int frames, float *ms, double *median, st_err *err) {
    for (int f = 0; f < 2; f++) // shader JIT, allocations
        if (!st_world_frame(w, err)) return false;
    glFinish();
    st_world_reset_samples(w);
    for (int f = 0; f < frames; f++) {
        st_world_invalidate(w, ST_CHANGE_ALL & ~ST_CHANGE_FIRST);
        double t0 = st_now_ms();
        if (!st_world_frame(w, err)) return false;
        glFinish();
        ms[f] = (float)(st_now_ms() - t0);
    }
    *median = st_median_f(ms, frames);
    return true;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr,
                "usage: bench_godrays SCENE.json INSCATTER.exr MODULE.PARAM=v1,v2,... [--frames F] "
                "[--size WxH] "
                "[--converged V]\n");
        return 2;
    }
    int frames = 9, width = 0, height = 0;
    const char *converged = NULL;
    for (int i = 4; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--frames")) frames = atoi(argv[i + 1]);
        if (!strcmp(argv[i], "--size")) sscanf(argv[i + 1], "%dx%d", &width, &height);
        if (!strcmp(argv[i], "--converged")) converged = argv[i + 1];
    }
    char module[64], param[64], values[512];
    if (sscanf(argv[3], "%63[^.].%63[^=]=%511s", module, param, values) != 3 || frames < 1) {
        fprintf(stderr, "bench_godrays: bad sweep '%s'\n", argv[3]);
        return 2;
    }
    st_err err = {0};
    st_scene with = {0}, without = {0};
    st_image ref = {0}, img = {0}, base = {0}, effect = {0}, conv = {0};
    if (!st_scene_load(argv[1], &with, &err) || !st_scene_load(argv[1], &without, &err))
        return fail(argv[1], &err);
    without.medium.present = false; // the surfaces alone: the modules skip their passes
    if (!st_image_read_exr(argv[2], &ref, &err)) return fail(argv[2], &err);
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) return fail("context", &err);
    st_world_opts opts = {width, height, true};
    st_world *wb = st_world_create(&without, &opts, &err);
    if (!wb || !st_world_frame(wb, &err) || !st_world_read(wb, &base, &err))
        return fail("base render", &err);
    if (base.width != ref.width || base.height != ref.height) {
        fprintf(stderr, "bench_godrays: reference is %dx%d, render %dx%d\n", ref.width, ref.height,
                base.width, base.height);
        return 2;
    }
    double conv_rms = 1;
    if (converged) {
        st_world *w = st_world_create(&with, &opts, &err);
        if (!w || !st_world_set_param(w, module, param, atof(converged), &err) ||
            !st_world_frame(w, &err) || !st_world_read(w, &conv, &err))
            return fail("converged render", &err);
        for (size_t i = 0; i < (size_t)conv.width * conv.height * 3; i++)
            conv.data[i] -= base.data[i];
        st_world_destroy(w);
        // Its RMS, to report the self-convergence error relative to it.
        st_image zero = {0};
        st_metrics m;
        if (!st_image_alloc(&zero, conv.width, conv.height, 3, &err) ||
            !st_image_compare(&zero, &conv, &m, &err))
            return fail("compare", &err);
        conv_rms = m.scaled_rmse[3];
        st_image_free(&zero);
    }
    printf("# %s, %dx%d, %s, %d frames (recompute), shafts vs %s%s%s\n", argv[1], base.width,
           base.height, st_context_renderer(), frames, argv[2],
           converged ? "; self-convergence vs " : "", converged ? converged : "");
    printf("%-22s %10s %12s %12s %10s %12s\n", "setting", "frame ms", "module gpu ms",
           "scaled rmse", "scale", "vs conv. rel");
    float *ms = calloc((size_t)frames, sizeof *ms);
    {
        // Baseline: the scene without medium (the module skips its passes),
        // no shafts at all (scale 0, error = RMS of the reference).
        double median;
        if (!time_frames(wb, frames, ms, &median, &err)) return fail("frame", &err);
        st_metrics m;
        st_image zero = {0};
        if (!st_image_alloc(&zero, base.width, base.height, 3, &err) ||
            !st_image_compare(&zero, &ref, &m, &err))
            return fail("compare", &err);
        printf("%-22s %10.2f %12s %12.5f %10s %12s\n", "(no shafts)", median, "-", m.scaled_rmse[3],
               "-", "-");
        st_image_free(&zero);
    }
    for (char *v = strtok(values, ","); v; v = strtok(NULL, ",")) {
        st_world *w = st_world_create(&with, &opts, &err);
        if (!w || !st_world_set_param(w, module, param, atof(v), &err)) return fail(v, &err);
        double median;
        if (!time_frames(w, frames, ms, &median, &err)) return fail("frame", &err);
        if (!st_world_read(w, &img, &err)) return fail("read", &err);
        st_image_free(&effect);
        if (!st_image_alloc(&effect, img.width, img.height, 3, &err)) return fail("alloc", &err);
        for (size_t i = 0; i < (size_t)img.width * img.height * 3; i++)
            effect.data[i] = img.data[i] - base.data[i];
        st_metrics m;
        if (!st_image_compare(&effect, &ref, &m, &err)) return fail("compare", &err);
        char setting[160];
        snprintf(setting, sizeof setting, "%s.%s=%s", module, param, v);
        double self = -1;
        st_metrics mc;
        if (converged && st_image_compare(&effect, &conv, &mc, &err))
            self = mc.scaled_rmse[3] / conv_rms;
        char self_s[32] = "-";
        if (self >= 0) snprintf(self_s, sizeof self_s, "%.5f", self);
        printf("%-22s %10.2f %12.2f %12.5f %10.4g %12s\n", setting, median,
               module_gpu_ms(w, module), m.scaled_rmse[3], m.scale, self_s);
        fflush(stdout);
        st_image_free(&img);
        st_world_destroy(w);
    }
    free(ms);
    st_image_free(&effect), st_image_free(&base), st_image_free(&ref), st_image_free(&conv);
    st_world_destroy(wb);
    st_context_destroy(ctx);
    st_scene_free(&with), st_scene_free(&without);
    return 0;
}
