// shadow_map: shadows for point, spot and directional lights. Point and spot
// lights: one cube map per light (layers of one cube-map array) storing the
// distance to the light, view-independent (a camera-only frame re-renders
// nothing). Directional lights: cascaded orthographic maps storing the
// light's path from where it enters the scene (cascades.h), re-fitted only
// when the camera's slices leave their fitted region. The regular pass and
// volumetric modules test visibility against them with a slope-scaled bias
// and optional PCF. refine=true settles the hard lookups that are ambiguous
// (a shadow edge within two texels, a receiver lit only thanks to the bias)
// with an exact ray against the scene's triangles (a BVH on the GPU,
// framework/st_bvh.h), so surface shadow edges are where the geometry
// puts them, not where the map's texels do.
#include "cascades.h"
#include "st_bvh.h"
#include "st_world_api.h"
#include <cglm/cglm.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    P_RESOLUTION,
    P_CASCADE_RESOLUTION,
    P_BIAS,
    P_SLOPE_BIAS,
    P_PCF,
    P_PCF_RADIUS,
    P_CASCADES,
    P_SPLIT,
    P_REFINE,
    P_COUNT
};

static const st_param_def params[P_COUNT] = {
    // 512, not 1024: with refine the cube only has to say where an edge may
    // be (surfaces get the exact answer there), and a 1024 cube was half of a
    // relight's time; volumes (toth) measure the same against Cycles at 512
    // (docs/benchmarks.md). The cascades stay at 1024: toth's sun shadows in
    // a medium read them unrefined and lose 1% per pixel at 512.
    {"resolution", ST_PARAM_INT, 512, 16, 8192, NULL,
     "point and spot lights: cube face size in texels"},
    {"cascade_resolution", ST_PARAM_INT, 1024, 16, 8192, NULL,
     "directional lights: size of each cascade in texels"},
    {"bias", ST_PARAM_FLOAT, 1.0, 0, 64, NULL,
     "constant depth bias, in shadow-map texels at the receiver's distance"},
    {"slope_bias", ST_PARAM_FLOAT, 1.0, 0, 64, NULL,
     "bias per unit tan(angle of incidence), in texels (clamped at tan = 20)"},
    {"pcf", ST_PARAM_BOOL, 0, 0, 1, NULL, "percentage-closer filtering over 16 taps"},
    {"pcf_radius", ST_PARAM_FLOAT, 1.5, 0.5, 16, NULL, "PCF kernel radius in texels"},
    {"cascades", ST_PARAM_INT, 4, 1, SM_MAX_CASCADES, NULL,
     "directional lights: shadow cascades over the view"},
    {"cascade_split", ST_PARAM_FLOAT, 0.75, 0, 1, NULL,
     "directional lights: 0 uniform, 1 logarithmic split distances (practical split scheme)"},
    {"refine", ST_PARAM_BOOL, 1, 0, 1, NULL,
     "surfaces without PCF: where the map is ambiguous (taps two texels around disagree, or the "
     "lookup is lit only thanks to the bias), an exact ray against the scene's triangles "
     "decides"},
};

// The distance to a point light (cube faces) and a sun's path from where it
// enters the scene (cascades); compiled on first use, so a scene without a
// sun never compiles the cascade program.
enum { PROG_DEPTH, PROG_CASCADE };
static const st_program_decl programs[] = {
    {"depth", "shadow_map/depth.vert", "shadow_map/depth.frag"},
    {"cascade", "shadow_map/depth.vert", "shadow_map/cascade.frag"},
};

// What shaders including shadow_map/visibility.glsl read that a parameter or
// a target says as it is (the world sets them by the uniform's GLSL type);
// the uniforms derived from the scene and the camera are callbacks below.
static const st_export_decl exports[] = {
    {"st_shadow_cubes", .target = "shadow_map.cubes"},
    {"st_shadow_suns", .target = "shadow_map.suns"},
    {"st_shadow_res", "resolution"},
    {"st_shadow_sun_res", "cascade_resolution"},
    {"st_shadow_bias", "bias"},
    {"st_shadow_slope", "slope_bias"},
    {"st_shadow_pcf", "pcf"},
    {"st_shadow_pcf_radius", "pcf_radius"},
    {"st_shadow_cascade_count", "cascades"},
};

typedef struct shadow_map {
    st_world *w;
    const double *p;
    float lo[3], hi[3]; // scene bounds, re-taken when the geometry changes
    st_pass_info info;
    // Directional lights: slot per light (-1 none), cascades in a 2D array.
    int sun_slot[ST_MAX_LIGHTS], num_suns;
    sm_sun suns[ST_MAX_LIGHTS];
    bool sun_dirty[ST_MAX_LIGHTS]; // fitted anew but not rendered yet
    // refine: the scene's triangles in world-owned buffers (0: not built)
    GLuint bvh_nodes, bvh_tris;
} shadow_map;

