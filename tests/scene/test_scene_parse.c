// Scene JSON v1: a valid scene parses to exact values, defaults apply, and
// every kind of bad input fails with ST_ERR_INPUT naming file and key path.
#include "st_test.h"
#include "st_physics.h"
#include "st_scene.h"

#define FILE_NAME "scenes/x.json"

static bool parse(const char *json, st_scene *s, st_err *e) {
    memset(e, 0, sizeof *e);
    return st_scene_parse(json, strlen(json), FILE_NAME, s, e);
}

static const char *valid =
    "{\n"
    "  \"image\": {\"width\": 640, \"height\": 360},\n"
    "  \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0],\n"
    "             \"fov_y\": 40, \"near\": 0.05, \"far\": 100},\n"
    "  \"lights\": [{\"type\": \"point\", \"position\": [0, 1.9, 0], \"intensity\": [3, 2, 1]}],\n"
    "  \"geometry\": [\n"
    "    {\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}, \"albedo\": [0.5, 0.25, 0.125],\n"
    "     \"inward\": true},\n"
    "    {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}},\n"
    "    {\"quad\": {\"corner\": [-0.2, 1.99, -0.2], \"u\": [0.4, 0, 0], \"v\": [0, 0, 0.4]},\n"
    "     \"emission\": [1, 2, 3], \"double_sided\": true},\n"
    "    {\"sphere\": {\"center\": [0, 0.5, 0], \"radius\": 0.25, \"rings\": 8, \"segments\": "
    "12}}\n"
    "  ],\n"
    "  \"medium\": {\"sigma_s\": [0.05, 0.06, 0.07], \"sigma_a\": [0.005, 0.006, 0.007],\n"
    "             \"phase\": {\"hg\": 0.5}},\n"
    "  \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 1024, \"pcf\": "
    "true}},\n"
    "              {\"name\": \"toth\", \"params\": {\"samples\": 64, \"integrator\": "
    "\"thesis\"}},\n"
    "              {\"name\": \"mitchell\"}]\n"
    "}\n";

static const st_param_setting *param(st_scene *s, const char *module, const char *name) {
    st_module_setting *m = st_scene_module(s, module);
    for (int i = 0; m && i < m->num_params; i++)
        if (!strcmp(m->params[i].name, name)) return &m->params[i];
    return NULL;
}

