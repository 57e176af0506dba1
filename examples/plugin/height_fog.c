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
#include <stdlib.h>

enum { P_DENSITY, P_FALLOFF, P_HEIGHT, P_RADIANCE, P_COUNT };

static const st_param_def params[P_COUNT] = {
    {"density", ST_PARAM_FLOAT, 0.1, 0, 100, NULL, "extinction at `height`, 1/m"},
    {"falloff", ST_PARAM_FLOAT, 0.5, 0, 100, NULL, "density falls by e every 1/falloff metres up"},
    {"height", ST_PARAM_FLOAT, 0, -1e4, 1e4, NULL,
     "height (y, metres) where the density is `density`"},
    {"radiance", ST_PARAM_FLOAT, 0.2, 0, 1e6, NULL,
     "radiance of the fog itself (grey, W/(sr m^2))"},
};

typedef struct fog {
    const double *p; // this instance's parameters, kept up to date by strahl
    st_shader *sh;
    st_pass_info info;
} fog;

static void *create(st_world *w, const double *p, st_err *err) {
    fog *f = calloc(1, sizeof *f);
    if (!f) {
        st_fail(err, ST_ERR_RUNTIME, "out of memory");
        return NULL;
    }
    f->p = p;
    // "height_fog/..." is read from the shaders/height_fog folder beside
    // this .so; "common/..." from strahl's own shaders.
    f->sh = st_shader_load("common/fullscreen.vert", "height_fog/fog.frag", NULL, err);
    if (!f->sh) {
        free(f);
        return NULL;
    }
    // Reads the image and the G-buffer, writes the next image.
    f->info = (st_pass_info){"fog", ST_STAGE_POST, "hdr,gbuffer", "hdr", ST_PASS_FULLSCREEN};
    return f;
}

static void destroy(void *self) {
    fog *f = self;
    st_shader_destroy(f->sh);
    free(f);
}

static int num_passes(void *self) {
    return 1;
}
static const st_pass_info *pass_info(void *self, int pass) {
    return &((fog *)self)->info;
}
static st_shader *shader(void *self, int pass) {
    return ((fog *)self)->sh;
}

// The world has bound the shader, the camera uniforms, st_hdr_in and
// st_gbuffer; the plugin adds its own and the world draws the triangle.
static bool on_pass(void *self, int pass, const st_frame *frame, st_err *err) {
    fog *f = self;
    st_shader_set_float(f->sh, "u_density", (float)f->p[P_DENSITY]);
    st_shader_set_float(f->sh, "u_falloff", (float)f->p[P_FALLOFF]);
    st_shader_set_float(f->sh, "u_height", (float)f->p[P_HEIGHT]);
    st_shader_set_float(f->sh, "u_radiance", (float)f->p[P_RADIANCE]);
    return st_gl_check("height_fog", err);
}

static bool reload(void *self, st_err *err) {
    return st_shader_reload(((fog *)self)->sh, err);
}

ST_PLUGIN(.name = "height_fog",
          .description = "exponential height fog (post-process, closed-form optical depth)",
          ST_PARAMS(params), .create = create, .destroy = destroy, .num_passes = num_passes,
          .pass_info = pass_info, .shader = shader, .on_pass = on_pass, .reload = reload)
