// Small double-precision 3-vector helpers for the CPU code that does
// geometry in double (physics oracles, the reference renderer, tests).
// Internal: not part of the installed SDK.
#ifndef ST_VEC3_H
#define ST_VEC3_H
#include <math.h>
#include <string.h>

static inline double st_dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void st_sub3(double o[3], const double a[3], const double b[3]) {
    for (int k = 0; k < 3; k++)
        o[k] = a[k] - b[k];
}
// o may alias a or b.
static inline void st_cross3(double o[3], const double a[3], const double b[3]) {
    double t[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    memcpy(o, t, sizeof t);
}
static inline double st_len3(const double a[3]) {
    return sqrt(st_dot3(a, a));
}
// Scales v to unit length and returns its former length; a zero or
// non-finite vector is left as it is (the caller checks the length).
static inline double st_normalize3(double v[3]) {
    double l = st_len3(v);
    if (l > 0 && isfinite(l))
        for (int k = 0; k < 3; k++)
            v[k] /= l;
    return l;
}
#endif