// The world's targets: one distance cube per light (layers of a cube-map
// array), the light's path per texel for every (directional light, cascade)
// (a 2D array). Without a directional light a 1x1 layer: every sampler the
// shaders declare must see a texture of its own type, or the draw fails.
static bool declare_targets(shadow_map *s, st_err *err) {
    int size = (int)s->p[P_RESOLUTION], lights = st_world_scene(s->w)->num_lights;
    int sun_size = (int)s->p[P_CASCADE_RESOLUTION];
    int sun_layers = s->num_suns * (int)s->p[P_CASCADES];
    const st_target_desc cubes = {GL_R32F,
                                  .depth = true,
                                  .type = GL_TEXTURE_CUBE_MAP_ARRAY,
                                  .width = size,
                                  .height = size,
                                  .layers = lights,
                                  .filter = GL_NEAREST},
                         suns = {GL_R32F,
                                 .depth = sun_layers > 0,
                                 .type = GL_TEXTURE_2D_ARRAY,
                                 .width = sun_layers > 0 ? sun_size : 1,
                                 .height = sun_layers > 0 ? sun_size : 1,
                                 .layers = sun_layers,
                                 .filter = GL_NEAREST};
    for (int i = 0; i < ST_MAX_LIGHTS; i++)
        s->sun_dirty[i] = true;
    return st_world_declare_target(s->w, "shadow_map.cubes", &cubes, err) &&
           st_world_declare_target(s->w, "shadow_map.suns", &suns, err);
}

// The scene's world-space bounds (every vertex), for the cube's clip planes.
static void scene_bounds(const st_scene *sc, float lo[3], float hi[3]) {
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int m = 0; m < sc->num_meshes; m++) {
        const st_mesh *me = &sc->meshes[m];
        const float *M = me->model; // column-major
        for (uint32_t v = 0; v < me->num_vertices; v++) {
            const float *p = me->positions + 3 * (size_t)v;
            for (int r = 0; r < 3; r++) {
                float w = M[r] * p[0] + M[4 + r] * p[1] + M[8 + r] * p[2] + M[12 + r];
                lo[r] = fminf(lo[r], w), hi[r] = fmaxf(hi[r], w);
            }
        }
    }
}

// Far plane for a light at lp: past the bounds' farthest corner (no vertex
// is farther), so every occluder is drawn wherever the light has moved.
static float light_far(const shadow_map *s, const float lp[3]) {
    float far2 = 1e-6f;
    for (int k = 0; k < 3; k++) {
        float a = fabsf(s->lo[k] - lp[k]), b = fabsf(s->hi[k] - lp[k]), m = fmaxf(a, b);
        if (isfinite(m)) far2 += m * m;
    }
    return sqrtf(far2) * 1.01f + 1e-3f;
}

static void *create(st_world *w, const double *p, st_err *err) {
    shadow_map *s = st_calloc(sizeof *s, err);
    if (!s) return NULL;
    s->w = w;
    s->p = p;
    scene_bounds(st_world_scene(w), s->lo, s->hi);
    const st_scene *sc = st_world_scene(w);
    for (int i = 0; i < sc->num_lights && i < ST_MAX_LIGHTS; i++) {
        s->sun_slot[i] = sc->lights[i].type == ST_LIGHT_DIRECTIONAL ? s->num_suns++ : -1;
        if (s->sun_slot[i] >= 0) sm_sun_init(&s->suns[s->sun_slot[i]], sc, sc->lights[i].direction);
    }
    if (!declare_targets(s, err)) {
        free(s);
        return NULL;
    }
    return s;
}

// The world frees its buffers (untrack deletes what it owns).
static void bvh_release(shadow_map *s) {
    if (s->bvh_nodes) {
        st_world_untrack(s->w, "shadow_map.bvh_nodes");
        st_world_untrack(s->w, "shadow_map.bvh_triangles");
    }
    s->bvh_nodes = s->bvh_tris = 0;
}

static void destroy(void *self) {
    bvh_release(self);
    free(self);
}

// One pass per light; nothing to do without lights.
static int num_passes(void *self) {
    return st_world_scene(((shadow_map *)self)->w)->num_lights;
}

static const st_pass_info *pass_info(void *self, int pass) {
    shadow_map *s = self;
    s->info = (st_pass_info){s->sun_slot[pass] >= 0 ? "cascades" : "cube", ST_STAGE_PRE, "",
                             "shadow_map", 0};
    return &s->info;
}

enum { SM_REDO = ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY | ST_CHANGE_LIGHTS | ST_CHANGE_PARAMS };

