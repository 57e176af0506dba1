// A relight equals a fresh render: atlas_gi (mode=transfer) with the light
// moved twice after its first frame gives the same image, bit for bit, as a
// world whose first frame has the light where it ended: with display
// combined, then with visibility=false (a new transfer, which also takes in
// the texels the buried test had sealed), then with display atlas (which
// reads the combined atlas at every texel). A relight redraws only what the light changes
// (gbuffer.c: L0, at the transfer's texels), so this is what keeps it from reading anything stale.
// The closed boxes stand on the floor: buried and sealed texels.
#include "gi_world.h"
#include "st_test_support.h"

static const char *scene_json =
    "{\"image\": {\"width\": 64, \"height\": 64},"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], \"fov_y\": "
    "40, \"near\": 0.05, \"far\": 100},"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.9, 0], \"intensity\": [3, 3, 3]}],"
    " \"geometry\": [" ST_TEST_CORNELL_WALLS ST_TEST_CORNELL_BLOCKS " ],"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 256}},"
    "  {\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128}}]}";

static const float MOVES[2][3] = {{0.4f, 1.7f, 0.3f}, {-0.3f, 1.8f, 0.2f}};
static const float INTENSITY[3] = {3, 3, 3};

// The images at display combined, with visibility off, at display atlas; `moves` light
// positions before the first read (the first frame at the scene's light
// when moves > 0, else at the last move's position).
static int render(int moves, st_image img[3]) {
    gi_world g;
    st_err err = {0};
    if (!gi_world_open(&g, scene_json)) return 0;
    int ok = 1;
    if (moves == 0) ok = st_world_set_light(g.w, 0, MOVES[1], INTENSITY, &err);
    ok = ok && gi_frame(&g);
    for (int m = 0; m < moves && ok; m++)
        ok = st_world_set_light(g.w, 0, MOVES[m], INTENSITY, &err) && gi_frame(&g);
    ok = ok && gi_read(&g, &img[0]);
    ok = ok && st_world_set_param(g.w, "atlas_gi", "visibility", 0, &err) && gi_frame(&g) &&
         gi_read(&g, &img[1]);
    ok = ok && st_world_set_param(g.w, "atlas_gi", "display", 3, &err) && gi_frame(&g) &&
         gi_read(&g, &img[2]);
    CHECK(ok, "render after %d moves: %s", moves, err.msg);
    gi_world_close(&g);
    return ok;
}

int main(void) {
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        CHECK(0, "context: %s", err.msg);
        return st_test_summary("test_atlas_gi_relight");
    }
    st_image moved[3] = {{0}}, fresh[3] = {{0}};
    if (render(2, moved) && render(0, fresh)) {
        static const char *const names[3] = {"combined", "combined, visibility off", "atlas"};
        for (int d = 0; d < 3; d++) {
            size_t n = (size_t)moved[d].width * moved[d].height * moved[d].channels, diff = 0;
            double worst = 0, sum = 0;
            for (size_t i = 0; i < n; i++) {
                double e = fabs((double)moved[d].data[i] - fresh[d].data[i]);
                diff += e > 0;
                worst = e > worst ? e : worst;
                sum += fresh[d].data[i];
            }
            printf("display %s: mean %.5f, %zu of %zu values differ (worst %.3g)\n", names[d],
                   sum / (double)n, diff, n, worst);
            CHECK(sum > 0, "display %s: a lit image", names[d]);
            CHECK(diff == 0, "display %s: relight == fresh render (%zu values differ, worst %.3g)",
                  names[d], diff, worst);
        }
    }
    for (int d = 0; d < 3; d++)
        st_image_free(&moved[d]), st_image_free(&fresh[d]);
    st_context_destroy(ctx);
    return st_test_summary("test_atlas_gi_relight");
}
