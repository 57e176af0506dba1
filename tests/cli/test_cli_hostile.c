// Hostile and careless input (issue 22): every reproduction must end with
// exit 2, one message naming the culprit, nothing executed, nothing read or
// written outside, nothing overwritten. Checks run the real `strahl`
// command; most fail before any rendering, the few that render use 8x8
// images.
#include "st_test.h"
#include "st_base.h"
#include "st_image.h"
#include <fcntl.h>
#include <sys/stat.h>

static char dir[1024];
static char out[8192];

// Runs "cd DIR && timeout 60 strahl ARGS"; its stdout+stderr land in `out`.
static int run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int run(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    int rc = st_test_strahl_v(out, sizeof out, dir, 60, "", fmt, ap);
    va_end(ap);
    return rc;
}

static void put(const char *name, const char *text) {
    st_test_write_text(dir, name, text);
}

static bool exists(const char *name) {
    char p[4200];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    struct stat st;
    return lstat(p, &st) == 0;
}

static char *slurp(const char *name) {
    char p[4200];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    st_err e = {0};
    return st_read_file(p, NULL, &e);
}

// Exit 2 and the message names `culprit` (and, when given, `why`).
static bool says(const char *culprit, const char *why) {
    return strstr(out, culprit) && (!why || strstr(out, why));
}
#define BAD(rc, culprit, why, what)                                                                \
    CHECK((rc) == 2 && says(culprit, why), "%s: exit %d, message '%s' (wanted '%s'%s%s)", what,    \
          rc, out, culprit, (why) ? " and " : "", (why) ? (const char *)(why) : "")

static const char scene[] =
    "{\"image\": {\"width\": 8, \"height\": 8},\n"
    " \"camera\": {\"position\": [0, 2.5, 3], \"target\": [0, 0, 0], \"fov_y\": 50},\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0.3, 1, -0.2], \"intensity\": [2, 1, "
    "1]}],\n"
    " \"geometry\": [{\"quad\": {\"corner\": [-5, 0, -5], \"u\": [0, 0, 10], \"v\": [10, 0, "
    "0]}}],\n"
    " \"modules\": [{\"name\": \"shadow_map\"}]}\n";

static const char csv[] =
    "scene,setting,curve,x,frames,frame_ms_median,module_gpu_ms_median,module_cpu_ms_median,"
    "error_rmse\n"
    "s.json,toth.samples=8,toth,8,1,4,1,1,0.1\n"
    "s.json,toth.samples=64,toth,64,1,30,1,1,0.01\n";

// A 1x1 shard of strahl reference with the given seeds; value 1234.5 in R
// unless `r` is given. ZIP leaves a chunk this small stored raw, so a test
// can patch the float bytes afterwards.
static void shard(const char *name, const char *seeds, float r, float se) {
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_image img;
    st_err e = {0};
    st_image_alloc(&img, 1, 1, 6, &e);
    float v[6] = {r, 1, 1, se, 0.1f, 0.1f};
    memcpy(img.data, v, sizeof v);
    st_exr_meta m = {.spp = 4};
    snprintf(m.seeds, sizeof m.seeds, "%s", seeds);
    snprintf(m.config, sizeof m.config, "test");
    char p[4200];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    CHECK(st_image_write_exr_meta(p, &img, names, &m, &e), "%s", e.msg);
    st_image_free(&img);
}

// Replaces the float `from` in a file by `to` (bit patterns).
static bool patch_float(const char *name, float from, uint32_t to) {
    char p[4200];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    size_t n = 0;
    st_err e = {0};
    char *b = st_read_file(p, &n, &e);
    bool done = false;
    for (size_t i = 0; b && i + 4 <= n && !done; i++)
        if (!memcmp(b + i, &from, 4)) memcpy(b + i, &to, 4), done = true;
    FILE *f = fopen(p, "wb");
    fwrite(b, 1, n, f);
    fclose(f);
    free(b);
    return done;
}

