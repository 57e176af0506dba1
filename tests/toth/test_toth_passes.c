// toth's passes in the frame graph (--stats=json): nothing runs without a
// scattering medium (no medium, or sigma_s = 0) or without lights (the view
// ray's extinction belongs to the regular pass, tests/toth/test_toth_absorb.c);
// toth declares its five passes always (march, gather, edges, keep,
// compose); the gather runs only when interleaved, the edges pass only below
// full resolution, the keep pass only for box stills with reuse=on;
// shadow_map is required; a parameter that is out of range is refused naming it.
#include "toth_test.h"
#include <cjson/cJSON.h>

static char buf[1 << 16], scene[512], out[512];

typedef struct {
    int passes, runs, skipped, culled;
    int march, gather, edges, keep, compose; // runs per pass
} toth_stats;

static toth_stats stats(const char *extra) {
    toth_stats t = {0};
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s render %s -o %s --stats=json --filter point %s 2>/dev/null",
             ST_TEST_STRAHL, scene, out, extra);
    int rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 0, "stats render rc %d", rc);
    cJSON *j = cJSON_Parse(buf);
    CHECK(j != NULL, "stats output is JSON");
    if (!j) return t;
    cJSON *p;
    cJSON_ArrayForEach(p, cJSON_GetObjectItem(j, "passes")) {
        if (strcmp(cJSON_GetObjectItem(p, "module")->valuestring, "toth")) continue;
        const char *name = cJSON_GetObjectItem(p, "pass")->valuestring;
        int runs = cJSON_GetObjectItem(p, "runs")->valueint;
        t.passes++;
        t.runs += runs;
        t.skipped += cJSON_GetObjectItem(p, "skipped")->valueint;
        t.culled += cJSON_GetObjectItem(p, "culled")->valueint;
        if (!strcmp(name, "march")) t.march = runs;
        if (!strcmp(name, "gather")) t.gather = runs;
        if (!strcmp(name, "edges")) t.edges = runs;
        if (!strcmp(name, "keep")) t.keep = runs;
        if (!strcmp(name, "compose")) t.compose = runs;
    }
    cJSON_Delete(j);
    return t;
}

static void write_room(int lights, const char *medium, const char *params) {
    const double L[2][3] = {{0.8, 2.9, -0.5}, {-1, 1, 0}}, I[2][3] = {{10, 10, 10}, {1, 1, 1}};
    toth_write_room_n(scene, 32, lights, L, I, 0.5, medium, params);
}

