// The frame finds the target a pass draws into by index, not by name
// (issue 33): st_targets_written resolves a pass's `writes` to the registry's
// index once, and the registry's generation says when that must be redone.
// - the first drawn-into target the list names, in registry order; a 1D
//   table is never drawn into; a list naming none gives -1;
// - the generation moves on every change of a name's index or description
//   (a new target, a forgotten one, a new description, freeing a module's)
//   and stays on a re-declaration with the same description (a `needed`
//   hook that declares every frame costs no lookup);
// - after forgetting an earlier target the same list resolves to the
//   shifted index, which a cached index would have missed.
#include "st_test.h"
#include "st_test_support.h"
#include "st_targets.h"

int main(void) {
    st_context *ctx = st_test_context();
    static st_targets t; // large: not on the stack
    st_err err = {0};
    st_target_desc lut = {.format = GL_RGBA32F, .type = GL_TEXTURE_1D, .width = 16};
    st_target_desc screen = {.format = GL_RGBA16F}, half = {.format = GL_RGBA16F, .divisor = 2};
    unsigned g0 = t.gen;
    CHECK(st_targets_declare(&t, "m.lut", &lut, &err), "%s", err.msg);
    CHECK(st_targets_declare(&t, "m.a", &screen, &err), "%s", err.msg);
    CHECK(st_targets_declare(&t, "m.b", &half, &err), "%s", err.msg);
    CHECK(t.gen != g0, "declaring moves the generation");

    CHECK(st_targets_written(&t, "m.b") == 2, "m.b at %d", st_targets_written(&t, "m.b"));
    CHECK(st_targets_written(&t, "hdr, m.b,m.a") == 1, "first in registry order: %d",
          st_targets_written(&t, "hdr, m.b,m.a"));
    CHECK(st_targets_written(&t, "m.lut,m.b") == 2, "a 1D table is not drawn into: %d",
          st_targets_written(&t, "m.lut,m.b"));
    CHECK(st_targets_written(&t, "m.lut") == -1 && st_targets_written(&t, "hdr") == -1 &&
              st_targets_written(&t, "") == -1,
          "no drawn-into target named");

    unsigned g1 = t.gen;
    CHECK(st_targets_declare(&t, "m.b", &half, &err), "%s", err.msg);
    CHECK(t.gen == g1, "the same description again keeps the generation");
    CHECK(st_targets_declare(&t, "m.b", &screen, &err), "%s", err.msg);
    CHECK(t.gen != g1, "a new description moves the generation");

    unsigned g2 = t.gen;
    CHECK(st_targets_declare(&t, "m.a", NULL, &err), "%s", err.msg);
    CHECK(t.gen != g2, "forgetting moves the generation");
    CHECK(st_targets_written(&t, "m.a,m.b") == 1, "m.b shifted to 1: %d",
          st_targets_written(&t, "m.a,m.b"));
    unsigned g3 = t.gen;
    CHECK(st_targets_declare(&t, "x.c", NULL, &err), "%s", err.msg);
    CHECK(t.gen == g3, "forgetting an unknown target keeps the generation");

    st_targets_free(&t, "other");
    CHECK(t.gen == g3, "freeing nobody's targets keeps the generation");
    st_targets_free(&t, "m");
    CHECK(t.gen != g3 && t.n == 0, "freeing a module's targets moves the generation");
    CHECK(st_targets_written(&t, "m.b") == -1, "m.b is gone");
    st_context_destroy(ctx);
    return st_test_summary("test_target_index");
}
