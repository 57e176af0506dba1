// atlas_gi runs only what the scene needs. With progressive accumulation the
// gather runs exactly max_frames times (tolerance 0) and then stops; camera
// moves and display changes run no atlas pass and give bit-identical indirect
// light back at the first pose; a sampling parameter restarts only the gather;
// lights restart G-buffer and gather; geometry and atlas parameters rebuild
// the atlas. The `strahl render --stats=json` counts show the same.
#include "gi_world.h"
#include <cjson/cJSON.h>

static const char *scene =
    "{\"image\": {\"width\": 64, \"height\": 64},"
    " \"camera\": {\"position\": [0, 1, 0.95], \"target\": [0, 0.8, -1], \"up\": [0, 1, 0], "
    "\"fov_y\": 80, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.5, 0], \"intensity\": [3, 3, 3]}],"
    " \"geometry\": [{\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}, \"inward\": true},"
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}, \"albedo\": "
    "[0.75, 0.1, 0.1]},"
    "  {\"box\": {\"min\": [-0.3, 0, -0.3], \"max\": [0.3, 0.6, 0.3]}}],"
    " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 64, \"mode\": "
    "\"gather\", \"visibility\": false, \"sampling\": \"uniform\", \"samples\": 32, "
    "\"max_frames\": 6,"
    " \"tolerance\": 0, \"display\": \"indirect\"}}]}";

static int gb, ga;
// Runs since the last call.
static void delta(gi_world *g, int *dgb, int *dga) {
    int b = gi_runs(g, "atlas_gi", "gbuffer", NULL), a = gi_runs(g, "atlas_gi", "gather", NULL);
    *dgb = b - gb, *dga = a - ga;
    gb = b, ga = a;
}

static void frames(gi_world *g, int n) {
    for (int i = 0; i < n; i++)
        gi_frame(g);
}

static void set(gi_world *g, const char *param, double v) {
    st_err err = {0};
    CHECK(st_world_set_param(g->w, "atlas_gi", param, v, &err), "set %s: %s", param, err.msg);
}

