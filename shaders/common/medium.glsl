// Extinction on light paths (docs/physics.md): with a medium, light travelling
// from a light to a surface or scattering point, and from a bounce's sender to
// its receiver, is attenuated by e^(-sigma_t d). C: st_medium_sigma_t,
// st_transmittance.
#ifndef ST_MEDIUM_GLSL
#define ST_MEDIUM_GLSL
#include "common/uniforms.glsl"
#include "common/physics.glsl"

vec3 st_medium_sigma_t() { return st_has_medium != 0 ? st_sigma_s + st_sigma_a : vec3(0.0); }

// Transmittance of a light path of length d through the scene's medium.
vec3 st_path_transmittance(float d) { return st_transmittance(st_medium_sigma_t(), d); }
#endif
