// Hostile input, round 2 (issue 36): a scene's assets, VDB files, merge
// headers and numbers at the edges. Each reproduction ends with exit 2 and
// one message naming the culprit (nothing overwritten, nothing read outside
// the scene's folder, no raw control character printed), or succeeds within
// bounded time and memory where that is the right answer. Runs the real
// `strahl`; the few renders are 8x8 references with 1 spp.
#include "st_test.h"
#include "reference/vdb_writer.h"
#include "st_base.h"
#include "st_image.h"
#include <sys/resource.h>
#include <sys/stat.h>

static char dir[1024];
static char out[16384];

static int run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int run(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    int rc = st_test_strahl_v(out, sizeof out, dir, 60, "", fmt, ap);
    va_end(ap);
    return rc;
}

static void at(char *p, size_t n, const char *name) {
    snprintf(p, n, "%s/%s", dir, name);
}

static void put_bytes(const char *name, const void *data, size_t len) {
    char p[1200];
    at(p, sizeof p, name);
    FILE *f = fopen(p, "wb");
    CHECK(f && fwrite(data, 1, len, f) == len, "writing %s", name);
    if (f) fclose(f);
}

static void put(const char *name, const char *text) {
    put_bytes(name, text, strlen(text));
}

static char *slurp(const char *name, size_t *len) {
    char p[1200];
    at(p, sizeof p, name);
    st_err e = {0};
    return st_read_file(p, len, &e);
}

static bool says(const char *a, const char *b) {
    return strstr(out, a) && (!b || strstr(out, b));
}
#define BAD(rc, culprit, why, what)                                                                \
    CHECK((rc) == 2 && says(culprit, why), "%s: exit %d, message '%s' (wanted '%s'%s%s)", what,    \
          rc, out, culprit, (why) ? " and " : "", (why) ? (const char *)(why) : "")

// No byte of the output is a control character other than newline.
static bool clean(void) {
    for (const char *p = out; *p; p++)
        if (((unsigned char)*p < 0x20 && *p != '\n') || *p == 0x7f) return false;
    return true;
}

// Peak memory of the children run so far, in MiB (ru_maxrss of the largest).
static double child_peak_mib(void) {
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    return ru.ru_maxrss / 1024.0;
}

static const char camera_light[] =
    "\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0.5, 3], "
    "\"target\": [0, 0.5, 0], \"fov_y\": 50}, \"lights\": [{\"type\": \"point\", \"position\": "
    "[0, 2, 1], \"intensity\": [3, 3, 3]}]";

// A one-triangle glTF whose buffer is the file `bin`.
static void gltf_with_buffer(const char *name, const char *uri) {
    char g[2048];
    snprintf(g, sizeof g,
             "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primitives\": [{\"attributes\": "
             "{\"POSITION\": 0}}]}], \"nodes\": [{\"mesh\": 0}], \"buffers\": [{\"byteLength\": "
             "36, \"uri\": \"%s\"}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], "
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, "
             "\"type\": \"VEC3\", \"min\": [-1, 0, 0], \"max\": [1, 1, 0]}]}",
             uri);
    put(name, g);
}

static void tri_bin(const char *name) {
    const float tri[9] = {-1, 0, 0, 1, 0, 0, 0, 1, 0};
    put_bytes(name, tri, sizeof tri);
}

static void write_vdb(const char *name, const st_test_vdb *spec) {
    char p[1200];
    at(p, sizeof p, name);
    CHECK(st_test_write_vdb(p, spec), "writing %s", name);
}

static void vdb_scene(const char *name, const char *vdb, const char *grid, double sigma_s) {
    char s[2048];
    snprintf(s, sizeof s,
             "{%s, \"geometry\": [{\"quad\": {\"corner\": [-2, 0, -2], \"u\": [0, 0, 4], \"v\": "
             "[4, 0, 0]}}], \"medium\": {\"sigma_s\": [%g, %g, %g], \"sigma_a\": [0, 0, 0], "
             "\"density\": {\"vdb\": \"%s\", \"grid\": \"%s\"}}}",
             camera_light, sigma_s, sigma_s, sigma_s, vdb, grid);
    put(name, s);
}

