// toth's edges pass lists the full-resolution pixels whose upsampling taps
// disagree (select step) and marches them one fragment each, packed densely
// (march step). Invariants on godrays_window (160 x 120, quarter resolution,
// the window scene's equal-error settings and the defaults' probes/kink): the
// list holds distinct pixels of the image, exactly the toth.refined texels
// that are not -1; every listed pixel's fraction is bit for bit the one a
// full-resolution march of that pixel finds (the same call, the same
// jitter), and the border rule marches fewer pixels than the 1-3 pixel image
// border holds while keeping every texel of it that compose reads.
#include "st_test.h" // first: it defines _GNU_SOURCE
#include "st_test_support.h"
#include "st_world.h"

enum { W = 160, H = 120 };
static float refined[W * H * 4], full[W * H * 4], quarter[(W / 4) * (H / 4) * 4];

static bool read_target(st_world *w, const char *name, float *px, int n) {
    const st_target *t = st_world_target(w, name);
    if (!t) return false;
    glGetTextureImage(t->color[0], 0, GL_RGBA, GL_FLOAT, n * 4 * sizeof(float), px);
    return true;
}

static void set(st_world *w, const char *param, double v) {
    st_err err = {0};
    CHECK(st_world_set_param(w, "toth", param, v, &err), "toth.%s: %s", param, err.msg);
}

static void run(const char *name, int probes, double kink) {
    st_scene scene;
    const st_scene *sc = &scene;
    st_err err = {0};
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s.json", ST_TEST_SOURCE_DIR, name);
    CHECK(st_scene_load(path, &scene, &err), "%s: %s", path, err.msg);
    if (err.msg[0]) return;
    scene.width = W;
    scene.height = H;
    st_world *w = st_world_create(sc, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (!w) {
        st_scene_free(&scene);
        return;
    }
    set(w, "samples", 32);
    set(w, "resolution", 2); // quarter
    set(w, "min_rows", 0);
    set(w, "probes", probes);
    set(w, "refine_kink", kink);
    bool ok = st_world_frame(w, &err) && read_target(w, "toth.refined", refined, W * H) &&
              read_target(w, "toth.march", quarter, (W / 4) * (H / 4));
    CHECK(ok, "quarter-resolution frame: %s", err.msg);
    // The list (toth/edges_list.glsl) stays bound at storage binding 4.
    GLint buf = 0;
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 4, &buf);
    GLuint count = 0;
    if (buf) glGetNamedBufferSubData((GLuint)buf, 0, sizeof count, &count);
    CHECK(buf != 0 && count > 0 && count <= W * H, "%s: list of %u pixels", name, count);
    GLuint *list = calloc(count + 1, sizeof *list);
    static unsigned char seen[W * H];
    memset(seen, 0, sizeof seen);
    if (buf && count <= W * H)
        glGetNamedBufferSubData((GLuint)buf, sizeof(GLuint), count * sizeof(GLuint), list);
    int bad = 0, marched = 0, border = 0, border_listed = 0;
    for (GLuint i = 0; i < count && count <= W * H; i++) {
        int x = list[i] & 0xffff, y = list[i] >> 16;
        if (x >= W || y >= H || seen[y * W + x]++) bad++;
    }
    for (int p = 0; p < W * H; p++) {
        marched += refined[4 * p] >= 0;
        bad += (refined[4 * p] >= 0) != (seen[p] != 0);
        // Pixels beyond the outermost march pixels (x or y of 0, or 157-159
        // and 117-119 at quarter resolution): all marched before the rule.
        int x = p % W, y = p / W;
        if (x < 1 || y < 1 || x >= W - 3 || y >= H - 3) border++, border_listed += seen[p] != 0;
    }
    CHECK(bad == 0 && marched == (int)count,
          "%s: %d listed pixels bad or not in toth.refined (%d texels >= 0, %u listed)", name, bad,
          marched, count);
    // The same pixels marched at full resolution by the march pass.
    set(w, "resolution", 0);
    ok = st_world_frame(w, &err) && read_target(w, "toth.march", full, W * H);
    CHECK(ok, "full-resolution frame: %s", err.msg);
    int differ = 0;
    for (GLuint i = 0; i < count && count <= W * H; i++) {
        int x = list[i] & 0xffff, y = list[i] >> 16;
        if (x < W && y < H && memcmp(&refined[4 * (y * W + x)], &full[4 * (y * W + x)], 16)) {
            if (differ++ < 3)
                fprintf(stderr, "  (%d, %d): %.9g against %.9g\n", x, y, refined[4 * (y * W + x)],
                        full[4 * (y * W + x)]);
        }
    }
    CHECK(differ == 0, "%s: %d of %u listed pixels differ from the full-resolution march", name,
          differ, count);
    // Border pixels not marched: their own ray sees the fraction of the
    // nearest march texel (march pixel k traces full pixel 4 k + 1).
    int wrong = 0;
    for (int p = 0; p < W * H; p++) {
        int x = p % W, y = p / W, kx = (x + 1) / 4, ky = (y + 1) / 4;
        kx = kx < W / 4 ? kx : W / 4 - 1;
        ky = ky < H / 4 ? ky : H / 4 - 1;
        bool edge = x < 1 || y < 1 || x >= W - 3 || y >= H - 3;
        if (edge && !seen[p] && memcmp(&full[4 * p], &quarter[4 * (ky * (W / 4) + kx)], 16))
            wrong++;
    }
    CHECK(wrong == 0, "%s: %d border pixels not marched see another fraction than their taps", name,
          wrong);
    printf("%s: %u pixels marched, %d of %d border pixels\n", name, count, border_listed, border);
    free(list);
    st_world_destroy(w);
    st_scene_free(&scene);
}

int main(void) {
    st_context *ctx = st_test_context();
    run("godrays_window", 1, 0.0);
    run("godrays_hidden_hole", 3, 0.01);
    st_context_destroy(ctx);
    return st_test_summary("test_toth_edges");
}
