// strahl info: what a scene holds before anything is rendered: its modules
// with what each requires and who provides it, lights, triangles, bounds,
// the camera (or the one --auto-camera would use), the medium, and the
// memory that is known without a GPU.
#include "cmd_common.h"
#include "st_cmd.h"
#include "st_list.h"
#include "st_module.h"
#include <stdio.h>
#include <string.h>

static const char help_text[] =
    "usage: strahl info SCENE.json [options]\n"
    "Describes a scene without rendering it: modules (after --enable/--disable) with what\n"
    "each requires and which module provides it, lights, meshes and triangles, world\n"
    "bounds, the camera (for a scene without one, the camera --auto-camera would frame),\n"
    "the medium, and the memory known without a GPU (the scene's arrays; a module's GPU\n"
    "memory is in `strahl render SCENE -o OUT.exr --stats`).\n"
    "  --set MODULE.PARAM=VALUE  change a module parameter, checked as render does\n"
    "                            (repeatable; default: the scene's)\n"
    "  --size WxH                image size (default: the scene's)\n"
    "  --allow-outside-assets    let glTF buffer/image URIs leave the glTF file's folder\n"
    "                            (default: refused)\n" ST_CMD_SCENE_HELP
    "  -h, --help                this text\n"
    "example:\n"
    "  strahl info scenes/godrays_window.json --disable toth --enable froxel\n";

#define MAX_SETS 64
typedef struct info_args {
    const char *scene_path;
    char *sets[MAX_SETS];
    int num_sets, width, height;
} info_args;

static bool info_value(void *ctx, const char *a, const char *v, bool *known, st_err *err) {
    info_args *o = ctx;
    *known = true;
    if (!strcmp(a, "--set")) {
        if (o->num_sets == MAX_SETS) return st_fail(err, ST_ERR_INPUT, "too many --set");
        o->sets[o->num_sets++] = (char *)v;
    } else if (!strcmp(a, "--size")) {
        if (!st_parse_size(v, &o->width, &o->height))
            return st_fail(err, ST_ERR_INPUT, "--size %s: expected WxH, 1..16384 each", v);
    } else {
        *known = false;
    }
    return true;
}

static bool info_flag(void *ctx, const char *a) {
    (void)ctx, (void)a;
    return false;
}

// Which module of the scene provides capability cap ("" if none).
static void provider(const st_scene *s, const char *cap, char out[ST_NAME_MAX]) {
    out[0] = 0;
    for (int i = 0; i < s->num_modules && !out[0]; i++) {
        st_err ignore = {0};
        st_plugin_lib *lib = st_plugin_open(s->modules[i].name, &ignore);
        if (!lib) continue;
        if (st_list_has(st_plugin_desc(lib)->provides, cap))
            snprintf(out, ST_NAME_MAX, "%s", s->modules[i].name);
        st_plugin_close(lib);
    }
}

static void print_modules(const st_scene *s) {
    const char *inscatter[2] = {0};
    int n_in = 0;
    printf("modules: %d%s\n", s->num_modules, s->inscatter_overlay ? " (inscatter_overlay)" : "");
    for (int i = 0; i < s->num_modules; i++) {
        const st_module_setting *m = &s->modules[i];
        st_err err = {0};
        st_plugin_lib *lib = st_plugin_open(m->name, &err);
        printf("  %s", m->name);
        for (int k = 0; k < m->num_params; k++) {
            const st_value *v = &m->params[k].value;
            printf("%s%s=", k ? ", " : " (", m->params[k].name);
            if (v->type == ST_VALUE_STRING)
                printf("%s", v->str);
            else if (v->type == ST_VALUE_BOOL)
                printf("%s", v->number ? "true" : "false");
            else
                printf("%.9g", v->number);
        }
        printf("%s\n", m->num_params ? ")" : "");
        if (!lib) {
            printf("    not installed: %s\n", err.msg);
            continue;
        }
        const st_plugin *p = st_plugin_desc(lib);
        char cap[ST_NAME_MAX], who[ST_NAME_MAX];
        bool optional;
        for (const char *r = p->requires; (r = st_list_next(r, cap, &optional));) {
            if (!cap[0]) continue;
            provider(s, cap, who);
            printf("    requires %s%s: %s\n", cap, optional ? " (optional)" : "",
                   who[0] ? who : "no module provides it");
        }
        if (p->provides && p->provides[0]) printf("    provides %s\n", p->provides);
        if (st_list_has(p->provides, ST_CAP_INSCATTER)) inscatter[n_in++ % 2] = m->name;
        st_plugin_close(lib);
    }
    if (n_in > 1 && !s->inscatter_overlay)
        printf("  note: %s and %s both compute the medium's in-scattering: render refuses them in "
               "one image without --overlay\n",
               inscatter[0], inscatter[1]);
}

