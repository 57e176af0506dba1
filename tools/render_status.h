// strahl render: why a still's frames stopped, said honestly in one line,
// and the self-overwriting progress line shown on a terminal while they run.
#ifndef ST_RENDER_STATUS_H
#define ST_RENDER_STATUS_H
#include "st_module.h"

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

// The final line, without the "strahl render: " prefix: "converged after N
// frame(s), T ms, estimated remaining relative error E" only when it did;
// "N frame(s) (--frames N), T ms, ..." for --frames; otherwise "N frame(s),
// stopped by WHAT before converging, T ms, ..."; with no finite estimate
// (one frame, or a module that cannot tell yet) it says so and why instead
// of printing 0 or inf.
void st_still_status_line(const st_still_status *s, char *out, size_t n);

// The progress line on stderr: drawn only when stderr is a terminal and
// not quiet, from 1 s on, at most 4 times a second; frames done, the
// estimated remaining error and an ETA (from the error's 1/sqrt(frames)
// fall towards the box filter's tolerance, else from the frame or time cap).
typedef struct st_still_progress {
    bool on, drawn;
    double t0, last;
} st_still_progress;
void st_still_progress_begin(st_still_progress *p, bool quiet);
// s->ran frames done of at most s->limit; frames_given: --frames (the ETA is
// exact then).
void st_still_progress_update(st_still_progress *p, const st_still_status *s, bool frames_given);
// Clears the line (the final line follows on stdout).
void st_still_progress_end(st_still_progress *p);
#endif
