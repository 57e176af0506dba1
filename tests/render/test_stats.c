// --stats=json: which passes ran, were skipped or culled. No shadow pass
// without shadow_map; one per light with it, rendered once for a static scene.
// The GPU memory table adds up and counts shadow_map's targets.
#include "st_test_render.h"
#include "st_test_support.h"
#include <cjson/cJSON.h>

static cJSON *stats(const char *scene, const char *out, const char *extra) {
    int rc;
    cJSON *j = st_test_stats_json(scene, out, extra, &rc);
    CHECK(rc == 0, "stats render rc %d", rc);
    CHECK(j != NULL, "stats output is JSON");
    return j;
}

static int count_module(cJSON *j, const char *module, int *runs, int *skipped) {
    int n = 0;
    *runs = *skipped = 0;
    cJSON *p;
    cJSON_ArrayForEach(p, cJSON_GetObjectItem(j, "passes")) {
        if (strcmp(cJSON_GetObjectItem(p, "module")->valuestring, module)) continue;
        n++;
        *runs += cJSON_GetObjectItem(p, "runs")->valueint;
        *skipped += cJSON_GetObjectItem(p, "skipped")->valueint;
    }
    return n;
}

// The GPU memory table: rows sum to gpu_bytes and to the per-owner totals;
// shadow_map's two 64^2 R32F cubes and their depth, and the refine pass's
// BVH over the box's 12 triangles (48 bytes each; nodes 32 bytes each), by
// formula. Its 1 x 1 cascade placeholder is never allocated: without a
// directional light the shaders compile the cascade lookups out
// (ST_LIGHT_TYPES), so nothing asks for it.
static void check_memory(cJSON *j) {
    double rows = 0, owners = 0, cubes = -1, bvh_nodes = -1, bvh_tris = -1, suns = 0;
    cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(j, "memory")) {
        const char *name = cJSON_GetObjectItem(e, "name")->valuestring;
        double b = cJSON_GetObjectItem(e, "bytes")->valuedouble;
        rows += b;
        if (!strcmp(name, "shadow_map.cubes")) cubes = b;
        if (!strcmp(name, "shadow_map.bvh_nodes")) bvh_nodes = b;
        if (!strcmp(name, "shadow_map.bvh_triangles")) bvh_tris = b;
        if (!strcmp(name, "shadow_map.suns")) suns = b;
    }
    CHECK(suns == 0, "shadow_map.suns: %.0f bytes without a directional light", suns);
    CHECK(bvh_tris == 12 * 48, "shadow_map.bvh_triangles: %.0f bytes", bvh_tris);
    CHECK(bvh_nodes > 0 && fmod(bvh_nodes, 32) == 0, "shadow_map.bvh_nodes: %.0f bytes", bvh_nodes);
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(j, "memory_by_owner")) owners += e->valuedouble;
    double total = cJSON_GetObjectItem(j, "gpu_bytes")->valuedouble;
    CHECK(rows == total && owners == total, "memory rows %.0f, owners %.0f, gpu_bytes %.0f", rows,
          owners, total);
    CHECK(cubes == 64 * 64 * 4 * (2 * 6 + 1), "shadow_map.cubes: %.0f bytes", cubes);
    cJSON *sm = cJSON_GetObjectItem(cJSON_GetObjectItem(j, "memory_by_owner"), "shadow_map");
    CHECK(sm && sm->valuedouble == cubes + bvh_nodes + bvh_tris, "shadow_map owns %.0f bytes",
          sm ? sm->valuedouble : -1);
}

static void write_scene(const char *path, int lights, const char *modules) {
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 32, \"height\": 32},\n"
             " \"camera\": {\"position\": [0, 1, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 50, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [%s],\n"
             " \"geometry\": [{\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}, \"inward\": "
             "true}],\n"
             " \"modules\": [%s]}\n",
             lights == 2
                 ? "{\"type\": \"point\", \"position\": [0.5, 1.5, 0], \"intensity\": [1, 1, 1]},"
                   "{\"type\": \"point\", \"position\": [-0.5, 1.5, 0], \"intensity\": [1, 1, 1]}"
                 : "",
             modules);
    st_test_write(path, json);
}

int main(void) {
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/stats.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/stats.exr", ST_TEST_SCRATCH);
    int runs, skipped;

    write_scene(scene, 2, "");
    cJSON *j = stats(scene, out, "--frames 3");
    if (j) {
        CHECK(count_module(j, "shadow_map", &runs, &skipped) == 0,
              "no shadow pass without shadow_map");
        CHECK(count_module(j, "world", &runs, &skipped) == 1 && runs == 3,
              "regular pass ran 3 times: %d", runs);
        CHECK(cJSON_GetObjectItem(j, "frames")->valueint == 2, "2 frames timed after 1 warm-up");
        cJSON_Delete(j);
    }

    write_scene(scene, 2, "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 64}}");
    j = stats(scene, out, "--frames 3");
    if (j) {
        CHECK(count_module(j, "shadow_map", &runs, &skipped) == 2, "one shadow pass per light");
        // Static scene: each cube map is rendered once, then reused.
        CHECK(runs == 2 && skipped == 4, "shadow runs %d (want 2), skipped %d (want 4)", runs,
              skipped);
        check_memory(j);
        cJSON_Delete(j);
    }

    write_scene(scene, 0, "{\"name\": \"shadow_map\"}");
    j = stats(scene, out, "");
    if (j) {
        CHECK(count_module(j, "shadow_map", &runs, &skipped) == 0, "no lights, no shadow pass");
        cJSON_Delete(j);
    }
    st_image img = {0};
    if (st_test_read(out, &img)) {
        CHECK(st_test_all_finite(&img), "finite");
        st_image_free(&img);
    }
    return st_test_summary("test_stats");
}