int main(void) {
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        CHECK(0, "context: %s", err.msg);
        return st_test_summary("test_atlas_gi_skip");
    }
    gi_world g;
    if (gi_world_open(&g, scene)) {
        int db, da;
        frames(&g, 10);
        delta(&g, &db, &da);
        CHECK(db == 1 && da == 6,
              "static scene: G-buffer once, gather max_frames = 6 times (%d, %d)", db, da);
        st_image first = {0}, back = {0};
        gi_read(&g, &first);

        const gi_pose poses[3] = {{{0.5, 1.5, 0.9}, {0, 0.5, 0}, 50},
                                  {{-0.5, 0.5, 0.8}, {0, 1, -1}, 60},
                                  {{0, 1, 0.95}, {0, 0.8, -1}, 80}};
        for (int p = 0; p < 3; p++) {
            gi_set_pose(&g, &poses[p]);
            gi_frame(&g);
        }
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 0, "camera-only frames run no atlas pass (%d, %d)", db, da);
        gi_read(&g, &back);
        CHECK(first.data && back.data &&
                  !memcmp(first.data, back.data, sizeof(float) * 3 * 64 * 64),
              "back at the first pose, the image is bit-identical");
        st_image_free(&back);

        set(&g, "display", 0);
        frames(&g, 2);
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 0, "display change runs no atlas pass (%d, %d)", db, da);
        set(&g, "display", 2);

        set(&g, "samples", 48);
        frames(&g, 10);
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 6, "samples change: gather only, accumulated again (%d, %d)", db,
              da);

        set(&g, "max_frames", 8);
        frames(&g, 10);
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 2, "raising max_frames continues the accumulation (%d, %d)", db, da);

        set(&g, "progressive", 0);
        set(&g, "estimator", 1);
        frames(&g, 4);
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 1, "without progressive accumulation one gather per change (%d, %d)",
              db, da);
        set(&g, "estimator", 0);

        // With a tolerance the accumulation stops by itself, before max_frames.
        set(&g, "progressive", 1);
        set(&g, "max_frames", 1000);
        set(&g, "tolerance", 0.25);
        frames(&g, 60);
        delta(&g, &db, &da);
        CHECK(da >= 4 && da < 60, "converged after %d frames (tolerance 0.25)", da);
        frames(&g, 5);
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 0, "converged: nothing runs (%d, %d)", db, da);
        set(&g, "progressive", 0);
        set(&g, "tolerance", 0);
        set(&g, "max_frames", 8);

        st_world_invalidate(g.w, ST_CHANGE_LIGHTS);
        frames(&g, 3);
        delta(&g, &db, &da);
        CHECK(db == 1 && da == 1, "light change: G-buffer and gather (%d, %d)", db, da);

        st_world_invalidate(g.w, ST_CHANGE_GEOMETRY);
        frames(&g, 3);
        delta(&g, &db, &da);
        CHECK(db == 1 && da == 1, "geometry change: atlas rebuilt (%d, %d)", db, da);

        st_world_invalidate(g.w, ST_CHANGE_SIZE | ST_CHANGE_CAMERA);
        frames(&g, 2);
        delta(&g, &db, &da);
        CHECK(db == 0 && da == 0, "size and camera changes run no atlas pass (%d, %d)", db, da);

        // The medium attenuates light -> texel and sender -> receiver paths.
        st_world_invalidate(g.w, ST_CHANGE_MEDIUM);
        frames(&g, 3);
        delta(&g, &db, &da);
        CHECK(db == 1 && da == 1, "medium change: G-buffer and gather (%d, %d)", db, da);

        set(&g, "progressive", 1);
        set(&g, "samples", 32);
        frames(&g, 10);
        set(&g, "atlas_size", 128);
        delta(&g, &db, &da);
        frames(&g, 10);
        delta(&g, &db, &da);
        CHECK(db == 1 && da == 8, "atlas_size change: atlas rebuilt, accumulated again (%d, %d)",
              db, da);
        // Same indirect light up to the resolution: the mean over the image within 10%.
        st_image now = {0};
        if (gi_read(&g, &now) && first.data) {
            double a = 0, b = 0;
            for (size_t i = 0; i < 3 * 64 * 64; i++)
                a += first.data[i], b += now.data[i];
            CHECK(b > 0 && fabs(a / b - 1) < 0.1, "indirect at atlas 64 vs 128: %.4f vs %.4f", a,
                  b);
        }
        st_image_free(&now);
        st_image_free(&first);
        gi_world_close(&g);
    }
    st_context_destroy(ctx);

    // The command line shows the same: 5 static frames without accumulation
    // run each atlas pass once and skip it 4 times.
    char path[512], out[512], cmd[2048];
    static char buf[1 << 16];
    snprintf(path, sizeof path, "%s/skip.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/skip.exr", ST_TEST_SCRATCH);
    st_test_write(path, scene);
    snprintf(
        cmd, sizeof cmd,
        "%s render %s -o %s --frames 5 --set atlas_gi.progressive=false --stats=json 2>/dev/null",
        ST_TEST_STRAHL, path, out);
    CHECK(st_test_capture(buf, sizeof buf, cmd) == 0, "render --stats=json");
    cJSON *j = cJSON_Parse(buf), *p, *passes = cJSON_GetObjectItem(j, "passes");
    CHECK(j != NULL, "stats are JSON");
    int seen = 0;
    cJSON_ArrayForEach(p, passes) {
        if (strcmp(cJSON_GetObjectItem(p, "module")->valuestring, "atlas_gi")) continue;
        seen++;
        int runs = cJSON_GetObjectItem(p, "runs")->valueint;
        int skipped = cJSON_GetObjectItem(p, "skipped")->valueint +
                      cJSON_GetObjectItem(p, "culled")->valueint;
        CHECK(runs == 1 && skipped == 4, "--stats: atlas_gi %s ran %d, skipped or culled %d",
              cJSON_GetObjectItem(p, "pass")->valuestring, runs, skipped);
    }
    CHECK(seen == 2, "--stats lists atlas_gi's gbuffer and gather passes (%d)", seen);
    cJSON_Delete(j);
    return st_test_summary("test_atlas_gi_skip");
}
