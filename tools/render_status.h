// strahl render: why a still's frames stopped, said honestly in one line,
// and the self-overwriting progress line shown on a terminal while they run.
#ifndef ST_RENDER_STATUS_H
#define ST_RENDER_STATUS_H
#include "st_still.h"

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