static void print_lights(const st_scene *s) {
    printf("lights: %d\n", s->num_lights);
    for (int i = 0; i < s->num_lights; i++) {
        const st_light_desc *l = &s->lights[i];
        const float *v = l->type == ST_LIGHT_DIRECTIONAL ? l->direction : l->position;
        printf("  [%d] %s %s (%g, %g, %g), %s (%g, %g, %g)", i, st_light_type_name(l->type),
               l->type == ST_LIGHT_DIRECTIONAL ? "direction" : "at", v[0], v[1], v[2],
               l->type == ST_LIGHT_DIRECTIONAL ? "irradiance W/m^2" : "intensity W/sr",
               l->intensity[0], l->intensity[1], l->intensity[2]);
        if (l->type == ST_LIGHT_SPOT)
            printf(", direction (%g, %g, %g), cone %g..%g deg", l->direction[0], l->direction[1],
                   l->direction[2], l->inner_angle * 57.2957795, l->outer_angle * 57.2957795);
        printf("\n");
    }
}

// Geometry, bounds and the memory the scene's arrays take.
static void print_geometry(const st_scene *s) {
    uint64_t verts = 0, tris = st_scene_triangle_count(s);
    for (int i = 0; i < s->num_meshes; i++)
        verts += s->meshes[i].num_vertices;
    printf("geometry: %d mesh(es), %llu triangles, %llu vertices\n", s->num_meshes,
           (unsigned long long)tris, (unsigned long long)verts);
    double lo[3], hi[3];
    if (st_scene_bounds(s, lo, hi))
        printf("bounds: (%.4g, %.4g, %.4g) .. (%.4g, %.4g, %.4g), size %.4g x %.4g x %.4g m\n",
               lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], hi[0] - lo[0], hi[1] - lo[1],
               hi[2] - lo[2]);
    else
        printf("bounds: none (no geometry)\n");
    // Positions and normals (3 floats each), indices (3 per triangle).
    double mesh_mib = (verts * 24.0 + tris * 12.0) / 1048576.0;
    printf("memory: meshes %.3f MiB (positions, normals, indices)", mesh_mib);
    const st_density_grid *g = s->density.grid;
    if (g)
        printf(", density grid %dx%dx%d voxels %.3f MiB", g->n[0], g->n[1], g->n[2],
               (double)g->n[0] * g->n[1] * g->n[2] * 4.0 / 1048576.0);
    printf("; GPU memory per module: strahl render SCENE -o OUT.exr --stats\n");
}

static void print_camera(const st_scene *s) {
    const st_camera_desc *c = &s->camera;
    printf("camera:%s position (%g, %g, %g), target (%g, %g, %g), up (%g, %g, %g), fov_y %g "
           "deg, near %g, far %g\n",
           s->camera_auto ? " none in the scene; --auto-camera frames the bounds:" : "",
           c->position[0], c->position[1], c->position[2], c->target[0], c->target[1], c->target[2],
           c->up[0], c->up[1], c->up[2], c->fov_y, c->near_z, c->far_z);
    printf("image: %dx%d, filter %s\n", s->width, s->height, st_filter_name(s->filter));
}

static void print_medium(const st_scene *s) {
    const st_medium_desc *m = &s->medium;
    static const char *const phases[] = {"isotropic", "rayleigh", "hg"};
    static const char *const dens[] = {"uniform", "height", "grid (OpenVDB)"};
    if (!m->present) {
        printf("medium: none\n");
    } else {
        printf("medium: sigma_s (%g, %g, %g) 1/m, sigma_a (%g, %g, %g) 1/m, phase %s",
               m->sigma_s[0], m->sigma_s[1], m->sigma_s[2], m->sigma_a[0], m->sigma_a[1],
               m->sigma_a[2], phases[m->phase]);
        if (m->phase == ST_PHASE_HG) printf(" g %g", m->g);
        printf(", density %s", dens[s->density.kind]);
        if (s->density.kind == ST_DENSITY_HEIGHT)
            printf(" (base %g m, falloff %g 1/m)", s->density.base, s->density.falloff);
        printf("\n");
    }
    if (s->has_background)
        printf("background: (%g, %g, %g) W/(m^2 sr)\n", s->background[0], s->background[1],
               s->background[2]);
}

int st_cmd_info(int argc, char **argv) {
    static const st_argv_spec spec = {help_text, "", info_value, info_flag};
    info_args o = {0};
    st_err err = {0};
    bool help;
    if (!st_cmd_walk_args(&spec, &o, argc, argv, &o.scene_path, &help, &err))
        return st_report("info", &err);
    if (help) return ST_EXIT_OK;
    if (!o.scene_path)
        return fprintf(stderr, "strahl info: usage: strahl info SCENE.json (see --help)\n"), 2;
    // The camera a scene without one would get is shown, not refused.
    st_cmd_scene_option("--auto-camera");
    st_scene s = {0};
    if (!st_load_scene_with(o.scene_path, o.sets, o.num_sets, o.width, o.height, &s, &err))
        return st_report("info", &err);
    printf("scene: %s\n", s.path);
    print_camera(&s);
    print_modules(&s);
    print_lights(&s);
    print_geometry(&s);
    print_medium(&s);
    st_scene_free(&s);
    return ST_EXIT_OK;
}
