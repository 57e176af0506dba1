// libFuzzer target: OpenVDB behind st_vdb_read_raw, in process, as the
// helper strahl-vdb-read runs it, then st_vdb_place on what it read, on
// arbitrary bytes in an in-memory file. Must never crash, leak or hang, and
// its memory stays within what the voxel cap allows (-rss_limit_mb). Grid
// "density", as scenes default to. OpenVDB 10.0's own heap overflow
// (docs/security.md, finding 6) is reached here: strahl contains it by
// running this code in the helper, so long runs use -fork with
// -ignore_crashes and the crashes are sorted by their stacks.
#include "fuzz_vdb_file.h"
#include "st_vdb_proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    int fd = fuzz_vdb_file(data, size);
    st_vdb_raw raw;
    st_err e = {0};
    if (!st_vdb_read_raw(fd, "fuzz.vdb", "density", FUZZ_VDB_MAX_VOXELS, &raw, &e)) return 0;
    st_density_grid g;
    const double t[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    if (st_vdb_place(&raw, "fuzz.vdb", "density", FUZZ_VDB_MAX_VOXELS, t, s, &g, &e))
        st_density_grid_free(&g);
    return 0;
}
