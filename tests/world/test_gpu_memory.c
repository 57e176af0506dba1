// Every byte of GPU memory is named (issue 12): the world's memory table
// (st_world_memory, --stats) against what GL itself reports. With shadow_map
// (cubes and cascades), atlas_gi (gather, then transfer), toth (quarter
// resolution, interleaved) and ssgi loaded:
// - the live textures and buffers of the context, enumerated by name and
//   sized from GL's own level parameters, add up to the table's total, and
//   each carries the label of a row (no texture a module made by hand);
// - each target's bytes match its declaration by formula: the cube array
//   6 faces x lights, the cascades, toth's march at the screen / 4 rounded up
//   (49x37 -> 13x10), atlas_gi's textures at atlas_size^2 (the statistics
//   with their mip chain, the 1D sample and pick tables);
// - atlas_size 64 -> 128 changes atlas_gi's targets by their formula
//   difference and no other owner's bytes (the issue's --stats read 49.0 MiB
//   at 512 and at 2048);
// - after a resize, switching toth off and switching to mode=transfer (its
//   SSBOs tracked) the GL total still equals the table's; so it does for
//   mitchell and sousa in a second world (nothing of the first left over);
// - a scene whose medium is an OpenVDB grid (the cross-check's cloud, a
//   26^3 block with its ring of zero voxels) counts the grid's 3D texture
//   as the world's row medium.density, 26^3 x 4 bytes, and GL agrees.
#include "st_test_render.h"
#include "st_test_support.h"
#include "st_world.h"

enum { W = 49, H = 37, SM_RES = 32, CASCADES = 2, SAMPLES = 8, NAMES = 16384 };

static const char *scene_json =
    "{\"image\": {\"width\": 49, \"height\": 37},\n"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], "
    "\"fov_y\": 40, \"near\": 0.05, \"far\": 20},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.9, 0], \"intensity\": [3, 3, 3]},\n"
    "  {\"type\": \"directional\", \"direction\": [0.2, -1, -0.3], \"irradiance\": [1, 1, 1]}],\n"
    " \"geometry\": [\n" ST_TEST_CORNELL_WALLS
    "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}}],\n"
    " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]},\n"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 32, "
    "\"cascade_resolution\": 32, \"cascades\": "
    "2}},\n"
    "  {\"name\": \"atlas_gi\", \"params\": {\"mode\": \"gather\", \"samples\": 8, \"atlas_size\": "
    "64}},\n"
    "  {\"name\": \"toth\", \"params\": {\"resolution\": \"quarter\", \"min_rows\": 0, "
    "\"interleave\": 2}},\n"
    "  {\"name\": \"ssgi\", \"params\": {\"samples\": 8}}]}\n";

static const char *vdb_json =
    "{\"image\": {\"width\": 40, \"height\": 30},\n"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], "
    "\"fov_y\": 40, \"near\": 0.05, \"far\": 20},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.9, 0], \"intensity\": [3, 3, 3]}],\n"
    " \"geometry\": [\n" ST_TEST_CORNELL_WALLS
    "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}}],\n"
    " \"medium\": {\"sigma_s\": [0.9, 0.9, 0.9], \"sigma_a\": [0.1, 0.1, 0.1], \"density\": "
    "{\"vdb\": \"cloud.vdb\", \"transform\": "
    "{\"translate\": [0, 1, 0]}}},\n"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 32}},\n"
    "  {\"name\": \"toth\"}]}\n";

static const char *godray_json =
    "{\"image\": {\"width\": 40, \"height\": 30},\n"
    " \"camera\": {\"position\": [0, 1, 3.4], \"target\": [0, 1, 0], \"up\": [0, 1, 0], "
    "\"fov_y\": 40, \"near\": 0.05, \"far\": 20},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.5, -0.5], \"intensity\": [3, 3, "
    "3]}],\n"
    " \"geometry\": [\n" ST_TEST_CORNELL_WALLS
    "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}}],\n"
    " \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], \"sigma_a\": [0.01, 0.01, 0.01]},\n"
    " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 32}},\n"
    "  {\"name\": \"mitchell\"}, {\"name\": \"sousa\"}]}\n";

