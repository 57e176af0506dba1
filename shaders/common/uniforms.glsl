// Uniforms the world sets on every shader that declares them.
#ifndef ST_UNIFORMS_GLSL
#define ST_UNIFORMS_GLSL
#ifndef ST_MAX_LIGHTS
#define ST_MAX_LIGHTS 8
#endif
uniform mat4 st_view, st_proj, st_view_proj, st_inv_view_proj;
uniform vec3 st_cam_pos;
uniform float st_near, st_far, st_fov_y; // fov in radians
uniform vec2 st_resolution;
uniform int st_frame_index;
uniform int st_num_lights;
uniform vec3 st_light_pos[ST_MAX_LIGHTS];
uniform vec3 st_light_intensity[ST_MAX_LIGHTS]; // W/sr (point, spot on its axis); W/m^2 (directional)
// 0 point, 1 directional, 2 spot (st_light_type in C).
uniform int st_light_type[ST_MAX_LIGHTS];
// The scene's light types, bit 1 << type (st_world_light_defines; all
// without it). Tests through these macros fold to false for absent types,
// and their code compiles out: llvmpipe runs both sides of a branch on a
// uniform, so a sun's cascade lookups would otherwise cost every pixel of a
// point-lit scene.
#ifndef ST_LIGHT_TYPES
#define ST_LIGHT_TYPES 7
#endif
#define ST_LIGHT_IS(i, t) ((ST_LIGHT_TYPES & (1 << (t))) != 0 && st_light_type[i] == (t))
#define ST_LIGHT_POSITIONED(i) ((ST_LIGHT_TYPES & 5) != 0 && st_light_type[i] != 1)
uniform vec3 st_light_dir[ST_MAX_LIGHTS]; // unit travel direction (directional, spot)
// Spot: x, y = glTF falloff scale and offset in cos (st_spot_falloff);
// directional: z = entry (st_directional_entry).
uniform vec3 st_light_shape[ST_MAX_LIGHTS];
// Homogeneous medium (1/m) and its phase function: 0 isotropic, 1 Rayleigh, 2 HG.
uniform int st_has_medium;
uniform vec3 st_sigma_s, st_sigma_a;
uniform int st_phase_kind;
uniform float st_phase_g;
#endif
