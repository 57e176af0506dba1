// Extinction on every path (docs/physics.md): with a medium, light travelling
// from a light to a surface or scattering point, from a bounce's sender to
// its receiver, and from what the camera sees to the camera, is attenuated
// by e^(-sigma_t d), also where sigma_s = 0. C: st_medium_sigma_t,
// st_transmittance. The view ray's share is applied once, by the regular
// pass (regular.frag, background.frag); volumetric modules only add light.
#ifndef ST_MEDIUM_GLSL
#define ST_MEDIUM_GLSL
#include "common/uniforms.glsl"
#include "common/physics.glsl"

vec3 st_medium_sigma_t() { return st_has_medium != 0 ? st_sigma_s + st_sigma_a : vec3(0.0); }

// Transmittance of a light path of length d through the scene's medium.
vec3 st_path_transmittance(float d) { return st_transmittance(st_medium_sigma_t(), d); }

// Transmittance of the view ray from the camera to a point s metres away.
vec3 st_view_transmittance(float s) { return st_path_transmittance(s); }
#endif
