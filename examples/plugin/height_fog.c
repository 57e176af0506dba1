// height_fog: exponential height fog, an out-of-tree strahl plugin
// (examples/plugin, walked through in docs/plugin-guide.md). Fog density
// falls off with height,
//   sigma(y) = density e^(-falloff (y - height)),
// and a view ray to a surface at distance d keeps the fraction
// T = e^(-tau) of the surface's radiance, tau the density integrated along
// the ray, and gains (1 - T) times the fog's own radiance:
//   L = L_surface T + radiance (1 - T).
// tau has a closed form (shaders/height_fog/tau.comp), so the result is
// exact per pixel; pixels without a surface are left as they are.
//
// Two declared passes and no code: a compute pass writes tau per pixel into
// the target height_fog.tau, a full-screen pass applies it to the image.
#include <st_module.h>

enum { P_DENSITY, P_FALLOFF, P_HEIGHT, P_RADIANCE, P_COUNT };

static const st_param_def params[P_COUNT] = {
    {"density", ST_PARAM_FLOAT, 0.1, 0, 100, NULL, "extinction at `height`, 1/m"},
    {"falloff", ST_PARAM_FLOAT, 0.5, 0, 100, NULL, "density falls by e every 1/falloff metres up"},
    {"height", ST_PARAM_FLOAT, 0, -1e4, 1e4, NULL,
     "height (y, metres) where the density is `density`"},
    {"radiance", ST_PARAM_FLOAT, 0.2, 0, 1e6, NULL,
     "radiance of the fog itself (grey, W/(sr m^2))"},
};

// The programs strahl compiles, hot-reloads and deletes for the plugin
// ("height_fog/..." from the shaders/height_fog folder beside this .so,
// "common/..." from strahl's own).
static const st_program_decl programs[] = {
    {"tau", .comp = "height_fog/tau.comp"},
    {"fog", .frag = "height_fog/fog.frag"},
};

// "tau" runs after the regular pass (it reads the G-buffer) and writes its
// own R32F target at the screen's size, which strahl allocates, resizes and
// frees; strahl dispatches the compute program over it (bound as image unit
// 0), one invocation per pixel. "fog" reads the image and tau and writes the
// next image: strahl draws the full-screen triangle. Both programs get the
// camera uniforms, st_hdr_in, st_gbuffer and the parameters as the uniforms
// u_density, u_falloff, u_height, u_radiance.
static const st_pass_decl passes[] = {
    {{"tau", ST_STAGE_POST, "gbuffer", "height_fog.tau", 0},
     .program = "tau",
     .target = {GL_R32F, 1, .filter = GL_NEAREST}},
    {{"fog", ST_STAGE_POST, "hdr,height_fog.tau", "hdr", ST_PASS_FULLSCREEN}, .program = "fog"},
};

// The optical depth is bound as the sampler height_fog_tau on every program
// strahl binds: the fog pass reads it, and so could another plugin's shader.
static const st_export_decl exports[] = {{"height_fog_tau", .target = "height_fog.tau"}};

ST_PLUGIN(.name = "height_fog",
          .description = "exponential height fog (compute pass: closed-form optical depth)",
          ST_PARAMS(params), ST_PROGRAMS(programs), ST_PASSES(passes), ST_EXPORTS(exports),
          .param_uniforms = "u_")