static void test_shell_and_gnuplot(void) {
    put("ok.csv", csv);
    // 1. A path that would break out of shell quotes is just a name.
    int rc = run("plot ok.csv -o \"x';touch PWNED;'.png\"");
    CHECK(rc == 0 && !exists("PWNED") && exists("x';touch PWNED;'.png"),
          "quote in -o: exit %d, PWNED %d", rc, exists("PWNED"));
    rc = run("plot ok.csv -o \"o'neil.svg\" --title \"it's a \\`touch BQ\\` @x\"");
    char *svg = slurp("o'neil.svg");
    CHECK(rc == 0 && svg && strstr(svg, "it's a `touch BQ` @x") && !exists("BQ"),
          "apostrophe path and title: exit %d", rc);
    free(svg);
    // 2. A newline in the title would start a gnuplot command.
    rc = run("plot ok.csv -o t.png --title 'a\nsystem(\"id > P\")\n#'");
    BAD(rc, "--title", "control character", "newline title");
    CHECK(!exists("P") && !exists("t.png"), "the title ran or wrote");
    // A control character in the CSV is refused, naming file and line.
    put("ctl.csv", "scene,setting,curve,x,frames,frame_ms_median,a,b,error_rmse\n"
                   "s.json,toth.samples=8\x0bx,toth,8,1,4,1,1,0.1\n");
    rc = run("plot ctl.csv -o c.png");
    BAD(rc, "ctl.csv:2", "control character", "control character in the CSV");
    // 10. --baseline is checked; the empty-CSV error names the input.
    rc = run("plot ok.csv -o b.png --baseline x");
    BAD(rc, "--baseline x", "MODULE.PARAM=VALUE", "plot --baseline x");
    rc = run("plot ok.csv -o b.png --baseline toth.samples=3");
    BAD(rc, "--baseline toth.samples=3", "no row", "baseline without a row");
    put("empty.csv", "scene,setting,curve,x,frames,frame_ms_median,a,b,error_rmse\n");
    rc = run("plot empty.csv -o e.png");
    BAD(rc, "empty.csv", "no rows", "empty CSV");
    CHECK(!exists("b.png") && !exists("e.png") && !exists("c.png"), "a refused plot was written");
}

static void test_reads(void) {
    put("s.json", scene);
    // 3. Devices and FIFOs are refused at once (timeout 60 would give 124).
    int rc = run("render /dev/zero -o z.exr");
    BAD(rc, "/dev/zero", "not a regular file", "render /dev/zero");
    char p[4200];
    snprintf(p, sizeof p, "%s/fifo.json", dir);
    mkfifo(p, 0600);
    rc = run("render fifo.json -o z.exr");
    BAD(rc, "fifo.json", "FIFO", "FIFO scene");
    snprintf(p, sizeof p, "%s/fifo.gltf", dir);
    mkfifo(p, 0600);
    put("g.json",
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, 3], "
        "\"target\": [0, 0, 0]}, \"geometry\": [{\"gltf\": \"fifo.gltf\"}]}");
    rc = run("reference g.json -o z.exr --spp 1");
    BAD(rc, "fifo.gltf", "FIFO", "FIFO glTF");
    rc = run("compare fifo.json s.json");
    BAD(rc, "fifo.json", "FIFO", "FIFO EXR");
    rc = run("plot fifo.json -o f.png");
    BAD(rc, "fifo.json", "FIFO", "FIFO CSV");
    // Over the cap: a sparse 65 MiB scene file.
    snprintf(p, sizeof p, "%s/big.json", dir);
    int fd = open(p, O_CREAT | O_WRONLY | O_TRUNC, 0644);
    CHECK(fd >= 0 && ftruncate(fd, 65ll << 20) == 0, "sparse file");
    close(fd);
    rc = run("render big.json -o z.exr");
    BAD(rc, "big.json", "64 MiB", "scene over the cap");
    CHECK(!exists("z.exr"), "output written");
}