static void test_valid(void) {
    st_scene s;
    st_err e;
    CHECK(parse(valid, &s, &e), "valid scene: %s", e.msg);
    CHECK(!strcmp(s.path, FILE_NAME) && !strcmp(s.dir, "scenes"), "path %s dir %s", s.path, s.dir);
    CHECK(s.width == 640 && s.height == 360, "image %dx%d", s.width, s.height);
    CHECK(s.camera.position[0] == 0 && s.camera.position[1] == 1 && s.camera.position[2] == 3.4f,
          "camera position");
    CHECK(s.camera.target[1] == 1 && s.camera.up[1] == 1, "camera target/up");
    CHECK(s.camera.fov_y == 40 && s.camera.near_z == 0.05f && s.camera.far_z == 100, "camera lens");
    CHECK(s.num_lights == 1, "lights %d", s.num_lights);
    CHECK(s.lights[0].position[1] == 1.9f && s.lights[0].intensity[0] == 3 &&
              s.lights[0].intensity[1] == 2 && s.lights[0].intensity[2] == 1,
          "light values");
    CHECK(s.num_meshes == 4, "meshes %d", s.num_meshes);
    if (s.num_meshes == 4) {
        CHECK(s.meshes[0].num_triangles == 12 && s.meshes[0].num_vertices == 24, "box counts");
        CHECK(s.meshes[0].albedo[0] == 0.5f && s.meshes[0].albedo[1] == 0.25f &&
                  s.meshes[0].albedo[2] == 0.125f,
              "box albedo");
        // Inward box: the floor face (y = 0) points up.
        bool floor_up = false;
        for (uint32_t v = 0; v < 24; v++)
            if (s.meshes[0].positions[3 * v + 1] == 0 && s.meshes[0].normals[3 * v + 1] == 1)
                floor_up = true;
        CHECK(floor_up, "inward box floor normal is +y");
        CHECK(s.meshes[1].num_triangles == 2 && s.meshes[1].albedo[0] == 0.75f &&
                  s.meshes[1].emission[0] == 0 && !s.meshes[1].double_sided,
              "default material");
        // u x v = (0,2,0) x (0,0,2) = (4,0,0): +x.
        CHECK(s.meshes[1].normals[0] == 1 && s.meshes[1].normals[1] == 0, "quad normal +x");
        CHECK(s.meshes[2].emission[0] == 1 && s.meshes[2].emission[1] == 2 &&
                  s.meshes[2].emission[2] == 3 && s.meshes[2].double_sided,
              "emitter material");
        CHECK(s.meshes[3].num_triangles == 2 * 12 * 7, "sphere triangles %u",
              s.meshes[3].num_triangles);
        CHECK(s.meshes[3].uv1 == NULL && s.meshes[0].uv1 == NULL, "no uv1 on procedural shapes");
    }
    CHECK(st_scene_triangle_count(&s) == 12 + 2 + 2 + 168, "triangle count %llu",
          (unsigned long long)st_scene_triangle_count(&s));
    CHECK(s.medium.present && s.medium.sigma_s[1] == 0.06f && s.medium.sigma_a[2] == 0.007f,
          "medium coefficients");
    CHECK(s.medium.phase == ST_PHASE_HG && s.medium.g == 0.5f, "phase hg %g", s.medium.g);
    CHECK(s.num_modules == 3, "modules %d", s.num_modules);
    const st_param_setting *p = param(&s, "shadow_map", "resolution");
    CHECK(p && p->value.type == ST_VALUE_NUMBER && p->value.number == 1024, "resolution");
    p = param(&s, "shadow_map", "pcf");
    CHECK(p && p->value.type == ST_VALUE_BOOL && p->value.number == 1, "pcf");
    p = param(&s, "toth", "integrator");
    CHECK(p && p->value.type == ST_VALUE_STRING && !strcmp(p->value.str, "thesis"), "integrator");
    CHECK(st_scene_module(&s, "mitchell") && st_scene_module(&s, "mitchell")->num_params == 0,
          "module without params");
    CHECK(st_scene_module(&s, "sousa") == NULL, "absent module");

    // --set: replace, add, types.
    CHECK(st_scene_set(&s, "shadow_map.resolution=2048", &e), "%s", e.msg);
    p = param(&s, "shadow_map", "resolution");
    CHECK(p && p->value.number == 2048 && st_scene_module(&s, "shadow_map")->num_params == 2,
          "--set replaces");
    CHECK(st_scene_set(&s, "toth.jitter=false", &e), "%s", e.msg);
    p = param(&s, "toth", "jitter");
    CHECK(p && p->value.type == ST_VALUE_BOOL && p->value.number == 0, "--set adds a bool");
    CHECK(st_scene_set(&s, "mitchell.decay=-0.5e-1", &e), "%s", e.msg);
    p = param(&s, "mitchell", "decay");
    CHECK(p && p->value.type == ST_VALUE_NUMBER && p->value.number == -0.05, "--set number");
    CHECK(st_scene_set(&s, "toth.integrator=hillaire", &e), "%s", e.msg);
    p = param(&s, "toth", "integrator");
    CHECK(p && p->value.type == ST_VALUE_STRING && !strcmp(p->value.str, "hillaire"),
          "--set string");

    static const struct {
        const char *set, *needle;
    } bad_sets[] = {
        {"sousa.taps=8", "'sousa'"},
        {"shadow_map=1", "MODULE.PARAM=VALUE"},
        {"shadow_map.resolution", "MODULE.PARAM=VALUE"},
        {"shadow_map.=1", "shadow_map.=1"},
        {"shadow_map.bias=inf", "shadow_map.bias"},
        {"shadow_map.bias=", "shadow_map.bias"},
        {"shadow_map.bias=nan", "not a finite number"},
        {"shadow map.bias=1", "identifiers"},
    };
    for (size_t i = 0; i < sizeof bad_sets / sizeof bad_sets[0]; i++) {
        memset(&e, 0, sizeof e);
        CHECK(!st_scene_set(&s, bad_sets[i].set, &e) && e.kind == ST_ERR_INPUT, "--set %s accepted",
              bad_sets[i].set);
        CHECK(strstr(e.msg, bad_sets[i].needle) != NULL, "--set %s: message '%s' lacks '%s'",
              bad_sets[i].set, e.msg, bad_sets[i].needle);
    }
    st_scene_free(&s);
    CHECK(s.meshes == NULL && s.num_meshes == 0 && s.modules == NULL, "free zeroes the scene");
}

