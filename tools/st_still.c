// The still loop (st_still.h), shared by `strahl render` and the Python module.
#include "st_still.h"

void st_still_settle(st_still_opts *o, long max_frames) {
    // Without a frame count a still image is a converged one: frames run until
    // every progressive module reports convergence (or a cap is reached).
    if (!o->frames_given) o->frames = max_frames;
    if (o->warmup < 0) o->warmup = o->frames > 1 && o->frames_given ? 1 : 0;
    if (o->warmup >= o->frames) o->warmup = o->frames - 1;
}

st_world_opts st_still_world_opts(const st_scene *scene, const st_still_opts *o, bool timing) {
    st_world_opts opts = {.timing = timing, .filter = scene->filter};
    // A frame count: the box filter's mean of exactly that many frames.
    if (o->frames_given) opts.filter_max_frames = (int)o->frames, opts.filter_tolerance = -1;
    return opts;
}

bool st_still_run(st_world *w, const st_still_opts *o, st_still_result *res, st_err *err) {
    bool until_converged = !o->frames_given;
    double start = st_now_ms();
    res->prog = (st_progress){.converged = true};
    for (long f = 0; f < o->frames; f++) {
        if (f == o->warmup) st_world_reset_samples(w);
        double t0 = st_now_ms();
        if (!st_world_frame(w, err)) return false;
        glFinish();
        if (f >= o->warmup) res->frame_ms[res->timed++] = (float)(st_now_ms() - t0);
        res->ran++;
        res->has_prog = st_world_progress(w, &res->prog);
        if (o->on_frame) o->on_frame(o->user, res->ran, &res->prog, res->has_prog);
        if (until_converged &&
            (!res->has_prog || res->prog.converged || st_now_ms() - start > 1000 * o->max_seconds))
            break;
    }
    res->total_ms = st_now_ms() - start;
    return true;
}
