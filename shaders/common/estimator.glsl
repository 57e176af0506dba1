// The one-bounce gather estimators of docs/physics.md, shared by atlas_gi (senders
// drawn over the atlas) and ssgi (senders drawn over the camera image).
//   area:   L1 = rho/pi (cells/N) sum a_j L0_j V cos+x cos+j pi/(pi d^2 + a_j)
//           (a texel as a disk: a/d^2 bounded at concave edges)
//   thesis: L1 = rho/pi (2 pi/N) sum L0_j cos+x over mutually facing samples
//           (Merz 2010, eq. 9: no sender cosine, no 1/d^2, no area)
// Samples that land on no surface count in N and add nothing.
#ifndef AG_ESTIMATOR_GLSL
#define AG_ESTIMATOR_GLSL
#include "common/physics.glsl"

float ag_sample_weight(int estimator, float cos_x, float cos_j, float area, float d2) {
    if (estimator == 1) return cos_x;
    return cos_x * cos_j * (ST_PI * area / (ST_PI * d2 + area));
}

// `cells`: how many texels (pixels) the N samples are drawn from.
vec3 ag_estimate(int estimator, vec3 rho, vec3 sum, float cells, float n) {
    float k = estimator == 1 ? 2.0 * ST_PI / n : cells / n;
    vec3 L = rho / ST_PI * k * sum;
    // Nothing non-finite leaves a gather, and nothing so large that sums of
    // frames (or its square) could overflow.
    if (!all(lessThan(abs(L), vec3(3e38)))) return vec3(0.0);
    return min(L, vec3(1e15));
}

float ag_luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
#endif
