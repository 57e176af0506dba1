// Screen-space light handling shared by the image-space god-ray modules
// (mitchell, sousa) and their tests: where a point light or the sun lands on
// the screen, how strongly its shafts are faded, and the light's tint.
//
// Fade rules (docs/architecture.md: nothing runs that the scene does not need):
// - behind the camera or at its position (view depth w <= near): 0, and the
//   projected position is never computed, so no mirrored rays;
// - between near and 2 near of view depth: smoothstep up to 1 (the disc and
//   the projection are unreliable that close to the camera plane);
// - off screen: 1 - smoothstep(0, margin, d), d the distance of the projected
//   position outside the [0,1]^2 screen in screen heights (aspect-corrected).
// The product is continuous in the light's position, so shafts never pop, and
// a fade of exactly 0 lets the module skip its passes.
// A directional light (the sun) is a point at infinity: its direction is
// projected with w = 0, so its view depth w is the cosine of its angle to the
// view axis. Behind the camera or on its plane (w <= 0): 0, no projection;
// there is no near range at infinity, and as w -> 0+ the projected position
// runs off to infinity, so the off-screen fade reaches 0 first (continuous).
#ifndef ST_GODRAY_H
#define ST_GODRAY_H
#include "st_module.h"

typedef struct st_godray_light {
    float uv[2]; // texture coordinates of the light, (0,0) bottom left; (0.5,0.5) when fade = 0
    float fade;  // [0, 1]
    float w;     // view depth (clip w), metres in front of the camera
} st_godray_light;

// view_proj column-major (GL); p the light's world position.
st_godray_light st_godray_project(const float *view_proj, float near_z, int width, int height,
                                  const float p[3], double margin);

// The sun: to_light the unit direction toward it (minus the light's travel
// direction). view_proj column-major (GL).
st_godray_light st_godray_project_dir(const float *view_proj, int width, int height,
                                      const float to_light[3], double margin);

// A light's radiance as a screen-space source, W/(m^2 sr) per channel: a point
// light as a sphere of radius point_radius, I / (pi r^2); the sun as a disc of
// its angular diameter delta, E / Omega with Omega = 2 pi (1 - cos(delta / 2)).
void st_godray_source_radiance(const st_light_desc *l, double point_radius, double out[3]);

// A light's tint: its source radiance divided by the largest channel of any
// light's in the scene, so the brightest light is at most 1 per channel (the
// thesis draws the light object "in the light colour" into an 8-bit target)
// and every other light keeps its physical ratio to it, whatever its type.
// With point lights alone this is intensity / the largest intensity. Zero
// when every light is black.
void st_godray_tint(const st_light_desc *lights, int num_lights, int k, double point_radius,
                    float out[3]);

// Shafts need something to scatter: a medium with sigma_s > 0 in some channel.
bool st_godray_medium_active(const st_scene *s);

// Light k this frame (margin: the module's fade_margin), and its tint.
st_godray_light st_godray_light_state(const st_frame *f, int k, double margin, double point_radius,
                                      float tint[3]);
// Light k casts shafts this frame: a scattering medium, fade > 0, not black.
bool st_godray_light_active(const st_frame *f, int k, double margin);

// The light types both techniques handle (point lights and the sun).
#define ST_GODRAY_LIGHT_TYPES (ST_LIGHT_BIT(ST_LIGHT_POINT) | ST_LIGHT_BIT(ST_LIGHT_DIRECTIONAL))

#endif