// Only geometry, lights or our parameters invalidate the cube maps; a
// directional light's cascades also when the camera's slices leave their fit.
static bool needed(void *self, int pass, const st_frame *f) {
    shadow_map *s = self;
    int slot = s->sun_slot[pass];
    if (slot < 0) return f->changes & SM_REDO;
    if (f->changes & (SM_REDO | ST_CHANGE_SIZE)) return true;
    if ((f->changes & ST_CHANGE_CAMERA) &&
        sm_sun_fit(&s->suns[slot], f->scene, f, (int)s->p[P_CASCADES], s->p[P_SPLIT], false))
        s->sun_dirty[slot] = true;
    return s->sun_dirty[slot];
}

static bool render_cascades(shadow_map *s, int slot, const st_frame *f, st_err *err) {
    sm_sun *sun = &s->suns[slot];
    if (f->changes & (SM_REDO | ST_CHANGE_SIZE)) {
        const st_light_desc *l = &f->scene->lights[0];
        for (int i = 0; i < f->scene->num_lights; i++)
            if (s->sun_slot[i] == slot) l = &f->scene->lights[i];
        sm_sun_init(sun, f->scene, l->direction);
        sm_sun_fit(sun, f->scene, f, (int)s->p[P_CASCADES], s->p[P_SPLIT], true);
    }
    st_shader *sh = st_frame_use_program(f, PROG_CASCADE, err);
    const st_target *t = sh ? st_world_get_target(s->w, "shadow_map.suns", err) : NULL;
    if (!t) return false;
    float L[3] = {(float)sun->L[0], (float)sun->L[1], (float)sun->L[2]};
    st_shader_set_vec3(sh, "u_to_light", L);
    st_shader_set_float(sh, "u_entry", (float)sun->entry);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    const float cleared[4] = {1e30f, 0, 0, 0};
    for (int c = 0; c < sun->count; c++) {
        st_target_bind_layer(t, slot * sun->count + c);
        glClearBufferfv(GL_COLOR, 0, cleared);
        glClearBufferfv(GL_DEPTH, 0, (const float[]){1.0f});
        float m[16];
        sm_sun_matrix(sun, c, m);
        st_shader_set_mat4(sh, "u_view_proj", m);
        st_world_draw(s->w, sh);
    }
    s->sun_dirty[slot] = false;
    return st_gl_check("shadow cascades", err);
}

// The BVH for refine, built on first use and again when the geometry changes.
static bool ensure_bvh(shadow_map *s, int pass, const st_frame *f, st_err *err) {
    if (s->p[P_REFINE] == 0) {
        bvh_release(s);
        return true;
    }
    if (s->bvh_nodes && (pass > 0 || !(f->changes & (ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY))))
        return true;
    uint32_t n = 0;
    float *c = st_bvh_scene_corners(f->scene, &n, err);
    if (!c) return false;
    st_bvh b;
    bool ok = st_bvh_build(&b, c, n, err);
    free(c);
    if (!ok) return false;
    // The layout bvh.glsl reads (st_bvh.h); at least one triangle's room.
    // (st_bvh is moving into the SDK, branch sdk-physics; these stay world buffers.)
    size_t tris = (b.num_tris ? b.num_tris : 1) * 12 * sizeof(float);
    s->bvh_nodes = st_world_buffer(s->w, "shadow_map.bvh_nodes", b.num_nodes * 8 * sizeof(float),
                                   b.nodes, err);
    s->bvh_tris =
        s->bvh_nodes ? st_world_buffer(s->w, "shadow_map.bvh_triangles", tris, b.tris, err) : 0;
    st_bvh_free(&b);
    if (!s->bvh_tris) bvh_release(s);
    return s->bvh_tris && st_gl_check("shadow_map bvh upload", err);
}