static void test_writes(void) {
    put("s.json", scene);
    put("victim.txt", "precious\n");
    char a[4200], b[4200];
    shard("a.exr", "1", 0.5f, 0.1f);
    shard("ref.exr", "2", 0.5f, 0.1f);
    // 5. An output that is an input, also through a hard link or a symlink.
    int rc = run("compare a.exr ref.exr --heatmap ref.exr");
    BAD(rc, "ref.exr", "the file name must end in .png", "heatmap onto the reference");
    snprintf(a, sizeof a, "%s/ref.exr", dir);
    snprintf(b, sizeof b, "%s/ref.png", dir);
    unlink(b);
    CHECK(link(a, b) == 0, "hard link");
    rc = run("compare a.exr ref.exr --heatmap ref.png");
    BAD(rc, "ref.png", "the same file", "heatmap onto a hard link of the reference");
    char *ref = slurp("ref.exr");
    CHECK(ref && !strncmp(ref, "v/1\x01", 4), "the reference was overwritten");
    free(ref);
    rc = run("bench s.json --reference ref.exr --sweep shadow_map.bias=0.1 --csv s.json");
    BAD(rc, "--csv s.json", ".csv", "bench --csv onto the scene");
    put("s.csv", scene);
    rc = run("bench s.csv --reference ref.exr --sweep shadow_map.bias=0.1 --csv s.csv");
    BAD(rc, "--csv s.csv", "the same file", "bench --csv onto the scene (.csv)");
    char *sc = slurp("s.csv");
    CHECK(sc && !strcmp(sc, scene), "the scene was overwritten");
    free(sc);
    // 4. A symlink at the output is replaced, its target left alone.
    snprintf(a, sizeof a, "%s/victim.txt", dir);
    snprintf(b, sizeof b, "%s/link.exr", dir);
    unlink(b);
    CHECK(symlink(a, b) == 0, "symlink");
    rc = run("reference s.json -o link.exr --spp 1 --threads 1");
    char *v = slurp("victim.txt");
    struct stat st;
    CHECK(rc == 0 && v && !strcmp(v, "precious\n") && lstat(b, &st) == 0 && S_ISREG(st.st_mode),
          "symlinked output: exit %d, victim '%s'", rc, v ? v : "(gone)");
    free(v);
    // 9. Output paths checked before any work.
    snprintf(a, sizeof a, "%s/adir.exr", dir);
    mkdir(a, 0755);
    rc = run("render s.json -o adir.exr");
    BAD(rc, "adir.exr", "directory", "-o a directory");
    rc = run("render s.json -o out/");
    BAD(rc, "out/", "directory", "-o ending in /");
    rc = run("reference s.json -o no/such/x.exr");
    BAD(rc, "no/such/x.exr", "does not exist", "-o in a missing folder");
    rc = run("render s.json -o /proc/x.exr");
    BAD(rc, "/proc/x.exr", "cannot create", "-o /proc/x.exr");
    char name[300];
    memset(name, 'n', 256);
    memcpy(name + 252, ".exr", 5); // 256 bytes: over NAME_MAX
    rc = run("reference s.json -o %s --spp 1", name);
    BAD(rc, name, "longer than 255", "-o over NAME_MAX");
    memcpy(name + 251, ".exr", 5); // 255 bytes: fits, and so does the temporary file
    rc = run("reference s.json -o %s --spp 1 --threads 1", name);
    CHECK(rc == 0 && exists(name), "-o of 255 bytes: exit %d", rc);
    rc = run("render s.json -o s.jpg");
    BAD(rc, "s.jpg", ".exr or .png", "-o extension");
    rc = run("bench s.json --reference ref.exr --sweep shadow_map.bias=0.1 --csv b.csv --plot "
             "b.csv");
    BAD(rc, "--plot b.csv", ".png or .svg", "--plot extension");
}

