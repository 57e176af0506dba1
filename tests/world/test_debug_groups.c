// GPU captures read like --stats: every pass that runs is wrapped in a debug
// group named "module/pass" exactly as in the stats table, in frame order;
// skipped and culled passes push none. The camera's targets carry the
// resource names of the pass list as object labels.
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"

#define MAX_GROUPS 64
static char groups[MAX_GROUPS][2 * ST_NAME_MAX + 2];
static int num_groups;

static void GLAPIENTRY on_debug(GLenum source, GLenum type, GLuint id, GLenum severity,
                                GLsizei length, const GLchar *message, const void *user) {
    if (type != GL_DEBUG_TYPE_PUSH_GROUP || source != GL_DEBUG_SOURCE_APPLICATION) return;
    if (num_groups < MAX_GROUPS) snprintf(groups[num_groups++], sizeof groups[0], "%s", message);
}

static const char *scene_json =
    "{\"image\": {\"width\": 32, \"height\": 32},\n"
    " \"camera\": {\"position\": [0.5, 1.7, 7], \"target\": [0, 1.5, 0], \"up\": [0, 1, 0], "
    "\"fov_y\": 50,"
    " \"near\": 0.05, \"far\": 40},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0.2, 1.8, 2.2], \"intensity\": [12, 12, "
    "12]}],\n"
    " \"geometry\": [{\"quad\": {\"corner\": [-8, 0, -8], \"u\": [0, 0, 16], \"v\": [16, 0, 0]}},\n"
    "  {\"box\": {\"min\": [-0.6, 0, -0.2], \"max\": [-0.2, 3.2, 0.2]}}],\n"
    " \"medium\": {\"sigma_s\": [0.08, 0.08, 0.08], \"sigma_a\": [0.01, 0.01, 0.01]},\n"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 64}}, {\"name\": "
    "\"mitchell\"}]}\n";

// The groups of one frame against the passes the stats say ran.
static void check_frame(st_world *w, const char *what, int want_runs) {
    st_err err = {0};
    num_groups = 0;
    CHECK(st_world_frame(w, &err), "%s: frame: %s", what, err.msg);
    int k = 0;
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *ps = st_world_pass_stats(w, i);
        if (!ps->ran_last_frame) continue;
        char want[2 * ST_NAME_MAX + 2];
        snprintf(want, sizeof want, "%s/%s", ps->module, ps->pass);
        CHECK(k < num_groups && !strcmp(groups[k], want), "%s: group %d is '%s', want '%s'", what,
              k, k < num_groups ? groups[k] : "(none)", want);
        k++;
    }
    printf("%s: %d debug groups:", what, num_groups);
    for (int i = 0; i < num_groups; i++)
        printf(" %s", groups[i]);
    printf("\n");
    CHECK(num_groups == k && k == want_runs, "%s: %d groups, %d passes ran, want %d", what,
          num_groups, k, want_runs);
}

int main(void) {
    st_context *ctx = st_test_context();
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(on_debug, NULL);
    st_scene sc = {0};
    st_err err = {0};
    CHECK(st_scene_parse(scene_json, strlen(scene_json), ST_TEST_SCRATCH "/debug.json", &sc, &err),
          "%s", err.msg);
    st_world *w = st_world_create(&sc, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (w) {
        // First frame: shadow cube, occlusion, regular, blur.
        check_frame(w, "first frame", 4);
        // The camera moved: the cube is skipped, the rest runs again.
        const float pos[3] = {0.6f, 1.7f, 7}, tgt[3] = {0, 1.5f, 0}, up[3] = {0, 1, 0};
        st_world_set_camera(w, pos, tgt, up);
        check_frame(w, "camera moved", 3);
        const st_camera *c = st_world_camera(w);
        const struct {
            GLenum kind;
            GLuint id;
            const char *name;
        } labels[] = {{GL_TEXTURE, c->scene.color[0], "hdr"},
                      {GL_TEXTURE, c->scene.color[1], "gbuffer"},
                      {GL_TEXTURE, c->scene.color[2], "albedo"},
                      {GL_TEXTURE, c->scene.depth, "depth"},
                      {GL_FRAMEBUFFER, c->scene.fbo, "camera.scene"}};
        for (size_t i = 0; i < sizeof labels / sizeof labels[0]; i++) {
            char got[64] = "";
            glGetObjectLabel(labels[i].kind, labels[i].id, sizeof got, NULL, got);
            CHECK(!strcmp(got, labels[i].name), "label '%s', want '%s'", got, labels[i].name);
        }
        st_world_destroy(w);
    }
    st_scene_free(&sc);
    st_context_destroy(ctx);
    return st_test_summary("test_debug_groups");
}