// A crafted VDB from the source tree (REL) as NAME.vdb under NAME.json:
// `reference` must exit 2 naming NAME.vdb with WHY.
static void vdb_file_case(const char *rel, const char *name, const char *why, const char *what) {
    char src[1200], vdb[64], scene[64];
    snprintf(src, sizeof src, "%s/%s", ST_TEST_SOURCE_DIR, rel);
    snprintf(vdb, sizeof vdb, "%s.vdb", name);
    snprintf(scene, sizeof scene, "%s.json", name);
    st_err e = {0};
    size_t n = 0;
    char *bytes = st_read_file(src, &n, &e);
    CHECK(bytes != NULL, "reading %s: %s", src, e.msg);
    if (bytes) put_bytes(vdb, bytes, n);
    free(bytes);
    vdb_scene(scene, vdb, "density", 1);
    int rc = run("reference %s -o c.exr --spp 1", scene);
    BAD(rc, vdb, why, what);
}

static const st_test_vdb small_box = {
    .name = "density", .n = {4, 4, 4}, .value = 0.5f, .voxel = 0.25, .single_grid = true};

static void shard(const char *name, const char *seeds, int spp, const char *config,
                  const char *filter);

// Item 2: -o is checked against every file the loaded scene read.
static void test_outputs_vs_assets(void) {
    tri_bin("buf.exr"); // a buffer named like an output
    gltf_with_buffer("model.png", "buf.exr");
    write_vdb("cloud.exr", &small_box);
    char s[2048];
    snprintf(s, sizeof s,
             "{%s, \"geometry\": [{\"gltf\": \"model.png\"}], \"medium\": {\"sigma_s\": [0.1, "
             "0.1, 0.1], \"sigma_a\": [0, 0, 0], \"density\": {\"vdb\": \"cloud.exr\"}}}",
             camera_light);
    put("a.json", s);
    size_t n0 = 0, n1 = 0, n2 = 0;
    char *g0 = slurp("model.png", &n0), *b0 = slurp("buf.exr", &n1), *v0 = slurp("cloud.exr", &n2);
    int rc = run("render a.json -o model.png");
    BAD(rc, "-o model.png", "a file the scene a.json uses", "render -o onto the glTF");
    rc = run("reference a.json -o cloud.exr --spp 1");
    BAD(rc, "-o cloud.exr", "the scene", "reference -o onto the VDB");
    rc = run("reference a.json -o buf.exr --spp 1");
    BAD(rc, "-o buf.exr", "the scene", "reference -o onto the glTF's buffer");
    // A hard link to the glTF is the same file.
    char a[1200], b[1200];
    at(a, sizeof a, "model.png");
    at(b, sizeof b, "hard.png");
    unlink(b);
    CHECK(link(a, b) == 0, "hard link");
    rc = run("render a.json -o hard.png");
    BAD(rc, "-o hard.png", "model.png", "render -o onto a hard link of the glTF");
    // bench --csv onto a glTF named like a CSV (checked after the load, before rendering).
    gltf_with_buffer("model.csv", "buf.exr");
    snprintf(s, sizeof s,
             "{%s, \"geometry\": [{\"gltf\": \"model.csv\"}], \"modules\": [{\"name\": "
             "\"shadow_map\"}]}",
             camera_light);
    put("b.json", s);
    shard("ref1.exr", "1", 4, "cfg", "box");
    size_t c0 = 0, c1 = 0;
    char *csv0 = slurp("model.csv", &c0);
    rc = run("bench b.json --reference ref1.exr --sweep shadow_map.bias=0.1 --csv model.csv");
    BAD(rc, "--csv model.csv", "the scene", "bench --csv onto the glTF");
    char *csv1 = slurp("model.csv", &c1);
    CHECK(csv0 && csv1 && c0 == c1 && !memcmp(csv0, csv1, c0), "bench overwrote the glTF");
    free(csv0), free(csv1);
    // A texture of the glTF (never opened, still the model's file).
    put("tex.png", "not really a png");
    char g[2048];
    snprintf(g, sizeof g,
             "{\"asset\": {\"version\": \"2.0\"}, \"images\": [{\"uri\": \"tex.png\"}], "
             "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}], "
             "\"nodes\": [{\"mesh\": 0}], \"buffers\": [{\"byteLength\": 36, \"uri\": "
             "\"buf.exr\"}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], "
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, "
             "\"type\": \"VEC3\", \"min\": [-1, 0, 0], \"max\": [1, 1, 0]}]}");
    put("textured.gltf", g);
    snprintf(s, sizeof s, "{%s, \"geometry\": [{\"gltf\": \"textured.gltf\"}]}", camera_light);
    put("t.json", s);
    rc = run("reference t.json -o tex.exr --spp 1 --size 8x8");
    CHECK(rc == 0, "a textured glTF renders: exit %d: %s", rc, out);
    rc = run("render t.json -o tex.png");
    BAD(rc, "-o tex.png", "the scene", "render -o onto the glTF's texture");
    char *tex = slurp("tex.png", NULL);
    CHECK(tex && !strcmp(tex, "not really a png"), "the texture was overwritten");
    free(tex);
    size_t m0 = 0, m1 = 0, m2 = 0;
    char *g1 = slurp("model.png", &m0), *b1 = slurp("buf.exr", &m1), *v1 = slurp("cloud.exr", &m2);
    CHECK(g0 && g1 && n0 == m0 && !memcmp(g0, g1, n0), "the glTF was overwritten");
    CHECK(b0 && b1 && n1 == m1 && !memcmp(b0, b1, n1), "the buffer was overwritten");
    CHECK(v0 && v1 && n2 == m2 && !memcmp(v0, v1, n2), "the VDB was overwritten");
    free(g0), free(g1), free(b0), free(b1), free(v0), free(v1);
}