static void test_defaults(void) {
    st_scene s;
    st_err e;
    const char *json = "{\"camera\": {\"position\": [0,0,5], \"target\": [0,0,0], \"fov_y\": 30},"
                       " \"medium\": {\"sigma_s\": [1,1,1], \"phase\": {\"hg\": -1}}}";
    CHECK(parse(json, &s, &e), "minimal scene: %s", e.msg);
    CHECK(s.width == 512 && s.height == 512, "default image %dx%d", s.width, s.height);
    CHECK(s.camera.up[0] == 0 && s.camera.up[1] == 1 && s.camera.up[2] == 0, "default up");
    CHECK(s.camera.near_z == 0.05f && s.camera.far_z == 100, "default near/far");
    CHECK(s.num_lights == 0 && s.num_meshes == 0 && s.num_modules == 0, "empty lists");
    CHECK(s.medium.phase == ST_PHASE_HG && s.medium.g == -0.999f, "g clamped to -0.999: %g",
          s.medium.g);
    CHECK(s.medium.sigma_a[0] == 0, "default sigma_a");
    CHECK(!s.has_background && s.background[0] == 0 && s.background[2] == 0, "no background");
    st_scene_free(&s);
    // The sun's disc: 0.53 degrees unless given; a background radiance.
    CHECK(parse("{\"camera\": {\"position\": [0,0,5], \"target\": [0,0,0], \"fov_y\": 30},"
                " \"background\": [0.2, 0.3, 0.6], \"lights\": ["
                "{\"type\": \"directional\", \"direction\": [0,-1,0], \"irradiance\": [1,1,1]},"
                "{\"type\": \"directional\", \"direction\": [0,-1,0], \"irradiance\": [1,1,1],"
                " \"angular_diameter\": 2}]}",
                &s, &e),
          "sun and background: %s", e.msg);
    CHECK(s.has_background && s.background[0] == 0.2f && s.background[1] == 0.3f &&
              s.background[2] == 0.6f,
          "background (%g, %g, %g)", s.background[0], s.background[1], s.background[2]);
    CHECK(s.num_lights == 2 &&
              fabs(st_light_angular_diameter(&s.lights[0]) - 0.53 * ST_PI / 180) < 1e-7,
          "default angular diameter %g rad", st_light_angular_diameter(&s.lights[0]));
    CHECK(s.num_lights == 2 && fabs(s.lights[1].angular_diameter - 2 * ST_PI / 180) < 1e-7,
          "angular diameter 2 degrees: %g rad", s.lights[1].angular_diameter);
    st_scene_free(&s);
    CHECK(parse("{\"camera\": {\"position\": [0,0,5], \"target\": [0,0,0], \"fov_y\": 30},"
                " \"medium\": {\"sigma_s\": [1,1,1], \"phase\": \"rayleigh\"}}",
                &s, &e) &&
              s.medium.phase == ST_PHASE_RAYLEIGH,
          "rayleigh: %s", e.msg);
    st_scene_free(&s);
    CHECK(!parse("{}", &s, &e) && strstr(e.msg, FILE_NAME ": camera: required"), "no camera: %s",
          e.msg);
}

#define CAM "\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"fov_y\": 40}"
#define QUAD(u) "\"geometry\": [{\"quad\": {\"corner\": [0,0,0], \"u\": " u ", \"v\": [0,0,1]}}]"

