// A test plugin that reads another module's exports (ABI 1.4), for
// test_declared_programs: one post pass adds (grid(x, y, 0), 0,
// value + 10 mode + 100 alt) to the image, where value, mode, alt and the
// grid are the uniforms u_abi_value (float), u_abi_mode (int), u_abi_alt
// (bool) and u_abi_grid (sampler2DArray) that probe_abi exports. It has no
// code: one declared pass whose program the test writes into
// <probe dir>/shaders/probe_reader/read.frag.
#include "st_module.h"

static const st_pass_decl passes[] = {
    {{"read", ST_STAGE_POST, "hdr,probe_abi.grid", "hdr", ST_PASS_FULLSCREEN},
     .frag = "probe_reader/read.frag"},
};

ST_PLUGIN(.name = "probe_reader", .description = "test plugin reading probe_abi's exports",
          .requires = "probe_abi", ST_PASSES(passes))
