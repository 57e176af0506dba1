// Declared passes (ABI 1.3) and the plugins built before them. probe_decl
// declares a per-light pre-pass that fills its own target and a post pass
// that adds to the image; it loads no program and declares no target. The
// test checks that the world expands the table per light (and culls the
// light whose target nobody reads), sets the parameters as uniforms, sizes
// the targets by the `scale` parameter and resizes them when it changes,
// hot-reloads the programs from their files (keeping the old program when a
// file breaks) and deletes them with the module. probe_old is a plugin as
// ABI 1.2 built it (minor 2, shorter st_plugin and st_frame, garbage past
// its struct_size): it must load and run on the old path. ABI 1.4: an export
// of a world-owned buffer texture reaches the add pass, and a shader reload
// runs a pass again that waits for its inputs (ST_CHANGE_PROGRAMS).
#include "probe_world.h"

static void part_declared(st_world *w) {
    st_err err = {0};
    int programs = live_programs();
    CHECK(st_world_enable(w, "probe_decl", true, &err), "probe_decl loads: %s", err.msg);
    CHECK(live_programs() == programs + 2, "the world loaded 2 programs (%d -> %d)", programs,
          live_programs());
    float px[3] = {0};
    pixel(w, px);
    CHECK(px[0] == 3.0f && px[1] == 103.0f, "value 3 as u_value, fill1 = 103: got %g %g", px[0],
          px[1]);
    CHECK(px[2] == 7.0f, "the exported buffer texture u_buf holds 7: got %g", px[2]);
    const st_pass_stats *f0 = stats(w, "probe_decl", "fill[0]"),
                        *f1 = stats(w, "probe_decl", "fill[1]"),
                        *add = stats(w, "probe_decl", "add");
    CHECK(f0 && f1 && add, "one fill pass per light and the add pass");
    if (f0 && f1 && add)
        CHECK(f0->culled_last_frame && f1->ran_last_frame && add->ran_last_frame,
              "fill[0] culled (nobody reads it), fill[1] and add ran");
    CHECK(target_width(w, "probe_decl.fill1") == 16, "fill1 at the screen's 16 px: %d",
          target_width(w, "probe_decl.fill1"));
    CHECK(st_world_set_param(w, "probe_decl", "scale", 0.5, &err) &&
              st_world_set_param(w, "probe_decl", "value", 5, &err),
          "set_param: %s", err.msg);
    pixel(w, px);
    CHECK(target_width(w, "probe_decl.fill1") == 8, "scale 0.5 resizes fill1 to 8 px: %d",
          target_width(w, "probe_decl.fill1"));
    CHECK(px[0] == 5.0f && px[1] == 105.0f, "value 5: got %g %g", px[0], px[1]);
    pixel(w, px);
    f1 = stats(w, "probe_decl", "fill[1]"); // the pass list was rebuilt by set_param
    CHECK(f1 && !f1->ran_last_frame && px[1] == 105.0f,
          "fill[1] waits while nothing changes, its target keeps 105: %g", px[1]);
    CHECK(write_add("probe_decl", 2.0, true), "rewrite add.frag");
    CHECK(st_world_reload_shaders(w, &err), "reload: %s", err.msg);
    pixel(w, px);
    CHECK(px[0] == 10.0f, "hot reload: gain 2 gives 10, got %g", px[0]);
    f1 = stats(w, "probe_decl", "fill[1]");
    CHECK(f1 && f1->ran_last_frame, "a reload runs fill[1] again (ST_CHANGE_PROGRAMS)");
    CHECK(write_file("probe_decl", "add.frag", "this is not GLSL\n"), "break add.frag");
    CHECK(!st_world_reload_shaders(w, &err) && strstr(err.msg, "add.frag"),
          "a broken file fails the reload naming it: %s", err.msg);
    pixel(w, px);
    CHECK(px[0] == 10.0f, "the old program stays: %g", px[0]);
    CHECK(write_add("probe_decl", 1.0, true), "restore add.frag");
    CHECK(st_world_enable(w, "probe_decl", false, &err), "probe_decl off: %s", err.msg);
    // A frame first: Mesa frees a deleted program only once no stage of it
    // is bound any more, and the regular program (rebuilt without the
    // module) has a geometry stage that stays bound until the next draw.
    pixel(w, px);
    CHECK(live_programs() == programs, "its programs are deleted (%d, was %d)", live_programs(),
          programs);
    CHECK(target_width(w, "probe_decl.fill1") == -1, "its targets are gone");
}

static void part_old(st_world *w) {
    st_err err = {0};
    CHECK(st_world_enable(w, "probe_old", true, &err), "a plugin built as ABI 1.2 loads: %s",
          err.msg);
    int n = st_world_num_modules(w);
    CHECK(n == 1 && st_world_module(w, 0).plugin->abi_minor == 2 &&
              !st_world_module(w, 0).plugin->passes &&
              !st_world_module(w, 0).plugin->param_uniforms,
          "probe_old is minor 2, its 1.3 fields read as NULL");
    CHECK(st_world_set_param(w, "probe_old", "value", 7, &err), "set_param: %s", err.msg);
    float px[3] = {0};
    pixel(w, px);
    CHECK(px[0] == 7.0f && px[1] == 0.0f, "probe_old adds 7 to red: %g %g", px[0], px[1]);
    CHECK(st_world_enable(w, "probe_old", false, &err), "probe_old off: %s", err.msg);
}

int main(void) {
    probe_dir_setup();
    CHECK(write_decl("probe_decl", true), "write the probe's shaders");
    st_context *ctx = st_test_context();
    st_scene sc = {0};
    st_world *w = probe_world(16, 16, ST_TEST_SCRATCH "/declared.json", &sc);
    if (w) {
        part_declared(w);
        part_old(w);
        st_world_destroy(w);
    }
    st_scene_free(&sc);
    st_context_destroy(ctx);
    return st_test_summary("test_declared_passes");
}