static const struct bad {
    const char *json, *needle;
} bad[] = {
    // unknown keys, top level and nested
    {"{" CAM ", \"lighs\": []}", FILE_NAME ": lighs: unknown key"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"fovy\": 40}}",
     "camera.fovy: unknown key"},
    {"{" CAM ", \"geometry\": [{\"quad\": {\"corner\": [0,0,0], \"u\": [1,0,0], \"v\": [0,0,1], "
     "\"w\": 1}}]}",
     "geometry[0].quad.w: unknown key"},
    {"{" CAM ", \"modules\": [{\"name\": \"toth\", \"parms\": {}}]}",
     "modules[0].parms: unknown key"},
    {"{" CAM ", \"medium\": {\"sigma_s\": [1,1,1], \"phase\": {\"g\": 0.5}}}",
     "medium.phase.g: unknown key"},
    // wrong types
    {"{" CAM ", \"image\": {\"width\": \"512\"}}", "image.width: expected a number"},
    {"{" CAM ", \"image\": {\"width\": 512.5}}", "image.width: expected an integer"},
    {"{" CAM ", \"geometry\": {}}", "geometry: expected an array"},
    {"{" CAM ", \"geometry\": [{\"gltf\": 3}]}", "geometry[0].gltf: expected a string"},
    {"{" CAM ", \"geometry\": [{\"box\": {\"min\": [0,0,0], \"max\": [1,1,1]}, \"inward\": 1}]}",
     "geometry[0].inward: expected true or false"},
    {"{" CAM ", \"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"intensity\": 3}]}",
     "lights[0].intensity: expected an array of 3 numbers"},
    {"{" CAM ", \"modules\": [{\"name\": \"toth\", \"params\": {\"n\": [1]}}]}",
     "modules[0].params.n: expected a number, true/false or a string"},
    {"{" CAM ", \"medium\": {\"sigma_s\": [1,1,1], \"phase\": \"mie\"}}", "medium.phase: expected"},
    {"[1, 2]", FILE_NAME ": expected a JSON object"},
    // NaN / Inf / float overflow
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"fov_y\": 1e999}}",
     "camera.fov_y: number is not finite"},
    {"{\"camera\": {\"position\": [0,1,-1e999], \"target\": [0,1,0], \"fov_y\": 40}}",
     "camera.position: element 2 is not finite"},
    {"{\"camera\": {\"position\": [0,1,1e39], \"target\": [0,1,0], \"fov_y\": 40}}",
     "camera.position: 1e+39 is out of range"},
    {"{\"camera\": {\"position\": [0,1,NaN], \"target\": [0,1,0], \"fov_y\": 40}}",
     FILE_NAME ": line 1, column"},
    {"{" CAM ", \"modules\": [{\"name\": \"toth\", \"params\": {\"n\": -1e400}}]}",
     "modules[0].params.n: number is not finite"},
    // wrong array lengths
    {"{" CAM ", " QUAD("[1,0]") "}", "geometry[0].quad.u: expected an array of 3 numbers"},
    {"{" CAM ", " QUAD("[1,0,0,0]") "}", "geometry[0].quad.u: expected an array of 3 numbers"},
    {"{" CAM ", " QUAD("[1,\"0\",0]") "}", "geometry[0].quad.u: expected an array of 3 numbers"},
    // out of range
    {"{" CAM ", \"image\": {\"height\": 0}}", "image.height: 0 is out of range"},
    {"{" CAM ", \"image\": {\"width\": 16385}}", "image.width: 16385 is out of range"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"fov_y\": 180}}",
     "camera.fov_y: 180 is out of range"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"fov_y\": 40, \"near\": 0}}",
     "camera.near: expected > 0"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"fov_y\": 40, \"near\": 1, "
     "\"far\": 1}}",
     "camera.far: 1 is not greater"},
    {"{" CAM
     ", \"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"intensity\": [1,-1,1]}]}",
     "lights[0].intensity: element 1 is -1"},
    {"{" CAM ", \"lights\": [{\"type\": \"area\", \"position\": [0,1,0], \"intensity\": [1,1,1]}]}",
     "lights[0].type: 'area': expected \"point\", \"directional\" or \"spot\""},
    {"{" CAM ", \"lights\": [{\"type\": \"spot\", \"position\": [0,1,0], \"intensity\": [1,1,1]}]}",
     "lights[0].direction: required key missing"},
    {"{" CAM
     ", \"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"irradiance\": [1,1,1]}]}",
     "lights[0].irradiance: unknown key (expected one of: type, position, intensity)"},
    {"{" CAM ", \"lights\": [{\"type\": \"directional\", \"direction\": [0,0,0], \"irradiance\": "
     "[1,1,1]}]}",
     "lights[0].direction: must be a non-zero vector"},
    {"{" CAM ", \"lights\": [{\"type\": \"directional\", \"direction\": [0,-1,0], \"irradiance\": "
     "[1,-1,1]}]}",
     "lights[0].irradiance: element 1 is -1"},
    {"{" CAM ", \"lights\": [{\"type\": \"directional\", \"direction\": [0,-1,0], \"irradiance\": "
     "[1,1,1], \"angular_diameter\": 0}]}",
     "lights[0].angular_diameter: 0 is out of range (0, 30] degrees"},
    {"{" CAM ", \"lights\": [{\"type\": \"directional\", \"direction\": [0,-1,0], \"irradiance\": "
     "[1,1,1], \"angular_diameter\": 31}]}",
     "lights[0].angular_diameter: 31 is out of range (0, 30] degrees"},
    {"{" CAM ", \"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"intensity\": [1,1,1], "
     "\"angular_diameter\": 1}]}",
     "lights[0].angular_diameter: unknown key"},
    {"{" CAM ", \"background\": [0.2, -0.3, 0.6]}", "background: element 1 is -0.3"},
    {"{" CAM ", \"background\": [0.2, 0.3]}", "background: expected an array of 3 numbers"},
    {"{" CAM ", \"background\": 1}", "background: expected an array of 3 numbers"},
    {"{" CAM ", \"background\": [0, 0, 1e39]}", "background"},
    {"{" CAM ", \"lights\": [{\"type\": \"spot\", \"position\": [0,1,0], \"direction\": [0,-1,0], "
     "\"intensity\": [1,1,1], \"outer_angle\": 91}]}",
     "lights[0].outer_angle: 91 is out of range (0, 90]"},
    {"{" CAM ", \"lights\": [{\"type\": \"spot\", \"position\": [0,1,0], \"direction\": [0,-1,0], "
     "\"intensity\": [1,1,1], \"inner_angle\": 30, \"outer_angle\": 30}]}",
     "lights[0].inner_angle: 30 must be in [0, outer_angle = 30)"},
    {"{" CAM ", \"lights\": [{\"type\": \"spot\", \"position\": [0,1,0], \"direction\": [0,-1,0], "
     "\"intensity\": [1,1,1], \"cone\": 30}]}",
     "lights[0].cone: unknown key"},
    {"{" CAM ", \"geometry\": [{\"box\": {\"min\": [0,0,0], \"max\": [1,1,1]}, \"albedo\": "
     "[0.5,1.5,0.5]}]}",
     "geometry[0].albedo: element 1 is 1.5"},
    {"{" CAM
     ", \"geometry\": [{\"box\": {\"min\": [0,0,0], \"max\": [1,1,1]}, \"emission\": [0,0,-0.1]}]}",
     "geometry[0].emission: element 2"},
    {"{" CAM ", \"medium\": {\"sigma_s\": [1,1,1], \"sigma_a\": [0,-1,0]}}",
     "medium.sigma_a: element 1"},
    {"{" CAM ", \"medium\": {\"sigma_s\": [1,1,1], \"phase\": {\"hg\": 1.5}}}",
     "medium.phase.hg: 1.5 is out of range"},
    {"{" CAM ", \"geometry\": [{\"sphere\": {\"center\": [0,0,0], \"radius\": 0}}]}",
     "geometry[0].sphere.radius: expected > 0"},
    {"{" CAM ", \"geometry\": [{\"sphere\": {\"center\": [0,0,0], \"radius\": 1, \"rings\": 1}}]}",
     "geometry[0].sphere.rings: 1 is out of range"},
    {"{" CAM ", \"geometry\": [{\"sphere\": {\"center\": [0,0,0], \"radius\": 1, \"rings\": 16384, "
     "\"segments\": 16384}}]}",
     "geometry[0].sphere: the scene would have"},
    // degenerate geometry and camera
    {"{" CAM ", " QUAD("[0,0,0]") "}", "geometry[0].quad.u: zero-length edge"},
    {"{" CAM ", " QUAD("[0,0,2]") "}", "geometry[0].quad: u and v are parallel"},
    {"{" CAM ", \"geometry\": [{\"box\": {\"min\": [0,0,0], \"max\": [1,0,1]}}]}",
     "geometry[0].box: zero or negative volume"},
    {"{" CAM
     ", \"geometry\": [{\"box\": {\"min\": [0,0,0], \"max\": [3e38,1,1]}, \"inward\": false}, "
     "{\"box\": {\"min\": [-3e38,0,0], \"max\": [3e38,1,1]}}]}",
     "geometry[1].box: coordinates overflow"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,3], \"fov_y\": 40}}",
     "camera.target: equals position"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,2,3], \"fov_y\": 40}}",
     "camera.up: parallel"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0], \"up\": [0,0,0], \"fov_y\": 40}}",
     "camera.up: zero vector"},
    {"{\"camera\": {\"position\": [0,1,3], \"target\": [0,1,0]}}",
     "camera.fov_y: required key missing"},
    // geometry entry shape rules
    {"{" CAM ", \"geometry\": [{\"albedo\": [1,1,1]}]}", "geometry[0]: expected one of the keys"},
    {"{" CAM
     ", \"geometry\": [{\"gltf\": \"a.glb\", \"box\": {\"min\": [0,0,0], \"max\": [1,1,1]}}]}",
     "geometry[0]: has both"},
    {"{" CAM ", \"geometry\": [{\"quad\": {\"corner\": [0,0,0], \"u\": [1,0,0], \"v\": [0,0,1]}, "
     "\"inward\": true}]}",
     "geometry[0].inward: only valid for a box"},
    // missing assets (relative to the scene folder)
    {"{" CAM ", \"geometry\": [{\"gltf\": \"assets/missing.glb\"}]}",
     "geometry[0].gltf: scenes/assets/missing.glb: cannot open"},
    {"{" CAM ", \"geometry\": [{\"gltf\": \"/\"}]}", "geometry[0].gltf: /: not a regular file"},
    {"{" CAM ", \"geometry\": [{\"gltf\": \"\"}]}", "geometry[0].gltf: empty string"},
    // modules
    {"{" CAM ", \"modules\": [{\"name\": \"toth\"}, {\"name\": \"toth\"}]}",
     "modules[1].name: module 'toth' is listed twice"},
    {"{" CAM ", \"modules\": [{\"name\": \"sh adow\"}]}",
     "modules[0].name: 'sh adow' is not an identifier"},
    {"{" CAM ", \"modules\": [{\"name\": \"\"}]}", "modules[0].name: empty string"},
    {"{" CAM ", \"modules\": [{\"name\": "
     "\"m123456789012345678901234567890123456789012345678901234567890123\"}]}",
     "modules[0].name: string longer than 63"},
    {"{" CAM ", \"modules\": [{\"params\": {}}]}", "modules[0].name: required key missing"},
    {"{" CAM ", \"modules\": [{\"name\": \"toth\", \"params\": {\"a.b\": 1}}]}",
     "modules[0].params.a.b: parameter names"},
    {"{" CAM ", \"modules\": [{\"name\": \"toth\", \"params\": {\"n\": 1, \"n\": 2}}]}",
     "modules[0].params.n: key given twice"},
    // syntax
    {"{" CAM ", \"image\": {\"width\": 5}} trailing", FILE_NAME ": line 1, column"},
    {"{" CAM ",\n \"image\": {\"width\": 5,}}", FILE_NAME ": line 2, column"},
    {"{\"camera\": {}, \"camera\": {}}", "camera: key given twice"},
    {"", FILE_NAME ": line 1, column 1: invalid JSON"},
};

