// Numerical stability: atlas sizes 64..2048 and sample counts 1..1024, both
// estimators, several bounces, visibility, a light touching a surface, tiny
// triangles and an absurdly bright emitter: every render finishes, every
// pixel is finite (the command refuses to write non-finite images, and the
// test checks again) and non-negative.
#include "gi_test.h"

static const char *scene_fmt =
    "{\"image\": {\"width\": 48, \"height\": 48},"
    " \"camera\": {\"position\": [0, 1, 0.95], \"target\": [0, 0.8, -1], \"up\": [0, 1, 0], "
    "\"fov_y\": 80, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [%s], \"intensity\": [3, 3, 3]}],"
    " \"geometry\": [{\"box\": {\"min\": [-1, 0, -1], \"max\": [1, 2, 1]}, \"inward\": true},"
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}, \"albedo\": "
    "[0.75, 0.1, 0.1]},"
    "  {\"sphere\": {\"center\": [0.3, 0.2, 0], \"radius\": %s, \"rings\": 12, \"segments\": 16}},"
    "  {\"quad\": {\"corner\": [-0.2, 1.99, -0.2], \"u\": [0.4, 0, 0], \"v\": [0, 0, 0.4]}, "
    "\"emission\": [%s, %s, %s]}],"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 64}},"
    "  {\"name\": \"atlas_gi\", \"params\": {%s}}]}";

static int run(const char *name, const char *light, const char *radius, const char *emission,
               const char *params, const char *frames) {
    char json[4096], extra[64];
    snprintf(json, sizeof json, scene_fmt, light, radius, emission, emission, emission, params);
    snprintf(extra, sizeof extra, "--frames %s", frames);
    st_image img = {0};
    if (!gi_render(name, json, extra, &img)) return 0;
    size_t neg = 0, n = (size_t)img.width * img.height * 3;
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        neg += img.data[i] < 0, sum += img.data[i];
    CHECK(neg == 0, "%s: %zu negative values", name, neg);
    CHECK(sum > 0 && isfinite(sum), "%s: lit image (sum %g)", name, sum);
    st_image_free(&img);
    return 1;
}

int main(void) {
    char name[64], params[256];
    for (int size = 64; size <= 2048; size *= 2) {
        snprintf(name, sizeof name, "atlas_%d", size);
        snprintf(params, sizeof params,
                 "\"atlas_size\": %d, \"mode\": \"gather\", \"visibility\": false, \"sampling\": "
                 "\"uniform\", \"samples\": %d",
                 size, size >= 1024 ? 1 : 16);
        run(name, "0, 1.5, 0", "0.15", "1", params, "2");
    }
    const int samples[] = {1, 2, 7, 100, 1024};
    for (int i = 0; i < 5; i++) {
        snprintf(name, sizeof name, "samples_%d", samples[i]);
        snprintf(params, sizeof params,
                 "\"atlas_size\": 64, \"mode\": \"gather\", \"visibility\": false, \"sampling\": "
                 "\"uniform\", \"samples\": %d, \"bounces\": %d",
                 samples[i], i == 2 ? 3 : 1);
        run(name, "0, 1.5, 0", "0.15", "1", params, "3");
    }
    run("thesis_bounces", "0, 1.5, 0", "0.15", "1",
        "\"atlas_size\": 64, \"mode\": \"gather\", \"visibility\": false, \"sampling\": "
        "\"uniform\", \"samples\": 64, \"estimator\": \"thesis\", \"bounces\": 4",
        "2");
    run("visibility_bounces", "0, 1.5, 0", "0.15", "1",
        "\"atlas_size\": 64, \"mode\": \"gather\", \"sampling\": \"uniform\", \"samples\": 64, "
        "\"visibility\": true, \"bounces\": 2",
        "2");
    // The light on the wall, a 0.1 mm sphere, an emitter at 1e30.
    run("light_on_wall", "0, 1, -1", "0.15", "1",
        "\"atlas_size\": 128, \"mode\": \"gather\", \"visibility\": false, \"sampling\": "
        "\"uniform\", \"samples\": 64",
        "2");
    run("tiny_sphere", "0, 1.5, 0", "0.0001", "1",
        "\"atlas_size\": 128, \"mode\": \"gather\", \"sampling\": \"uniform\", \"samples\": 64, "
        "\"visibility\": true",
        "2");
    run("huge_emission", "0, 1.5, 0", "0.15", "1e30",
        "\"atlas_size\": 64, \"mode\": \"gather\", \"visibility\": false, \"sampling\": "
        "\"uniform\", \"samples\": 64, \"bounces\": 2, \"display\": \"atlas\"",
        "4");
    return st_test_summary("test_atlas_gi_stress");
}