// Item 1: the steep fog finishes; a VDB medium too dense to track is refused.
static void test_reference_bounds(void) {
    char s[2048];
    snprintf(s, sizeof s,
             "{%s, \"geometry\": [{\"quad\": {\"corner\": [-2, 0, -2], \"u\": [0, 0, 4], \"v\": "
             "[4, 0, 0]}}], \"medium\": {\"sigma_s\": [0.08, 0.08, 0.085], \"sigma_a\": [0.005, "
             "0.005, 0.005], \"density\": {\"height\": {\"base\": 0.069, \"falloff\": 10000}}}}",
             camera_light);
    put("steep.json", s);
    int rc = run("reference steep.json -o steep.exr --spp 1 --steps 4 --bounces 0 --threads 1");
    CHECK(rc == 0, "steep height fog: exit %d: %s", rc, out);
    write_vdb("box.vdb", &small_box);
    vdb_scene("dense.json", "box.vdb", "density", 1e20);
    rc = run("reference dense.json -o dense.exr --spp 1 --steps 4 --bounces 0 --threads 1");
    BAD(rc, "dense.json", "tentative collisions", "VDB medium with sigma_s 1e20");
}

// Items 6 and 7: corrupt and oversized VDBs, paths leaving the folder.
static void test_vdb_files(void) {
    char src[1200], p[1200];
    snprintf(src, sizeof src, "%s/tests/data/crosscheck/cloud.vdb", ST_TEST_SOURCE_DIR);
    st_err e = {0};
    size_t n = 0;
    char *cloud = st_read_file(src, &n, &e);
    CHECK(cloud && n > 62122, "reading %s: %s", src, e.msg);
    if (!cloud) return;
    put_bytes("cut.vdb", cloud, 1000); // head -c 1000
    cloud[62122] ^= 0x5a;              // one flipped byte
    put_bytes("flip.vdb", cloud, n);
    free(cloud);
    vdb_scene("cut.json", "cut.vdb", "density", 1);
    int rc = run("reference cut.json -o c.exr --spp 1");
    BAD(rc, "cut.vdb", "not a readable OpenVDB file", "truncated VDB");
    vdb_scene("flip.json", "flip.vdb", "density", 1);
    rc = run("reference flip.json -o c.exr --spp 1");
    CHECK(rc == 2 || rc == 0, "flipped byte: exit %d: %s", rc, out);
    if (rc == 2) BAD(rc, "flip.vdb", NULL, "flipped byte");
    // A string length of 2^31 - 1 (the grid's name): OpenVDB would fill a
    // 2 GB string before noticing the end of the file (found by fuzz_vdb).
    write_vdb("len.vdb", &small_box);
    size_t ln = 0;
    char *lb = slurp("len.vdb", &ln);
    bool hit = false;
    for (size_t i = 0; lb && i + 11 < ln && !hit; i++)
        if (!memcmp(lb + i, "\7\0\0\0density", 11))
            memcpy(lb + i, "\377\377\377\177", 4), hit = true;
    CHECK(hit, "the grid name was not found in len.vdb");
    if (lb) put_bytes("len.vdb", lb, ln);
    free(lb);
    vdb_scene("len.json", "len.vdb", "density", 1);
    rc = run("reference len.json -o c.exr --spp 1");
    BAD(rc, "len.vdb", "past the end", "VDB string length 2^31 - 1");
    CHECK(child_peak_mib() < 1024, "peak memory of a bad length: %.0f MiB", child_peak_mib());
    // A blosc block whose size field asks for 56 PB (found by fuzz_vdb):
    // OpenVDB's new char[] throws, reported as a corrupt file.
    vdb_file_case("tests/fuzz/seeds/vdb/crash_blosc_size.vdb", "blosc",
                  "not a readable OpenVDB file", "VDB blosc size 56 PB");
    // A delayed-load mask shorter than the leaves: a clipped read asserted
    // inside OpenVDB (abort; found by fuzz_vdb). The whole grid is read.
    vdb_file_case("tests/fuzz/seeds/vdb/crash_delayed_load_mask.vdb", "dl",
                  "not a readable OpenVDB file", "VDB with a short delayed-load mask");
    // A root tile count of billions in a 14 KB file: OpenVDB looped for
    // minutes (found by fuzz_vdb); refused from the header.
    vdb_file_case("tests/fuzz/seeds/vdb/crash_root_tile_count.vdb", "rt", "root tiles or children",
                  "VDB with a huge root tile count");
    // OpenVDB 10.0's own heap overflow in bloscFromStream (docs/security.md,
    // finding 6): main aborted (exit 134). OpenVDB runs in the helper
    // strahl-vdb-read now, which dies; strahl names the file, exit 2.
    vdb_file_case("tests/fuzz/known_crashes/openvdb_blosc_overflow.vdb", "ov",
                  "the VDB reader strahl-vdb-read crashed", "OpenVDB's blosc overflow");
    CHECK(strchr(out, '\n') == out + strlen(out) - 1, "blosc overflow: not one line: %s", out);
    // Two voxels 400 apart: a 401^3 block, over the voxel cap; refused from
    // the grid's metadata before its voxels are read.
    st_test_vdb far = {.name = "density",
                       .n = {1, 1, 1},
                       .value = 1.0f,
                       .voxel = 0.1,
                       .has_bad = true,
                       .bad = {400, 400, 400},
                       .bad_value = 1.0f};
    write_vdb("far.vdb", &far);
    vdb_scene("far.json", "far.vdb", "density", 1);
    rc = run("reference far.json -o c.exr --spp 1");
    BAD(rc, "far.vdb", "more than the limit", "VDB over the voxel cap");
    CHECK(child_peak_mib() < 1024, "peak memory of a refused VDB: %.0f MiB", child_peak_mib());
    // Outside the scene's folder: "..", absolute, a symlink leading out.
    at(p, sizeof p, "in");
    mkdir(p, 0755);
    write_vdb("out.vdb", &small_box);
    vdb_scene("in/up.json", "../out.vdb", "density", 1);
    rc = run("reference in/up.json -o c.exr --spp 1");
    BAD(rc, "'../out.vdb'", "outside the scene's folder", "VDB path with ..");
    at(p, sizeof p, "out.vdb");
    vdb_scene("in/abs.json", p, "density", 1);
    rc = run("reference in/abs.json -o c.exr --spp 1");
    BAD(rc, p, "outside the scene's folder", "absolute VDB path");
    char link_path[1200];
    at(link_path, sizeof link_path, "in/link.vdb");
    unlink(link_path);
    CHECK(symlink(p, link_path) == 0, "symlink");
    vdb_scene("in/sym.json", "link.vdb", "density", 1);
    rc = run("reference in/sym.json -o c.exr --spp 1");
    BAD(rc, "'link.vdb'", "outside the scene's folder", "symlink VDB leading out");
    rc = run("reference in/sym.json -o c.exr --spp 1 --size 8x8 --allow-outside-assets");
    CHECK(rc == 0, "--allow-outside-assets: exit %d: %s", rc, out);
    // A grid name with an escape sequence is printed escaped.
    st_test_vdb esc = small_box;
    esc.name = "a\x1b[2Jb";
    write_vdb("esc.vdb", &esc);
    vdb_scene("esc.json", "esc.vdb", "density", 1);
    rc = run("reference esc.json -o c.exr --spp 1");
    BAD(rc, "no grid named 'density'", "a\\x1b[2Jb", "grid name with an escape");
    CHECK(clean(), "a raw control character was printed: %s", out);
}