// Bytes of a texture's every level, from GL (0 for a buffer texture).
static size_t gl_texture_bytes(GLuint t) {
    GLint store = 0, levels = 0;
    glGetTextureLevelParameteriv(t, 0, GL_TEXTURE_BUFFER_DATA_STORE_BINDING, &store);
    if (store) return 0;
    glGetTextureParameteriv(t, GL_TEXTURE_IMMUTABLE_LEVELS, &levels);
    size_t sum = 0;
    for (int l = 0; l < (levels > 0 ? levels : 1); l++) {
        GLint w = 0, h = 0, d = 0, f = 0;
        glGetTextureLevelParameteriv(t, l, GL_TEXTURE_WIDTH, &w);
        glGetTextureLevelParameteriv(t, l, GL_TEXTURE_HEIGHT, &h);
        glGetTextureLevelParameteriv(t, l, GL_TEXTURE_DEPTH, &d);
        glGetTextureLevelParameteriv(t, l, GL_TEXTURE_INTERNAL_FORMAT, &f);
        sum += (size_t)w * h * d * st_format_bytes((GLenum)f);
    }
    return sum;
}

static st_mem_entry rows[512];
static int num_rows;

static const st_mem_entry *row(const char *name) {
    for (int i = 0; i < num_rows; i++)
        if (!strcmp(rows[i].name, name)) return &rows[i];
    return NULL;
}

static size_t row_bytes(const char *name) {
    const st_mem_entry *e = row(name);
    CHECK(e != NULL, "no memory row '%s'", name);
    return e ? e->bytes : 0;
}

// A label names a row: the row itself, its depth texture, or one of the
// camera's textures (labelled with the resource names of the pass list).
static bool label_known(const char *label) {
    static const char *camera[] = {"hdr",   "gbuffer",      "albedo",
                                   "depth", "hdr (post 0)", "hdr (post 1)"};
    for (size_t i = 0; i < sizeof camera / sizeof camera[0]; i++)
        if (!strcmp(label, camera[i])) return true;
    char base[ST_NAME_MAX + 16];
    snprintf(base, sizeof base, "%s", label);
    char *dep = strstr(base, " (depth)");
    if (dep) *dep = 0;
    return row(base) != NULL;
}

// The context's every texture and buffer against the world's table.
static void check_complete(st_world *w, const char *what) {
    num_rows = st_world_memory(w, rows, (int)(sizeof rows / sizeof rows[0]));
    size_t table = 0, gl = 0;
    int objects = 0;
    for (int i = 0; i < num_rows; i++)
        table += rows[i].bytes;
    CHECK(table == st_world_memory_bytes(w), "%s: rows sum to %zu, total says %zu", what, table,
          st_world_memory_bytes(w));
    for (GLuint n = 1; n < NAMES; n++) {
        bool tex = glIsTexture(n), buf = glIsBuffer(n);
        for (int k = 0; k < 2; k++) {
            if (!(k ? buf : tex)) continue;
            GLenum id = k ? GL_BUFFER : GL_TEXTURE;
            GLint64 size = 0;
            if (k) glGetNamedBufferParameteri64v(n, GL_BUFFER_SIZE, &size);
            gl += k ? (size_t)size : gl_texture_bytes(n);
            objects++;
            char label[96] = "";
            glGetObjectLabel(id, n, sizeof label, NULL, label);
            CHECK(label_known(label), "%s: %s %u (label '%s') is in no row of the memory table",
                  what, k ? "buffer" : "texture", n, label);
        }
    }
    while (glGetError() != GL_NO_ERROR) {
    }
    printf("%s: %d GL textures and buffers, %zu bytes; the table: %d rows, %zu bytes\n", what,
           objects, gl, num_rows, table);
    CHECK(gl == table, "%s: GL holds %zu bytes, the memory table counts %zu", what, gl, table);
}