int main(void) {
    snprintf(scene, sizeof scene, "%s/passes.json", ST_TEST_SCRATCH);
    snprintf(out, sizeof out, "%s/passes.exr", ST_TEST_SCRATCH);
    const char *med = "\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]";

    // With a medium, interleaved: march, gather and compose every frame (32
    // rows, below min_rows: the march is at full resolution, the edges pass
    // has nothing to do; the keep pass of reuse=on only for box stills).
    write_room(2, med, "\"interleave\": 2");
    toth_stats t = stats("--frames 3");
    CHECK(t.passes == 5 && t.keep == 0 && t.march == 3 && t.gather == 3 && t.compose == 3 &&
              t.edges == 0,
          "medium: passes %d, march %d gather %d edges %d compose %d runs", t.passes, t.march,
          t.gather, t.edges, t.compose);
    // Not interleaved: the gather never runs.
    t = stats("--frames 2 --set toth.interleave=1");
    CHECK(t.passes == 5 && t.march == 2 && t.compose == 2 && t.gather == 0,
          "interleave 1: %d passes, gather %d runs", t.passes, t.gather);
    write_room(2, med, "");
    t = stats("--frames 2");
    CHECK(t.passes == 5 && t.march == 2 && t.compose == 2 && t.gather == 0,
          "interleave 1: %d passes, gather %d runs", t.passes, t.gather);
    // Below full resolution the edges pass runs every frame.
    t = stats("--frames 2 --set toth.min_rows=0");
    CHECK(t.edges == 2 && t.compose == 2, "reduced resolution: edges %d runs", t.edges);
    // Fewer samples than M^2 pixels to share them: interleaving is limited.
    t = stats("--set toth.samples=3 --set toth.interleave=4");
    CHECK(t.march == 1 && t.gather == 0,
          "3 samples cannot be split over 2x2 pixels: gather %d runs", t.gather);

    // reuse=on (default), box still: the first frame marches and keeps its
    // fractions, the jittered frames only compose; reuse=off marches every
    // frame and never keeps. Below full resolution (min_rows 0) the
    // edges pass follows the march.
    t = stats("--filter box --frames 6 --set toth.min_rows=0");
    CHECK(t.passes == 5 && t.march == 1 && t.edges == 1 && t.keep == 1 && t.compose == 6,
          "box, reuse: passes %d, march %d edges %d keep %d compose %d runs", t.passes, t.march,
          t.edges, t.keep, t.compose);
    t = stats("--filter box --frames 6 --set toth.min_rows=0 --set toth.reuse=0");
    CHECK(t.march == 6 && t.edges == 6 && t.keep == 0 && t.compose == 6,
          "box, no reuse: march %d edges %d keep %d compose %d runs", t.march, t.edges, t.keep,
          t.compose);
    // The uniform march holds in-scattered light, not a fraction: no reuse.
    t = stats("--filter box --frames 4 --set toth.sampling=uniform");
    CHECK(t.march == 4 && t.keep == 0 && t.compose == 4,
          "box, uniform sampling: march %d keep %d compose %d runs", t.march, t.keep, t.compose);

    // No medium, or one that does not scatter: no toth pass runs.
    write_room(2, NULL, "");
    t = stats("--frames 2");
    CHECK(t.runs == 0 && t.skipped + t.culled > 0, "no medium: %d runs", t.runs);
    write_room(2, "\"sigma_s\": [0, 0, 0], \"sigma_a\": [0.5, 0.5, 0.5]", "");
    t = stats("--frames 2");
    CHECK(t.runs == 0, "sigma_s = 0: %d runs", t.runs);

    // No lights: nothing to scatter (surfaces still fade with distance, in
    // the regular pass).
    write_room(0, med, "");
    t = stats("");
    CHECK(t.runs == 0 && t.march == 0 && t.gather == 0 && t.compose == 0,
          "no lights: march %d gather %d compose %d", t.march, t.gather, t.compose);

    // shadow_map is required; bad parameter values are refused.
    toth_write_room(scene, 32, (const double[3]){0, 1, 0}, (const double[3]){1, 1, 1}, 0.5, med,
                    "");
    char json[4096];
    FILE *f = fopen(scene, "r");
    size_t n = f ? fread(json, 1, sizeof json - 1, f) : 0;
    if (f) fclose(f);
    json[n] = 0;
    char *sm = strstr(json, "{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}},");
    CHECK(sm != NULL, "scene has shadow_map");
    if (sm) {
        size_t l = strlen("{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}},");
        memmove(sm, sm + l, strlen(sm + l) + 1);
        st_test_write(scene, json);
        char cmd[2048];
        snprintf(cmd, sizeof cmd, "%s render %s -o %s --filter point", ST_TEST_STRAHL, scene, out);
        unlink(out);
        int rc = st_test_capture(buf, sizeof buf, cmd);
        CHECK(rc == 2 && strstr(buf, "toth") && strstr(buf, "shadow_map"),
              "toth without shadow_map: rc %d: %s", rc, buf);
        CHECK(!st_test_exists(out), "no output written");
    }
    write_room(1, med, "\"samples\": -1"); // (0 is the default: 32 or 64 by the sampling)
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s render %s -o %s --filter point", ST_TEST_STRAHL, scene, out);
    int rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 2 && strstr(buf, "samples"), "samples -1 refused: rc %d: %s", rc, buf);
    write_room(1, med, "\"resolution\": \"eighth\"");
    rc = st_test_capture(buf, sizeof buf, cmd);
    CHECK(rc == 2 && strstr(buf, "resolution"), "unknown resolution refused: rc %d: %s", rc, buf);
    return st_test_summary("toth_passes");
}