static bool on_pass(void *self, int pass, const st_frame *f, st_err *err) {
    shadow_map *s = self;
    if (!ensure_bvh(s, pass, f, err)) return false;
    if (s->sun_slot[pass] >= 0) return render_cascades(s, s->sun_slot[pass], f, err);
    const float *lp = f->scene->lights[pass].position;
    // Cube face directions and up vectors of the GL cube-map convention.
    static const float dirs[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                     {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    static const float ups[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1},
                                    {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    // Clip planes from the light's current position (st_world_set_light
    // moves it; a plane fixed at create would cut off what lies past it).
    if (f->changes & (ST_CHANGE_FIRST | ST_CHANGE_GEOMETRY)) scene_bounds(f->scene, s->lo, s->hi);
    float far_z = light_far(s, lp);
    mat4 proj;
    glm_perspective(glm_rad(90.0f), 1.0f, far_z * 1e-4f, far_z, proj);
    st_shader *sh = st_frame_use_program(f, PROG_DEPTH, err);
    const st_target *t = sh ? st_world_get_target(s->w, "shadow_map.cubes", err) : NULL;
    if (!t) return false;
    st_shader_set_vec3(sh, "u_light_pos", lp);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    const float cleared[4] = {1e30f, 0, 0, 0};
    for (int face = 0; face < 6; face++) {
        st_target_bind_layer(t, 6 * pass + face);
        glClearBufferfv(GL_COLOR, 0, cleared);
        glClearBufferfv(GL_DEPTH, 0, (const float[]){1.0f});
        vec3 eye, center, up;
        memcpy(eye, lp, sizeof eye);
        memcpy(up, ups[face], sizeof up);
        glm_vec3_add(eye, (float *)dirs[face], center);
        mat4 view, vp;
        glm_lookat(eye, center, up, view);
        glm_mat4_mul(proj, view, vp);
        st_shader_set_mat4(sh, "u_view_proj", (float *)vp);
        st_world_draw(s->w, sh);
    }
    return st_gl_check("shadow cube faces", err);
}

// The uniforms visibility.glsl reads that are derived, not a parameter or a
// target: whether refine is on (and then the BVH's buffers, bound for the
// shader about to draw; other modules bind their storage at other points),
// the suns' slots and their camera-fitted cascades.
static void u_refine(void *self, st_shader *sh, GLint loc, const st_frame *f) {
    shadow_map *s = self;
    bool on = s->p[P_REFINE] != 0 && s->bvh_nodes;
    if (on) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ST_BVH_BINDING_NODES, s->bvh_nodes);
    if (on) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, ST_BVH_BINDING_TRIS, s->bvh_tris);
    glUniform1i(loc, on);
}

static void u_sun_slot(void *self, st_shader *sh, GLint loc, const st_frame *f) {
    glUniform1iv(loc, ST_MAX_LIGHTS, ((shadow_map *)self)->sun_slot);
}
// Every sun's cascades end at the same view depths (they depend on the camera).
static void u_cascade_far(void *self, st_shader *sh, GLint loc, const st_frame *f) {
    shadow_map *s = self;
    float far_z[SM_MAX_CASCADES] = {0};
    for (int c = 0; s->num_suns && c < s->suns[0].count; c++)
        far_z[c] = (float)s->suns[0].far_z[c];
    glUniform1fv(loc, SM_MAX_CASCADES, far_z);
}
static void u_cascade_rect(void *self, st_shader *sh, GLint loc, const st_frame *f) {
    shadow_map *s = self;
    float r[ST_MAX_LIGHTS * SM_MAX_CASCADES][4] = {{0}};
    for (int k = 0; k < s->num_suns; k++)
        for (int c = 0; c < s->suns[k].count; c++) {
            const sm_rect *q = &s->suns[k].fit[c];
            r[k * SM_MAX_CASCADES + c][0] = (float)q->cu,
                                    r[k * SM_MAX_CASCADES + c][1] = (float)q->cv;
            r[k * SM_MAX_CASCADES + c][2] = (float)q->half;
        }
    glUniform4fv(loc, ST_MAX_LIGHTS * SM_MAX_CASCADES, &r[0][0]);
}

static const st_uniform uniforms_table[] = {
    {"st_shadow_sun_slot", u_sun_slot},
    {"st_shadow_cascade_far", u_cascade_far},
    {"st_shadow_cascade_rect", u_cascade_rect},
    {"st_shadow_refine", u_refine},
};

static int uniforms(void *self, const st_uniform **out) {
    *out = uniforms_table;
    return (int)(sizeof uniforms_table / sizeof uniforms_table[0]);
}

// A new resolution or cascade count re-describes the targets (the world
// re-creates them at the next use).
static void param_changed(void *self, int index) {
    st_err ignore = {0}; // only fails for a bad name, which create already caught
    if (index == P_RESOLUTION || index == P_CASCADE_RESOLUTION || index == P_CASCADES)
        declare_targets(self, &ignore);
}

ST_PLUGIN(.name = "shadow_map",
          .description = "shadow maps: distance cube maps for point and spot lights, cascades for "
                         "directional ones (slope-scaled bias, optional PCF); ambiguous surface "
                         "lookups settled by an exact ray against the scene's triangles",
          ST_PARAMS(params), ST_PROGRAMS(programs), ST_EXPORTS(exports), .provides = "shadow_map",
          .regular_include = "shadow_map/visibility.glsl", .create = create, .destroy = destroy,
          .num_passes = num_passes, .pass_info = pass_info, .uniforms = uniforms, .needed = needed,
          .on_pass = on_pass, .param_changed = param_changed,
          /* a spot's cone lies inside its distance cube */ .light_types = ST_LIGHT_BITS_ALL)