// atlas_gi's targets at an A x A atlas in gather mode, by formula: eight
// RGBA32F textures, RGBA16F albedo, R32F area, the resolve's R8 mask, RGBA32F
// statistics with a full mip chain; 1D tables of SAMPLES RG32F points and
// RGBA32F picks.
static size_t atlas_formula(int a) {
    size_t texel = 8 * 16 + 8 + 4 + 1, stats = 0;
    for (int s = a; s >= 1; s /= 2)
        stats += (size_t)s * s * 16;
    return texel * a * a + stats + SAMPLES * 8 + SAMPLES * 16;
}

static size_t atlas_targets(void) {
    size_t sum = 0;
    for (int i = 0; i < num_rows; i++)
        if (!strcmp(rows[i].owner, "atlas_gi") && strstr(rows[i].kind, "buffer") == NULL)
            sum += rows[i].bytes;
    return sum;
}

static size_t owner_bytes(const char *owner) {
    size_t sum = 0;
    for (int i = 0; i < num_rows; i++)
        if (!strcmp(rows[i].owner, owner)) sum += rows[i].bytes;
    return sum;
}

static void frame(st_world *w, const char *what) {
    st_err err = {0};
    CHECK(st_world_frame(w, &err), "%s: frame: %s", what, err.msg);
}

