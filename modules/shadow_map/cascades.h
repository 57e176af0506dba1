// Cascaded orthographic shadow maps for directional lights: the view frustum
// from the near plane to the scene's far end is cut by the practical split
// scheme, and each slice gets an orthographic map around a bounding circle in
// the light's plane. The fit keeps a margin, so a camera move re-renders a
// cascade only when its slice leaves the fitted circle (or shrinks well
// inside it): the texel footprint stays within [1, 2) x 1.2 of the ideal.
#ifndef SM_CASCADES_H
#define SM_CASCADES_H
#include "st_module.h"

#define SM_MAX_CASCADES 4

typedef struct sm_rect {
    double cu, cv, half; // centre in the light's (u, v) basis and half size, metres
} sm_rect;

typedef struct sm_sun {
    double L[3], u[3], v[3]; // unit direction toward the light and the map's basis
    double entry, zrange;    // path = entry - dot(x, L) in [0, zrange] over the scene
    sm_rect fit[SM_MAX_CASCADES];
    double far_z[SM_MAX_CASCADES]; // view depth where each cascade ends
    int count;
    bool fitted;
} sm_sun;

// The light's basis and depth range over the scene's bounds.
void sm_sun_init(sm_sun *s, const st_scene *scene, const float direction[3]);
// Fits the cascades to the frame's camera. Returns true if any cascade's
// rectangle changed (the maps must be re-rendered); `force` refits all.
bool sm_sun_fit(sm_sun *s, const st_scene *scene, const st_frame *f, int cascades, double lambda,
                bool force);
// Column-major matrix from world space to cascade c's clip space: x, y over
// the rectangle, z from path 0 (-1) to zrange (+1).
void sm_sun_matrix(const sm_sun *s, int c, float out[16]);
// The basis rule shared with shaders/shadow_map/visibility.glsl.
void sm_sun_basis(const double L[3], double u[3], double v[3]);
#endif