// Item 4: 1000 nodes sharing a 130k-triangle mesh (u8 indices, 390 KB)
// would expand to ~11 GB: refused before any copy, in little memory.
static void test_instancing_bomb(void) {
    const int tris = 130000, nodes = 1000;
    size_t idx_len = (size_t)tris * 3, pos_off = (idx_len + 3) & ~(size_t)3;
    size_t len = pos_off + 4 * 3 * 4;
    unsigned char *buf = calloc(1, len);
    for (size_t i = 0; i < idx_len; i++)
        buf[i] = (unsigned char)(i % 3 + (i / 3) % 2);
    const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    memcpy(buf + pos_off, pos, sizeof pos);
    put_bytes("bomb.bin", buf, len);
    free(buf);
    size_t cap = 64 * (size_t)nodes + 4096;
    char *g = malloc(cap), *p = g;
    p += sprintf(p, "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [");
    for (int i = 0; i < nodes; i++)
        p += sprintf(p, "%s%d", i ? "," : "", i);
    p += sprintf(p, "]}], \"nodes\": [");
    for (int i = 0; i < nodes; i++)
        p += sprintf(p, "%s{\"mesh\": 0, \"translation\": [%d, 0, 0]}", i ? "," : "", i);
    sprintf(p,
            "], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 1}, \"indices\": "
            "0}]}], \"buffers\": [{\"byteLength\": %zu, \"uri\": \"bomb.bin\"}], \"bufferViews\": "
            "[{\"buffer\": 0, \"byteLength\": %zu}, {\"buffer\": 0, \"byteOffset\": %zu, "
            "\"byteLength\": 48}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5121, "
            "\"count\": %zu, \"type\": \"SCALAR\"}, {\"bufferView\": 1, \"componentType\": 5126, "
            "\"count\": 4, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}]}",
            len, idx_len, pos_off, idx_len);
    put("bomb.gltf", g);
    free(g);
    char s[1024];
    snprintf(s, sizeof s, "{%s, \"geometry\": [{\"gltf\": \"bomb.gltf\"}]}", camera_light);
    put("bomb.json", s);
    int rc = run("reference bomb.json -o b.exr --spp 1");
    BAD(rc, "bomb.gltf", "MiB of triangle meshes, more than the limit", "instancing bomb");
    CHECK(child_peak_mib() < 1024, "peak memory of the bomb: %.0f MiB", child_peak_mib());
}

