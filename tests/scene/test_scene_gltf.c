// glTF loading: a .glb written here (JSON + BIN chunk) with a node hierarchy,
// material, TEXCOORD_1, perspective camera and a KHR_lights_punctual point
// light loads with the right transforms and units; the scene JSON overrides
// it; truncated and corrupted files fail cleanly.
#include "st_test.h"
#include "st_scene.h"
#include <stdint.h>

// Unit quad in the xy plane: 4 positions, 4 normals (+z), 4 uv1, 6 u16 indices.
typedef struct bin {
    float pos[12], nrm[12], uv[8];
    uint16_t idx[6];
} bin;

static const bin quad_bin = {
    {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0},
    {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1},
    {0, 0, 1, 0, 1, 1, 0, 1},
    {0, 1, 2, 0, 2, 3},
};

// The JSON chunk; %s slots: primitive attributes, extra primitive keys,
// light type, node 3 children, accessor 0 count.
static const char *gltf_json =
    "{\"asset\": {\"version\": \"2.0\"},"
    " \"extensionsUsed\": [\"KHR_lights_punctual\"],"
    " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
    "   {\"type\": \"%s\", \"intensity\": 683, \"color\": [1, 0.5, 0.25]}]}},"
    " \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1, 2, 3]}],"
    " \"nodes\": ["
    "   {\"mesh\": 0, \"translation\": [1, 2, 3], \"scale\": [2, 2, 2]},"
    "   {\"camera\": 0, \"translation\": [0, 1, 5]},"
    "   {\"translation\": [0, 3, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
    "   {\"rotation\": [0, 0.70710678, 0, 0.70710678], \"children\": [%s]},"
    "   {\"mesh\": 0, \"translation\": [1, 0, 0]}],"
    " \"cameras\": [{\"type\": \"perspective\","
    "   \"perspective\": {\"yfov\": 0.5, \"znear\": 0.1, \"zfar\": 50, \"aspectRatio\": 1.5}}],"
    " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.2, 0.4, 0.6, 1]},"
    "   \"emissiveFactor\": [0.5, 0, 0], \"doubleSided\": true}],"
    " \"meshes\": [{\"name\": \"quad\", \"primitives\": [{\"attributes\": {%s}, \"material\": "
    "0%s}]}],"
    " \"buffers\": [{\"byteLength\": 140}],"
    " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 128},"
    "                  {\"buffer\": 0, \"byteOffset\": 128, \"byteLength\": 12}],"
    " \"accessors\": ["
    "   {\"bufferView\": 0, \"byteOffset\": 0, \"componentType\": 5126, \"count\": %s, \"type\": "
    "\"VEC3\"},"
    "   {\"bufferView\": 0, \"byteOffset\": 48, \"componentType\": 5126, \"count\": 4, \"type\": "
    "\"VEC3\"},"
    "   {\"bufferView\": 0, \"byteOffset\": 96, \"componentType\": 5126, \"count\": 4, \"type\": "
    "\"VEC2\"},"
    "   {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}";

typedef struct variant {
    const char *light, *children, *attributes, *prim_extra, *count;
} variant;

static const variant good = {"point", "4", "\"POSITION\": 0, \"NORMAL\": 1, \"TEXCOORD_1\": 2",
                             ", \"indices\": 3", "4"};

