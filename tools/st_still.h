// The still loop that `strahl render` and the Python module share: how
// many frames a still takes, the world options that go with them, and the
// frames themselves (until converged unless the count is given).
#ifndef ST_STILL_H
#define ST_STILL_H
#include "st_world.h"

// What ended the frames.
typedef enum {
    ST_STOP_CONVERGED,   // every progressive module and the box filter converged
    ST_STOP_FRAMES,      // --frames N ran
    ST_STOP_MAX_FRAMES,  // --max-frames N reached
    ST_STOP_CAP,         // the default cap on frames reached (no --max-frames)
    ST_STOP_MAX_SECONDS, // --max-seconds (or its default) ran out
    ST_STOP_FILTER_CAP,  // the box filter's own cap (ST_FILTER_MAX_FRAMES) ended it unconverged
} st_stop;

typedef struct st_still_status {
    st_stop stop;
    long ran;           // frames run
    long limit;         // the frame count of --frames, --max-frames or the cap
    double total_ms;    // wall time of the frames
    double max_seconds; // the time cap
    bool has_prog;      // some module or the box filter reports progress
    st_progress prog;   // the last report
} st_still_status;

typedef struct st_still_opts {
    long frames;           // frames to run (without frames_given: the cap, max frames)
    long warmup;           // frames before the timed ones (-1: 1 if frames > 1 were given, else 0)
    double max_seconds;    // cap on seconds when running to convergence
    bool frames_given;     // exactly `frames` frames (box: their mean), else until converged
    bool max_frames_given; // `frames` is the user's cap, not the default one (for the status)
    // Called after every frame that does not end the still (NULL: none), e.g.
    // for a command's progress line; the loop itself prints nothing (the
    // Python module shares it).
    void (*on_frame)(void *user, const st_still_status *st);
    void *user;
} st_still_opts;

// What the frames did: their times after the warm-up (frame_ms holds
// o->frames values, the caller's), how many ran, why they stopped and the
// last progress report.
typedef struct st_still_result {
    float *frame_ms;
    int timed;
    st_still_status st;
} st_still_result;

// Settles frames and warm-up: without frames_given frames becomes max_frames.
void st_still_settle(st_still_opts *o, long max_frames);
// The world options of a still of `scene` with o (settled): the scene's
// filter; a given frame count is the box filter's exact mean of that many.
st_world_opts st_still_world_opts(const st_scene *scene, const st_still_opts *o, bool timing);
// Runs the frames (until converged without frames_given).
bool st_still_run(st_world *w, const st_still_opts *o, st_still_result *res, st_err *err);

#endif
