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

// Why a run to convergence stopped after frame f (of o->frames, ms since
// the start), or -1 to go on.
static int stop_reason(const st_still_opts *o, const st_still_status *st, long f, double ms) {
    const st_progress *p = &st->prog;
    if (!st->has_prog) return ST_STOP_CONVERGED; // nothing progressive: one frame is the image
    if (p->converged) {
        // The box filter also reports converged at its own frame cap.
        bool capped = p->frames >= ST_FILTER_MAX_FRAMES && p->error > ST_FILTER_TOLERANCE;
        return capped ? ST_STOP_FILTER_CAP : ST_STOP_CONVERGED;
    }
    if (ms > 1000 * o->max_seconds) return ST_STOP_MAX_SECONDS;
    if (f + 1 == o->frames) return o->max_frames_given ? ST_STOP_MAX_FRAMES : ST_STOP_CAP;
    return -1;
}

bool st_still_run(st_world *w, const st_still_opts *o, st_still_result *res, st_err *err) {
    double start = st_now_ms();
    st_still_status *st = &res->st;
    *st = (st_still_status){.stop = ST_STOP_FRAMES,
                            .limit = o->frames,
                            .max_seconds = o->max_seconds,
                            .prog = {.converged = true}};
    for (long f = 0; f < o->frames; f++) {
        if (f == o->warmup) st_world_reset_samples(w);
        double t0 = st_now_ms();
        if (!st_world_frame(w, err)) return false;
        glFinish();
        if (f >= o->warmup) res->frame_ms[res->timed++] = (float)(st_now_ms() - t0);
        st->ran++;
        st->has_prog = st_world_progress(w, &st->prog);
        int why = o->frames_given ? -1 : stop_reason(o, st, f, st_now_ms() - start);
        st->total_ms = st_now_ms() - start;
        if (why >= 0) {
            st->stop = (st_stop)why;
            break;
        }
        if (o->on_frame) o->on_frame(o->user, st);
    }
    st->total_ms = st_now_ms() - start;
    return true;
}