int main(void) {
    st_context *ctx = st_test_context();
    st_scene sc = {0};
    st_err err = {0};
    CHECK(st_scene_parse(scene_json, strlen(scene_json), ST_TEST_SCRATCH "/memory.json", &sc, &err),
          "%s", err.msg);
    st_world *w = st_world_create(&sc, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (!w) return st_test_summary("test_gpu_memory");
    frame(w, "atlas 64");
    check_complete(w, "atlas 64");

    // Declarations by formula.
    size_t sm = (size_t)SM_RES * SM_RES * 4;
    CHECK(row_bytes("shadow_map.cubes") == sm * (6 * 2 + 1), "cubes: %zu bytes, want %zu",
          row_bytes("shadow_map.cubes"), sm * 13);
    CHECK(row_bytes("shadow_map.suns") == sm * (CASCADES + 1), "suns: %zu bytes, want %zu",
          row_bytes("shadow_map.suns"), sm * (CASCADES + 1));
    const st_mem_entry *march = row("toth.march");
    CHECK(march && march->width == 13 && march->height == 10 && march->bytes == 13 * 10 * 16,
          "toth.march: %dx%d, %zu bytes; want 13x10 (49x37 / 4 rounded up), 2080 bytes",
          march ? march->width : 0, march ? march->height : 0, march ? march->bytes : 0);
    CHECK(row_bytes("toth.gather") == 13 * 10 * 16, "toth.gather: %zu bytes",
          row_bytes("toth.gather"));
    CHECK(row_bytes("ssgi.hammersley") == SAMPLES * 8, "ssgi.hammersley: %zu bytes",
          row_bytes("ssgi.hammersley"));
    CHECK(row_bytes("camera.scene") == (size_t)W * H * (3 * 16 + 4), "camera.scene: %zu bytes",
          row_bytes("camera.scene"));
    size_t a64 = atlas_targets(), atlas64 = owner_bytes("atlas_gi"),
           total64 = st_world_memory_bytes(w);
    CHECK(a64 == atlas_formula(64), "atlas_gi targets at 64: %zu bytes, formula %zu", a64,
          atlas_formula(64));

    // The atlas doubles: the total grows by the atlas targets' difference
    // plus what the atlas' own buffers (coverage points) gained.
    CHECK(st_world_set_param(w, "atlas_gi", "atlas_size", 128, &err), "%s", err.msg);
    frame(w, "atlas 128");
    check_complete(w, "atlas 128");
    size_t a128 = atlas_targets(), total128 = st_world_memory_bytes(w);
    CHECK(a128 == atlas_formula(128), "atlas_gi targets at 128: %zu bytes, formula %zu", a128,
          atlas_formula(128));
    printf("atlas 64 -> 128: total %zu -> %zu bytes (+%zu; targets +%zu by formula, atlas_gi's "
           "buffers +%zu)\n",
           total64, total128, total128 - total64, atlas_formula(128) - atlas_formula(64),
           owner_bytes("atlas_gi") - a128 - (atlas64 - a64));
    CHECK(total128 - owner_bytes("atlas_gi") == total64 - atlas64,
          "other owners changed with the atlas: %zu -> %zu bytes", total64 - atlas64,
          total128 - owner_bytes("atlas_gi"));
    CHECK(total128 - total64 >= atlas_formula(128) - atlas_formula(64), "total grew by %zu only",
          total128 - total64);

    // The world resizes screen-relative targets, and frees a module's.
    CHECK(st_world_resize(w, 30, 22, &err), "%s", err.msg);
    frame(w, "resized");
    check_complete(w, "resized");
    march = row("toth.march");
    CHECK(march && march->width == 8 && march->height == 6, "toth.march after resize: %dx%d",
          march ? march->width : 0, march ? march->height : 0);
    CHECK(row_bytes("atlas_gi.position") == 128 * 128 * 16, "the atlas does not follow the screen");
    CHECK(st_world_enable(w, "toth", false, &err), "%s", err.msg);
    frame(w, "toth off");
    check_complete(w, "toth off");
    CHECK(row("toth.march") == NULL, "toth's targets outlive it");

    // The transfer's buffers and leaf texture are counted too.
    CHECK(st_world_set_param(w, "atlas_gi", "atlas_size", 64, &err), "%s", err.msg);
    CHECK(st_world_set_param(w, "atlas_gi", "mode", 0, &err), "%s", err.msg);
    frame(w, "transfer");
    check_complete(w, "transfer");
    CHECK(row_bytes("atlas_gi.leaf") == 64 * 64 * 4, "atlas_gi.leaf: %zu bytes",
          row_bytes("atlas_gi.leaf"));
    CHECK(row_bytes("atlas_gi.transfer_links") > 0, "the transfer's links are not counted");

    st_world_destroy(w);
    st_scene_free(&sc);

    // The screen-space god rays (point lights only) in a second world: their
    // targets too, and nothing of the first world left behind.
    st_scene sc2 = {0};
    CHECK(st_scene_parse(godray_json, strlen(godray_json), ST_TEST_SCRATCH "/godrays.json", &sc2,
                         &err),
          "%s", err.msg);
    w = st_world_create(&sc2, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (w) {
        frame(w, "god rays");
        check_complete(w, "god rays");
        CHECK(row_bytes("mitchell.occlusion0") > 0 && row_bytes("sousa.mask") > 0,
              "god-ray targets not counted");
        CHECK(st_world_enable(w, "sousa", false, &err), "%s", err.msg);
        frame(w, "sousa off");
        check_complete(w, "sousa off");
        st_world_destroy(w);
    }
    st_scene_free(&sc2);

    // A density grid: its 3D texture is the world's row (and the only
    // texture of its kind, so GL's total checks its bytes too).
    st_scene sc3 = {0};
    // Parsed as if beside the cross-check cloud: a VDB stays in its scene's folder.
    CHECK(st_scene_parse(vdb_json, strlen(vdb_json),
                         ST_TEST_SOURCE_DIR "/tests/data/crosscheck/vdb.json", &sc3, &err),
          "%s", err.msg);
    w = st_world_create(&sc3, NULL, &err);
    CHECK(w != NULL, "world: %s", err.msg);
    if (w) {
        frame(w, "vdb grid");
        check_complete(w, "vdb grid");
        const st_mem_entry *g = row("medium.density");
        CHECK(g && !strcmp(g->owner, "world") && g->width == 26 && g->height == 26 &&
                  g->layers == 26 && g->bytes == 26 * 26 * 26 * 4,
              "medium.density: owner %s, %dx%dx%d, %zu bytes; want world, 26x26x26, %d bytes",
              g ? g->owner : "-", g ? g->width : 0, g ? g->height : 0, g ? g->layers : 0,
              g ? g->bytes : 0, 26 * 26 * 26 * 4);
        st_world_destroy(w);
    }
    st_scene_free(&sc3);
    st_context_destroy(ctx);
    return st_test_summary("test_gpu_memory");
}