static void test_bad(void) {
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        st_scene s;
        st_err e;
        bool ok = parse(bad[i].json, &s, &e);
        if (getenv("ST_TEST_VERBOSE")) fprintf(stderr, "%s\n", e.msg);
        CHECK(!ok && e.kind == ST_ERR_INPUT, "case %zu accepted: %s", i, bad[i].json);
        CHECK(strstr(e.msg, bad[i].needle) != NULL, "case %zu: message '%s' lacks '%s'", i, e.msg,
              bad[i].needle);
        CHECK(!strncmp(e.msg, FILE_NAME ": ", strlen(FILE_NAME) + 2),
              "case %zu: no file prefix: %s", i, e.msg);
        CHECK(s.meshes == NULL && s.lights == NULL && s.modules == NULL,
              "case %zu left data behind", i);
        if (ok) st_scene_free(&s);
    }
}

static void test_load(void) {
    char path[1024];
    snprintf(path, sizeof path, "%s/scene.json", ST_TEST_SCRATCH);
    FILE *f = fopen(path, "w");
    fputs(valid, f);
    fclose(f);
    st_scene s;
    st_err e = {0};
    CHECK(st_scene_load(path, &s, &e), "load: %s", e.msg);
    CHECK(!strcmp(s.dir, ST_TEST_SCRATCH), "dir %s", s.dir);
    st_scene_free(&s);
    CHECK(!st_scene_load(ST_TEST_SCRATCH "/none.json", &s, &e) && e.kind == ST_ERR_INPUT &&
              strstr(e.msg, "none.json"),
          "missing scene file: %s", e.msg);
}

int main(void) {
    test_valid();
    test_defaults();
    test_bad();
    test_load();
    return st_test_summary("test_scene_parse");
}
