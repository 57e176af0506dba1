// The shipped scenes parse and say what they promise: the Cornell box's walls
// face into the room with the classic colours, the stress scene has at least
// a million triangles, the plane scene is one upward quad and one light.
#include "st_test.h"
#include "st_scene.h"

static bool load(const char *name, st_scene *s) {
    char path[1024];
    st_err e = {0};
    snprintf(path, sizeof path, "%s/scenes/%s", ST_TEST_SOURCE_DIR, name);
    bool ok = st_scene_load(path, s, &e);
    CHECK(ok, "%s: %s", name, e.msg);
    return ok;
}

static bool rgb(const float *c, float r, float g, float b) {
    return c[0] == r && c[1] == g && c[2] == b;
}

static void test_cornell(void) {
    st_scene s;
    if (!load("cornell.json", &s)) return;
    CHECK(s.num_meshes == 7 && st_scene_triangle_count(&s) == 5 * 2 + 2 * 12, "cornell: %d meshes",
          s.num_meshes);
    CHECK(s.camera.position[2] == 3.4f && s.camera.target[1] == 1 && s.camera.fov_y == 40,
          "cornell camera");
    CHECK(s.num_lights == 1 && s.lights[0].position[1] > 1.8f && s.lights[0].position[1] < 2,
          "light under the ceiling");
    // The default scene shows direct light with shadows, one GI bounce and a thin medium with god
    // rays.
    CHECK(s.num_modules == 3 && st_scene_module(&s, "shadow_map") &&
              st_scene_module(&s, "atlas_gi") && st_scene_module(&s, "toth"),
          "shadow_map, atlas_gi and toth modules");
    CHECK(s.medium.present && s.medium.sigma_s[0] > 0 && s.medium.sigma_s[0] * 3.4f < 1,
          "a thin medium");
    int red = 0, green = 0, white_walls = 0;
    for (int i = 0; i < 5 && i < s.num_meshes; i++) {
        const st_mesh *m = &s.meshes[i];
        // Each wall's normal points from the wall towards the room centre (0, 1, 0).
        double d = 0;
        for (int k = 0; k < 3; k++)
            d += m->normals[k] * ((k == 1 ? 1.0 : 0.0) - m->positions[k]);
        CHECK(d > 0.99, "wall %d faces into the room (%g)", i, d);
        // The room spans x, z in [-1, 1], y in [0, 2]: every wall vertex is on it.
        for (uint32_t v = 0; v < m->num_vertices; v++) {
            const float *p = m->positions + 3 * v;
            CHECK(fabsf(p[0]) <= 1 && p[1] >= 0 && p[1] <= 2 && fabsf(p[2]) <= 1,
                  "wall vertex in room");
        }
        if (rgb(m->albedo, 0.75f, 0.1f, 0.1f)) {
            red++;
            CHECK(m->normals[0] == 1, "red wall is the left one (x = -1, facing +x)");
        } else if (rgb(m->albedo, 0.1f, 0.75f, 0.1f)) {
            green++;
            CHECK(m->normals[0] == -1, "green wall is the right one (x = 1, facing -x)");
        } else if (rgb(m->albedo, 0.75f, 0.75f, 0.75f)) {
            white_walls++;
        }
    }
    CHECK(red == 1 && green == 1 && white_walls == 3, "walls red %d green %d white %d", red, green,
          white_walls);
    // Open front: no wall at z = +1.
    for (int i = 0; i < s.num_meshes; i++)
        CHECK(!(s.meshes[i].normals[2] == -1 && s.meshes[i].positions[2] == 1),
              "mesh %d closes the front", i);
    // Two white boxes standing on the floor, one twice as tall as the other.
    if (s.num_meshes == 7) {
        float top[2] = {0, 0};
        for (int b = 0; b < 2; b++) {
            const st_mesh *m = &s.meshes[5 + b];
            CHECK(rgb(m->albedo, 0.75f, 0.75f, 0.75f) && m->num_triangles == 12, "box %d", b);
            for (uint32_t v = 0; v < m->num_vertices; v++)
                top[b] = fmaxf(top[b], m->positions[3 * v + 1]);
        }
        CHECK_REL(top[1], 2 * top[0], 1e-6, 0);
    }
    st_scene_free(&s);
}

static void test_stress(void) {
    st_scene s;
    if (!load("stress.json", &s)) return;
    uint64_t n = st_scene_triangle_count(&s);
    CHECK(n >= 1000000, "stress: %llu triangles", (unsigned long long)n);
    CHECK(n == 2 + 16ull * 2 * 256 * 127, "stress: exact count %llu", (unsigned long long)n);
    CHECK(s.num_lights == 1 && st_scene_module(&s, "shadow_map"), "stress light and module");
    st_scene_free(&s);
}

static void test_plane(void) {
    st_scene s;
    if (!load("plane.json", &s)) return;
    CHECK(s.num_meshes == 1 && s.num_lights == 1 && s.num_modules == 0, "plane contents");
    if (s.num_meshes == 1) {
        CHECK(s.meshes[0].normals[1] == 1, "plane faces up");
        // 10 x 10 m.
        CHECK(st_scene_triangle_count(&s) == 2, "plane triangles");
    }
    st_scene_free(&s);
}

int main(void) {
    test_cornell();
    test_stress();
    test_plane();
    return st_test_summary("test_scene_files");
}