static void test_gltf(void) {
    // One triangle, its buffer outside the glTF's folder.
    char p[4200];
    snprintf(p, sizeof p, "%s/assets", dir);
    mkdir(p, 0755);
    snprintf(p, sizeof p, "%s/outside", dir);
    mkdir(p, 0755);
    const float tri[9] = {-1, -1, 0, 1, -1, 0, 0, 1, 0};
    for (int k = 0; k < 2; k++) {
        snprintf(p, sizeof p, "%s/%s", dir, k ? "assets/tri.bin" : "outside/tri.bin");
        FILE *f = fopen(p, "wb");
        fwrite(tri, sizeof tri, 1, f);
        fclose(f);
    }
    snprintf(p, sizeof p, "%s/assets/link.bin", dir);
    unlink(p);
    CHECK(symlink("../outside/tri.bin", p) == 0, "symlink");
    const char *uris[] = {"../outside/tri.bin",
                          "..%2Foutside%2Ftri.bin",
                          "../../../../../../../../etc/passwd",
                          "/etc/passwd",
                          "link.bin",
                          "tri.bin"};
    for (int k = 0; k < 6; k++) {
        char g[2048], s[1024];
        snprintf(
            g, sizeof g,
            "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], "
            "\"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": "
            "{\"POSITION\": 0}}]}], \"buffers\": [{\"byteLength\": 36, \"uri\": \"%s\"}], "
            "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"accessors\": "
            "[{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", "
            "\"min\": [-1, -1, 0], \"max\": [1, 1, 0]}]}",
            uris[k]);
        put("assets/m.gltf", g);
        snprintf(s, sizeof s,
                 "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, "
                 "3], \"target\": [0, 0, 0], \"fov_y\": 40}, \"lights\": [{\"type\": \"point\", "
                 "\"position\": "
                 "[0, 0, 2], \"intensity\": [1, 1, 1]}], \"geometry\": [{\"gltf\": "
                 "\"assets/m.gltf\"}]}");
        put("m.json", s);
        int rc = run("reference m.json -o g.exr --spp 1 --threads 1");
        if (k == 5) {
            CHECK(rc == 0, "a buffer inside the folder: exit %d: %s", rc, out);
            continue;
        }
        // 6. The URI is named; nothing of the file's size or content leaks.
        // An absolute URI that exists is refused as outside too (issue 36),
        // not as "File not found".
        const char *named = k == 1 ? "../outside/tri.bin" : uris[k];
        BAD(rc, named, "outside the glTF file's folder", uris[k]);
        CHECK(!strstr(out, "size mismatch") && !strstr(out, "requestedBytes"), "size leaked: %s",
              out);
        if (k == 0) {
            rc = run("reference m.json -o g.exr --spp 1 --threads 1 --allow-outside-assets");
            CHECK(rc == 0, "--allow-outside-assets: exit %d: %s", rc, out);
        }
    }
    put("assets/i.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"images\": [{\"uri\": "
                         "\"../outside/x.png\"}]}");
    put("i.json",
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 0, 3], "
        "\"target\": [0, 0, 0]}, \"geometry\": [{\"gltf\": \"assets/i.gltf\"}]}");
    int rc = run("reference i.json -o g.exr --spp 1");
    BAD(rc, "images[0]", "../outside/x.png", "image URI outside");
}

static void test_merge(void) {
    // 7. Bad shards are named; seeds are integers.
    shard("m1.exr", "1", 0.5f, 0.1f);
    shard("nan.exr", "2", 1234.5f, 0.1f);
    CHECK(patch_float("nan.exr", 1234.5f, 0x7fc00000u), "patched a NaN in");
    int rc = run("merge m1.exr nan.exr -o m.exr");
    BAD(rc, "nan.exr", "nan", "NaN shard");
    shard("neg.exr", "3", -0.5f, 0.1f);
    rc = run("merge m1.exr neg.exr -o m.exr");
    BAD(rc, "neg.exr", "radiance R is -0.5", "negative radiance");
    shard("negse.exr", "4", 0.5f, -0.1f);
    rc = run("merge m1.exr negse.exr -o m.exr");
    BAD(rc, "negse.exr", "stderr.R is -0.1", "negative stderr");
    const char *same[] = {"01", "1"};
    for (int k = 0; k < 2; k++) {
        shard("dup.exr", same[k], 0.5f, 0.1f);
        rc = run("merge m1.exr dup.exr -o m.exr");
        BAD(rc, "dup.exr", "seed 1 is in an earlier shard", same[k]);
    }
    const char *junk[] = {" 1", "0x1", "abc,,-1", "-1", "1,,2", "99999999999999999999"};
    for (int k = 0; k < 6; k++) {
        shard("junk.exr", junk[k], 0.5f, 0.1f);
        rc = run("merge m1.exr junk.exr -o m.exr");
        BAD(rc, "junk.exr", "seed", junk[k]);
    }
    shard("twice.exr", "5,6,5", 0.5f, 0.1f);
    rc = run("merge m1.exr twice.exr -o m.exr");
    BAD(rc, "twice.exr", "seed 5 is in the shard twice", "seed repeated in a shard");
    CHECK(!exists("m.exr"), "a refused merge wrote its output");
    shard("m2.exr", "007", 0.5f, 0.1f);
    rc = run("merge m1.exr m2.exr -o m.exr");
    st_exr_meta meta;
    st_err e = {0};
    char p[4200];
    snprintf(p, sizeof p, "%s/m.exr", dir);
    CHECK(rc == 0 && st_image_read_exr_meta(p, &meta, &e) && !strcmp(meta.seeds, "1,7"),
          "merged seeds '%s' (exit %d)", meta.seeds, rc);
}