// A 1x1 shard of strahl reference (merge tests).
static void shard(const char *name, const char *seeds, int spp, const char *config,
                  const char *filter) {
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_image img;
    st_err e = {0};
    st_image_alloc(&img, 1, 1, 6, &e);
    const float v[6] = {0.5f, 1, 1, 0.1f, 0.1f, 0.1f};
    memcpy(img.data, v, sizeof v);
    st_exr_meta m = {.spp = spp};
    snprintf(m.seeds, sizeof m.seeds, "%s", seeds);
    snprintf(m.config, sizeof m.config, "%s", config);
    snprintf(m.filter, sizeof m.filter, "%s", filter);
    char p[1200];
    at(p, sizeof p, name);
    CHECK(st_image_write_exr_meta(p, &img, names, &m, &e), "%s", e.msg);
    st_image_free(&img);
}

// Items 10 and 11: merge's messages and checks; URIs and numbers.
static void test_merge_and_minor(void) {
    shard("m1.exr", "1", 4, "cfg", "box");
    shard("m2.exr", "2", 4, "cfg\x1b[2J\x1b[Hfake", "box");
    int rc = run("merge m1.exr m2.exr -o mm.exr");
    BAD(rc, "m2.exr", "cfg\\x1b[2J\\x1b[Hfake", "merge config with an escape");
    CHECK(clean(), "a raw control character was printed: %s", out);
    shard("m3.exr", "3", 4, "cfg", "point");
    rc = run("merge m1.exr m3.exr -o mm.exr");
    BAD(rc, "m3.exr", "point pixel filter", "merge of differing strahl.filter");
    // spp 0 is not written by the EXR writer: patch the attribute's value.
    shard("m4.exr", "4", 7, "cfg", "box");
    size_t n = 0;
    char *b = slurp("m4.exr", &n);
    bool patched = false;
    for (size_t i = 0; b && i + 12 < n && !patched; i++)
        if (!memcmp(b + i, "spp\0int\0\4\0\0\0\7\0\0\0", 16)) {
            memset(b + i + 12, 0, 4);
            patched = true;
        }
    CHECK(patched, "the spp attribute was not found");
    if (b) put_bytes("m4.exr", b, n);
    free(b);
    rc = run("merge m1.exr m4.exr -o mm.exr");
    BAD(rc, "m4.exr", "spp is 0", "merge of a shard with spp 0");
    CHECK(!st_test_exists("mm.exr"), "a refused merge was written");
    // "tri.bin%00x" would open tri.bin.
    tri_bin("tri.bin");
    gltf_with_buffer("nul.gltf", "tri.bin%00x");
    char s[1024];
    snprintf(s, sizeof s, "{%s, \"geometry\": [{\"gltf\": \"nul.gltf\"}]}", camera_light);
    put("nul.json", s);
    rc = run("reference nul.json -o n.exr --spp 1");
    BAD(rc, "tri.bin\\x00x", "NUL or control character", "buffer URI tri.bin%00x");
    // An absolute buffer URI that exists is refused as outside, by name.
    char abs_bin[1200], uri[1300];
    at(abs_bin, sizeof abs_bin, "tri.bin");
    snprintf(uri, sizeof uri, "%s", abs_bin);
    gltf_with_buffer("in/absbuf.gltf", uri);
    snprintf(s, sizeof s, "{%s, \"geometry\": [{\"gltf\": \"absbuf.gltf\"}]}", camera_light);
    put("in/absbuf.json", s);
    rc = run("reference in/absbuf.json -o n.exr --spp 1");
    BAD(rc, abs_bin, "outside the glTF file's folder", "absolute buffer URI");
    // "near": 1e-300 is reported as written.
    put("near.json", "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, "
                     "3], \"target\": [0, 0, 0], \"fov_y\": 50, \"near\": 1e-300}}");
    rc = run("reference near.json -o n.exr --spp 1");
    BAD(rc, "camera.near", "1e-300", "near 1e-300");
    // A control character in a scene string is refused at the string.
    put("ctl.json", "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, "
                    "3], \"target\": [0, 0, 0], \"fov_y\": 50}, \"modules\": [{\"name\": "
                    "\"a\\u001b[2Jb\"}]}");
    rc = run("reference ctl.json -o n.exr --spp 1");
    BAD(rc, "ctl.json", "control character 0x1b", "escape in a scene string");
    CHECK(clean(), "a raw control character was printed: %s", out);
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    char p[1200];
    at(p, sizeof p, "in");
    mkdir(p, 0755);
    test_outputs_vs_assets();
    test_reference_bounds();
    test_vdb_files();
    test_instancing_bomb();
    test_merge_and_minor();
    return st_test_summary("cli_hostile_assets");
}
