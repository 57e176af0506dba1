// Parameter slider mapping of strahl view, shared by the panel
// (view_overlay.c, mouse) and the keyboard actions (view_actions.c): a
// parameter value <-> a slider position t in [0, 1].
#include "view.h"
#include <math.h>

// Wide positive ranges (resolution 16..8192, sigma 1e-4..10) get a log
// slider so every decade is reachable.
static bool log_scale(const st_param_def *d) {
    return d->min > 0 && d->max / d->min >= 100;
}

double view_param_to_t(const st_param_def *d, double x) {
    if (d->type == ST_PARAM_BOOL) return x != 0;
    if (d->type == ST_PARAM_ENUM) {
        int n = st_param_num_choices(d);
        return n > 1 ? x / (n - 1) : 0;
    }
    if (!(d->max > d->min) || !isfinite(d->max - d->min)) return 0;
    double t =
        log_scale(d) ? log(x / d->min) / log(d->max / d->min) : (x - d->min) / (d->max - d->min);
    return t < 0 ? 0 : t > 1 ? 1 : t;
}

double view_param_from_t(const st_param_def *d, double t) {
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    if (d->type == ST_PARAM_BOOL) return t >= 0.5;
    if (d->type == ST_PARAM_ENUM) return floor(t * (st_param_num_choices(d) - 1) + 0.5);
    double x = log_scale(d) ? d->min * pow(d->max / d->min, t) : d->min + t * (d->max - d->min);
    if (d->type == ST_PARAM_INT) x = floor(x + 0.5);
    return x < d->min ? d->min : x > d->max ? d->max : x;
}
