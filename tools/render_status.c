#define _POSIX_C_SOURCE 200809L
#include "render_status.h"
#include "st_world.h"
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

// Why there is no number: one frame has no second one to compare with; an
// infinite or NaN estimate is a module still gathering (its info says what).
static void error_text(const st_still_status *s, char *out, size_t n) {
    double e = s->prog.error;
    if (s->ran <= 1)
        snprintf(out, n, "no estimate of the remaining error (one frame: it needs two to compare)");
    else if (!isfinite(e))
        snprintf(out, n, "no estimate of the remaining error yet (%s)",
                 s->prog.info[0] ? s->prog.info : "a module has not settled");
    else
        snprintf(out, n, "estimated remaining relative error %.4g", e);
}

void st_still_status_line(const st_still_status *s, char *out, size_t n) {
    char err[640], why[128] = "";
    error_text(s, err, sizeof err);
    switch (s->stop) {
    case ST_STOP_CONVERGED:
        snprintf(out, n, "converged after %ld frame(s), %.0f ms, %s", s->ran, s->total_ms, err);
        return;
    case ST_STOP_FRAMES: // asked for: not a stop before converging
        snprintf(out, n, "%ld frame(s) (--frames %ld), %.0f ms, %s", s->ran, s->limit, s->total_ms,
                 err);
        return;
    case ST_STOP_MAX_FRAMES:
        snprintf(why, sizeof why, "--max-frames %ld", s->limit);
        break;
    case ST_STOP_CAP:
        snprintf(why, sizeof why, "the cap of %ld frames", s->limit);
        break;
    case ST_STOP_MAX_SECONDS:
        snprintf(why, sizeof why, "--max-seconds %g", s->max_seconds);
        break;
    case ST_STOP_FILTER_CAP:
        snprintf(why, sizeof why, "the box filter's cap of %d frames", ST_FILTER_MAX_FRAMES);
        break;
    }
    snprintf(out, n, "%ld frame(s), stopped by %s before converging, %.0f ms, %s", s->ran, why,
             s->total_ms, err);
}

void st_still_progress_begin(st_still_progress *p, bool quiet) {
    *p = (st_still_progress){.on = !quiet && isatty(STDERR_FILENO) == 1};
    p->t0 = p->last = st_now_ms();
}

// Seconds left: exact for --frames; else the frames the error's 1/sqrt(n)
// fall needs to reach the box filter's tolerance, within the caps; < 0:
// unknown.
static double eta_s(const st_still_status *s, bool frames_given, double el_s) {
    double per = el_s / (double)s->ran, left_t = s->max_seconds - el_s;
    if (frames_given) return per * (double)(s->limit - s->ran);
    double cap = fmin(per * (double)(s->limit - s->ran), left_t);
    double e = s->prog.error;
    if (!s->has_prog || !isfinite(e) || s->ran < 2) return -1;
    double need = (double)s->ran * (e / ST_FILTER_TOLERANCE) * (e / ST_FILTER_TOLERANCE);
    return fmax(0.0, fmin(per * (need - (double)s->ran), cap));
}

void st_still_progress_update(st_still_progress *p, const st_still_status *s, bool frames_given) {
    if (!p->on || s->ran < 1) return;
    double now = st_now_ms();
    if (now - p->t0 < 1000.0 || now - p->last < 250.0) return;
    p->last = now;
    double el = (now - p->t0) / 1000.0, eta = eta_s(s, frames_given, el);
    char err[64] = "no error estimate yet";
    if (s->has_prog && s->ran > 1 && isfinite(s->prog.error))
        snprintf(err, sizeof err, "estimated remaining error %.3g", s->prog.error);
    char t[64];
    if (eta >= 0)
        snprintf(t, sizeof t, "ETA %.0f s", eta);
    else // no estimate yet: the frame and time caps bound it
        snprintf(t, sizeof t, "ETA at most %.0f s",
                 fmin(el / (double)s->ran * (double)(s->limit - s->ran), s->max_seconds - el));
    // \r and clear to the end of the line: the text changes length.
    fprintf(stderr, "\r\033[Kstrahl render: %ld frame(s), %s, %.1f s, %s", s->ran, err, el, t);
    fflush(stderr);
    p->drawn = true;
}

void st_still_progress_end(st_still_progress *p) {
    if (!p->drawn) return;
    fputs("\r\033[K", stderr);
    fflush(stderr);
}