static void test_bench_and_messages(void) {
    put("s.json", scene);
    shard("ref.exr", "2", 0.5f, 0.1f);
    // 8. bench.
    int rc = run("bench s.json --reference ref.exr --sweep shadow_map.bias=0.1,0.2 --sweep "
                 "shadow_map.bias=0.3 --csv b.csv");
    BAD(rc, "shadow_map.bias is swept twice", NULL, "the same sweep twice");
    put("other.csv", "scene,setting,curve,x,frames,frame_ms_median,a,b,error_relmse\n");
    rc = run("bench s.json --reference ref.exr --sweep shadow_map.bias=0.1 --csv other.csv "
             "--append");
    BAD(rc, "--append other.csv", "header differs", "--append to another header");
    char *o = slurp("other.csv");
    CHECK(o && !strcmp(o, "scene,setting,curve,x,frames,frame_ms_median,a,b,error_relmse\n"),
          "other.csv changed");
    free(o);
    CHECK(!exists("b.csv"), "b.csv written");
    // 10. The smaller ones.
    put("nul.json",
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 2, 3], "
        "\"target\": [0, 0, 0]}, \"modules\": [{\"name\": \"shadow_map\\u0000x\"}]}");
    rc = run("render nul.json -o n.exr");
    BAD(rc, "nul.json", "\\u0000", "module name with NUL");
    char *deep = malloc(20010);
    memset(deep, '[', 10000);
    memset(deep + 10000, ']', 10000);
    deep[20000] = 0;
    put("deep.json", deep);
    free(deep);
    rc = run("render deep.json -o n.exr");
    BAD(rc, "deep.json", "nested deeper than 64 levels", "deep nesting");
    put("hg.json", "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"position\": [0, 2, "
                   "3], \"target\": [0, 0, 0]}, \"medium\": {\"sigma_s\": [0.1, 0.1, 0.1], "
                   "\"phase\": {\"hg\": 1.0000001}}}");
    rc = run("reference hg.json -o n.exr");
    BAD(rc, "1.0000001 is out of range", NULL, "out-of-range digits");
    // --set errors name the --set (this one builds the world: 8x8, one frame).
    rc = run("render s.json -o n.exr --frames 1 --set shadow_map.cascade_split=1.0000001");
    BAD(rc, "--set shadow_map.cascade_split=1.0000001", "1.0000001 is out of range [0, 1]",
        "--set out of range");
    CHECK(!strstr(out, "modules[0]"), "--set blamed on the scene: %s", out);
    CHECK(!exists("n.exr"), "n.exr written");
}

int main(void) {
    snprintf(dir, sizeof dir, "%s", ST_TEST_SCRATCH);
    st_test_sh("cd '%s' && rm -rf ./* ./.strahl-*", dir);
    test_shell_and_gnuplot();
    test_reads();
    test_writes();
    test_gltf();
    test_merge();
    test_bench_and_messages();
    // No temporary file is ever left behind.
    CHECK(st_test_sh("cd '%s' && ! ls -a | grep -q '^\\.strahl-'", dir) == 0, "temporary left");
    return st_test_summary("cli_hostile");
}
