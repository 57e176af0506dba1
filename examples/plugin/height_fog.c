// height_fog: exponential height fog as a post-process, an out-of-tree
// strahl plugin (examples/plugin). Fog density falls off with height,
//   sigma(y) = density e^(-falloff (y - height)),
// and a view ray to a surface at distance d keeps the fraction
// T = e^(-tau) of the surface's radiance, tau the density integrated along
// the ray, and gains (1 - T) times the fog's own radiance:
//   L = L_surface T + radiance (1 - T).
// tau has a closed form (see shaders/height_fog/fog.frag), so the result is
// exact per pixel; pixels without a surface are left as they are.
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

// One post pass that reads the image and the G-buffer and writes the next
// image. strahl loads its program ("height_fog/..." from the shaders/height_fog
// folder beside this .so, "common/..." from strahl's own), binds it with the
// camera uniforms, st_hdr_in and st_gbuffer, sets the parameters as the
// uniforms u_density, u_falloff, u_height, u_radiance and draws the triangle.
static const st_pass_decl passes[] = {
    {{"fog", ST_STAGE_POST, "hdr,gbuffer", "hdr", ST_PASS_FULLSCREEN},
     .frag = "height_fog/fog.frag"},
};

ST_PLUGIN(.name = "height_fog",
          .description = "exponential height fog (post-process, closed-form optical depth)",
          ST_PARAMS(params), ST_PASSES(passes), .param_uniforms = "u_")