static void put32(unsigned char *p, uint32_t v) {
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

// Binary glTF: 12-byte header, JSON chunk padded with spaces, BIN chunk
// padded with zeros. Returns the size written to buf.
static size_t make_glb(unsigned char *buf, size_t cap, const variant *v) {
    char json[8192];
    snprintf(json, sizeof json, gltf_json, v->light, v->children, v->attributes, v->prim_extra,
             v->count);
    size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, bl = sizeof(bin),
           bp = (bl + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jp + 8 + bp;
    if (total > cap) return 0;
    memcpy(buf, "glTF", 4);
    put32(buf + 4, 2);
    put32(buf + 8, (uint32_t)total);
    put32(buf + 12, (uint32_t)jp);
    put32(buf + 16, 0x4E4F534A);
    memcpy(buf + 20, json, jl);
    memset(buf + 20 + jl, ' ', jp - jl);
    unsigned char *b = buf + 20 + jp;
    put32(b, (uint32_t)bp);
    put32(b + 4, 0x004E4942);
    memset(b + 8, 0, bp);
    memcpy(b + 8, &quad_bin, bl);
    return total;
}

static void write_file(const char *path, const unsigned char *data, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) return;
    fwrite(data, 1, n, f);
    fclose(f);
}

// World-space bounds of a mesh (positions through its model matrix).
static void bounds(const st_mesh *m, double lo[3], double hi[3]) {
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (uint32_t i = 0; i < m->num_vertices; i++) {
        const float *p = m->positions + 3 * i;
        for (int r = 0; r < 3; r++) {
            double w = m->model[12 + r];
            for (int c = 0; c < 3; c++)
                w += (double)m->model[4 * c + r] * p[c];
            lo[r] = fmin(lo[r], w), hi[r] = fmax(hi[r], w);
        }
    }
}

static unsigned char glb[16384];

static void test_load(const char *path) {
    st_scene s = {0};
    st_err e = {0};
    bool cam = false;
    CHECK(st_gltf_load(path, &s, &cam, &e), "load: %s", e.msg);
    CHECK(s.num_meshes == 2, "two instances of the mesh, got %d", s.num_meshes);
    if (s.num_meshes == 2) {
        const st_mesh *m = &s.meshes[0];
        double lo[3], hi[3];
        bounds(m, lo, hi);
        // translation (1,2,3), scale 2: x in [1,3], y in [2,4], z = 3.
        CHECK_REL(lo[0], 1, 0, 1e-6);
        CHECK_REL(hi[0], 3, 0, 1e-6);
        CHECK_REL(lo[1], 2, 0, 1e-6);
        CHECK_REL(hi[1], 4, 0, 1e-6);
        CHECK_REL(lo[2], 3, 0, 1e-6);
        CHECK_REL(hi[2], 3, 0, 1e-6);
        CHECK(m->num_triangles == 2 && m->num_vertices == 4, "counts %u %u", m->num_triangles,
              m->num_vertices);
        CHECK(m->albedo[0] == 0.2f && m->albedo[1] == 0.4f && m->albedo[2] == 0.6f,
              "albedo %g %g %g", m->albedo[0], m->albedo[1], m->albedo[2]);
        CHECK(m->emission[0] == 0.5f && m->emission[1] == 0, "emission");
        CHECK(m->double_sided, "doubleSided");
        CHECK(m->uv1 != NULL, "uv1 present");
        if (m->uv1) CHECK(m->uv1[2] == 1 && m->uv1[3] == 0 && m->uv1[5] == 1, "uv1 values");
        CHECK(m->normals[2] == 1, "normal +z");
        CHECK(!strcmp(m->name, "quad"), "name %s", m->name);
        // Child of a node rotated 90 deg about y, translated (1,0,0) locally:
        // (x + 1, y, 0) -> (0, y, -(x + 1)).
        bounds(&s.meshes[1], lo, hi);
        CHECK_REL(lo[0], 0, 0, 1e-6);
        CHECK_REL(hi[0], 0, 0, 1e-6);
        CHECK_REL(lo[1], 0, 0, 1e-6);
        CHECK_REL(hi[1], 1, 0, 1e-6);
        CHECK_REL(lo[2], -2, 0, 1e-6);
        CHECK_REL(hi[2], -1, 0, 1e-6);
    }
    CHECK(cam, "camera found");
    CHECK_REL(s.camera.fov_y, 0.5 * 180 / 3.14159265358979, 1e-6, 0);
    CHECK(s.camera.near_z == 0.1f && s.camera.far_z == 50, "near/far %g %g", s.camera.near_z,
          s.camera.far_z);
    CHECK(s.camera.position[0] == 0 && s.camera.position[1] == 1 && s.camera.position[2] == 5,
          "camera position");
    CHECK(s.camera.target[0] == 0 && s.camera.target[1] == 1 && s.camera.target[2] == 4,
          "camera looks down -z");
    CHECK(s.camera.up[1] == 1, "camera up +y");
    CHECK(s.num_lights == 1, "lights %d", s.num_lights);
    if (s.num_lights == 1) {
        // 683 cd / 683 lm/W = 1 W/sr, times the colour.
        CHECK_REL(s.lights[0].intensity[0], 1.0, 1e-6, 0);
        CHECK_REL(s.lights[0].intensity[1], 0.5, 1e-6, 0);
        CHECK_REL(s.lights[0].intensity[2], 0.25, 1e-6, 0);
        CHECK(s.lights[0].position[1] == 3, "light position");
    }
    // A second file adds meshes but does not replace the first camera.
    s.camera.fov_y = 77;
    CHECK(st_gltf_load(path, &s, &cam, &e) && s.num_meshes == 4 && s.camera.fov_y == 77,
          "second load");
    st_scene_free(&s);
}

static void test_scene_override(const char *dir) {
    char path[1024], json[1024];
    snprintf(path, sizeof path, "%s/with_gltf.json", dir);
    // No camera in JSON: the glTF one is used; fov_y alone overrides.
    const char *a = "{\"geometry\": [{\"gltf\": \"quad.glb\", \"albedo\": [0.1, 0.2, 0.3]}],"
                    " \"camera\": {\"fov_y\": 60}}";
    st_scene s;
    st_err e = {0};
    CHECK(st_scene_parse(a, strlen(a), path, &s, &e), "scene with glTF: %s", e.msg);
    CHECK(s.camera.fov_y == 60 && s.camera.position[2] == 5 && s.camera.far_z == 50,
          "camera merge");
    CHECK(s.num_meshes == 2 && s.meshes[1].albedo[0] == 0.1f && s.meshes[1].albedo[2] == 0.3f &&
              s.meshes[1].double_sided,
          "albedo override keeps doubleSided");
    CHECK(s.num_lights == 1 && s.lights[0].intensity[1] == 0.5f, "glTF light kept");
    st_scene_free(&s);
    // A "lights" key replaces the glTF lights; double_sided overrides.
    snprintf(json, sizeof json,
             "{\"geometry\": [{\"gltf\": \"quad.glb\", \"double_sided\": false}], \"lights\": [],"
             " \"camera\": {\"position\": [9, 9, 9], \"target\": [0, 0, 0]}}");
    CHECK(st_scene_parse(json, strlen(json), path, &s, &e), "%s", e.msg);
    CHECK(s.num_lights == 0 && !s.meshes[0].double_sided,
          "lights replaced, double_sided overridden");
    CHECK(s.camera.position[0] == 9 &&
              s.camera.fov_y == (float)(0.5 * 180 / 3.14159265358979323846),
          "position override, fov from glTF");
    st_scene_free(&s);
}

static void expect_fail(const variant *v, const char *needle) {
    size_t n = make_glb(glb, sizeof glb, v);
    st_scene s = {0};
    st_err e = {0};
    bool cam = false;
    bool ok = st_gltf_load_memory(glb, n, "bad.glb", ".", &s, &cam, &e);
    CHECK(!ok && e.kind == ST_ERR_INPUT, "corrupt variant accepted (%s)", needle);
    CHECK(strstr(e.msg, needle) && !strncmp(e.msg, "bad.glb: ", 9), "message '%s' lacks '%s'",
          e.msg, needle);
    CHECK(s.num_meshes == 0 && s.num_lights == 0 && !cam, "nothing left behind (%s)", needle);
    st_scene_free(&s);
}

// Directional and spot lights: direction = the node's -z, lux or candela /
// 683, glTF's cone half-angles in radians.
static void test_light_types(void) {
    const variant kinds[2] = {
        {"directional", good.children, good.attributes, good.prim_extra, good.count},
        {"spot\", \"spot\": {\"innerConeAngle\": 0.25, \"outerConeAngle\": 0.5}, \"name\": \"s",
         good.children, good.attributes, good.prim_extra, good.count}};
    for (int k = 0; k < 2; k++) {
        size_t n = make_glb(glb, sizeof glb, &kinds[k]);
        st_scene s = {0};
        st_err e = {0};
        bool cam = false;
        CHECK(st_gltf_load_memory(glb, n, "lights.glb", ".", &s, &cam, &e) && s.num_lights == 1,
              "%s: %s", k ? "spot" : "directional", e.msg);
        if (s.num_lights != 1) continue;
        const st_light_desc *l = &s.lights[0];
        CHECK(l->type == (k ? ST_LIGHT_SPOT : ST_LIGHT_DIRECTIONAL), "type %d", l->type);
        CHECK(l->direction[0] == 0 && l->direction[1] == 0 && l->direction[2] == -1,
              "direction -z: %g %g %g", l->direction[0], l->direction[1], l->direction[2]);
        CHECK_REL(l->intensity[0], 1.0, 1e-6, 0); // 683 lux -> 1 W/m^2, 683 cd -> 1 W/sr
        CHECK_REL(l->intensity[2], 0.25, 1e-6, 0);
        if (k)
            CHECK(l->inner_angle == 0.25f && l->outer_angle == 0.5f, "cone %g %g", l->inner_angle,
                  l->outer_angle);
        if (k) CHECK(l->position[1] == 3, "spot position");
        st_scene_free(&s);
    }
}

static void test_corrupt(void) {
    size_t n = make_glb(glb, sizeof glb, &good);
    // Every truncation fails cleanly.
    int failures = 0;
    for (size_t len = 0; len < n; len++) {
        st_scene s = {0};
        st_err e = {0};
        bool cam = false;
        if (!st_gltf_load_memory(glb, len, "cut.glb", ".", &s, &cam, &e) &&
            e.kind == ST_ERR_INPUT && s.num_meshes == 0)
            failures++;
        st_scene_free(&s);
    }
    CHECK(failures == (int)n, "%d of %zu truncations failed cleanly", failures, n);
    // Random byte flips in the BIN chunk or header: no crash, and any
    // failure is an input error.
    unsigned seed = 1;
    int clean = 0;
    for (int i = 0; i < 2000; i++) {
        unsigned char copy[sizeof glb];
        memcpy(copy, glb, n);
        for (int f = 0; f < 4; f++) {
            seed = seed * 1103515245u + 12345u;
            copy[(seed >> 8) % n] ^= (unsigned char)(1u << ((seed >> 4) % 8));
        }
        st_scene s = {0};
        st_err e = {0};
        bool cam = false;
        bool ok = st_gltf_load_memory(copy, n, "flip.glb", ".", &s, &cam, &e);
        if (ok || e.kind == ST_ERR_INPUT) clean++;
        st_scene_free(&s);
    }
    CHECK(clean == 2000, "%d of 2000 corrupted files handled", clean);

    variant v = good;
    v.count = "11";
    expect_fail(&v, "accessors[0]: 11 elements at byteOffset 0 exceed bufferViews[0]");
    v = good, v.count = "4294967296";
    expect_fail(&v, "accessors[0]");
    v = good, v.light = "area";
    expect_fail(&v, "type 'area' is not point, directional or spot");
    v = good,
    v.light = "spot\", \"spot\": {\"innerConeAngle\": 0.5, \"outerConeAngle\": 0.5}, \"name\": \"s";
    expect_fail(&v, "innerConeAngle < outerConeAngle");
    v = good, v.children = "3";
    expect_fail(&v, "nodes[3]");
    v = good, v.children = "7";
    expect_fail(&v, "node 7 does not exist");
    v = good, v.children = "1";
    expect_fail(&v, "nodes[1] is reached twice");
    v = good, v.prim_extra = ", \"indices\": 3, \"mode\": 5";
    expect_fail(&v, "mode TRIANGLE_STRIP (5) is not supported");
    v = good, v.prim_extra = ", \"indices\": 2";
    expect_fail(&v, "meshes[0].primitives[0].indices: accessors[2] must be an integer SCALAR");
    v = good, v.attributes = "\"NORMAL\": 1";
    expect_fail(&v, "no POSITION attribute");
    v = good, v.attributes = "\"POSITION\": 0, \"TEXCOORD_1\": 1";
    expect_fail(&v, "TEXCOORD_1: accessors[1] must be 2-component");
    v = good, v.count = "3";
    expect_fail(&v, "NORMAL count differs from POSITION count");
    v = good, v.count = "3", v.attributes = "\"POSITION\": 0";
    expect_fail(&v, "index 5 is 3, but there are 3 vertices");
}

static void test_flat_normals(void) {
    // No NORMAL and no indices: 4 vertices are not whole triangles...
    variant v = good;
    v.attributes = "\"POSITION\": 0";
    v.prim_extra = "";
    expect_fail(&v, "4 vertices without indices is not a multiple of 3");
    // ...3 are: one triangle (0,0,0) (1,0,0) (1,1,0) with flat normal +z.
    v.count = "3";
    size_t n = make_glb(glb, sizeof glb, &v);
    st_scene s = {0};
    st_err e = {0};
    CHECK(st_gltf_load_memory(glb, n, "flat.glb", ".", &s, NULL, &e), "flat: %s", e.msg);
    CHECK(s.num_meshes == 2 && s.meshes[0].num_triangles == 1 && s.meshes[0].uv1 == NULL,
          "one triangle");
    if (s.num_meshes)
        for (int i = 0; i < 3; i++)
            CHECK(s.meshes[0].normals[3 * i + 2] == 1 && s.meshes[0].normals[3 * i] == 0,
                  "flat normal");
    CHECK(s.camera.fov_y == 0, "has_camera NULL leaves the camera alone");
    st_scene_free(&s);
    // Indexed without normals: unwelded to 6 vertices, uv1 carried along.
    v = good;
    v.attributes = "\"POSITION\": 0, \"TEXCOORD_1\": 2";
    n = make_glb(glb, sizeof glb, &v);
    CHECK(st_gltf_load_memory(glb, n, "flat.glb", ".", &s, NULL, &e), "flat indexed: %s", e.msg);
    CHECK(s.num_meshes == 2 && s.meshes[0].num_vertices == 6 && s.meshes[0].uv1 &&
              s.meshes[0].uv1[10] == 0 && s.meshes[0].uv1[11] == 1,
          "unwelded with uv1");
    st_scene_free(&s);
}

// JSON glTF with an embedded (data URI) buffer; hostile nesting is refused
// before tinygltf's recursive conversion could overflow the stack.
static void test_ascii(void) {
    const char *tri =
        "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"mesh\": 0, \"matrix\": "
        "[1,0,0,0, 0,1,0,0, 0,0,1,0, 5,0,0,1]}],"
        " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],"
        " \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
        " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": "
        "\"VEC3\"}]}";
    st_scene s = {0};
    st_err e = {0};
    CHECK(st_gltf_load_memory(tri, strlen(tri), "tri.gltf", ".", &s, NULL, &e), "ascii: %s", e.msg);
    CHECK(s.num_meshes == 1 && s.meshes[0].num_triangles == 1 && s.meshes[0].model[12] == 5 &&
              s.meshes[0].albedo[0] == 0.75f && s.meshes[0].normals[2] == 1,
          "ascii triangle: matrix, default grey, flat normal +z");
    st_scene_free(&s);

    static char deep[4096];
    int n = snprintf(deep, sizeof deep, "{\"asset\": {\"version\": \"2.0\"}, \"extras\": ");
    for (int i = 0; i < 300; i++)
        deep[n++] = '[';
    for (int i = 0; i < 300; i++)
        deep[n++] = ']';
    deep[n++] = '}';
    CHECK(!st_gltf_load_memory(deep, (size_t)n, "deep.gltf", ".", &s, NULL, &e) &&
              strstr(e.msg, "nested deeper than 256"),
          "deep nesting refused: %s", e.msg);
    // Brackets inside strings do not count.
    n = snprintf(deep, sizeof deep, "{\"asset\": {\"version\": \"2.0\", \"generator\": \"");
    for (int i = 0; i < 300; i++)
        deep[n++] = '[';
    n += snprintf(deep + n, sizeof deep - (size_t)n, "\\\"\"}}");
    CHECK(st_gltf_load_memory(deep, (size_t)n, "brackets.gltf", ".", &s, NULL, &e),
          "brackets in a string: %s", e.msg);
    st_scene_free(&s);
    // An accessor without bufferView could claim 4 billion zero vertices.
    const char *bare =
        "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"mesh\": 0}],"
        " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],"
        " \"accessors\": [{\"componentType\": 5126, \"count\": 4000000000, \"type\": \"VEC3\"}]}";
    CHECK(!st_gltf_load_memory(bare, strlen(bare), "bare.gltf", ".", &s, NULL, &e) &&
              strstr(e.msg, "accessors[0]: no bufferView"),
          "accessor without bufferView: %s", e.msg);
}

int main(void) {
    char path[1024];
    snprintf(path, sizeof path, "%s/quad.glb", ST_TEST_SCRATCH);
    size_t n = make_glb(glb, sizeof glb, &good);
    CHECK(n > 0 && n % 4 == 0, "glb size %zu", n);
    write_file(path, glb, n);
    test_load(path);
    test_scene_override(ST_TEST_SCRATCH);
    test_light_types();
    test_corrupt();
    test_flat_normals();
    test_ascii();
    st_err e = {0};
    st_scene s = {0};
    CHECK(!st_gltf_load(ST_TEST_SCRATCH "/missing.glb", &s, NULL, &e) &&
              strstr(e.msg, "missing.glb"),
          "missing file: %s", e.msg);
    return st_test_summary("test_scene_gltf");
}
