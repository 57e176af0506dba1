// libFuzzer target: strahl's own code around OpenVDB, without OpenVDB: the
// header check (st_vdb_check_header, which the helper runs before OpenVDB
// sees the file) and the reading and placing of the helper's reply
// (st_vdb_read_reply, st_vdb_place: a compromised helper may send anything),
// both on the same arbitrary bytes. Must never crash, leak or hang; a reply
// is bounded by the voxel cap before anything is allocated.
#include "fuzz_vdb_file.h"
#include "st_vdb_header.h"
#include "st_vdb_proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    int fd = fuzz_vdb_file(data, size);
    st_err e = {0};
    st_vdb_check_header(fd, size, "fuzz.vdb", &e);
    if (lseek(fd, 0, SEEK_SET) != 0) abort();
    st_vdb_raw raw;
    bool timed_out = false;
    if (!st_vdb_read_reply(fd, "fuzz.vdb", FUZZ_VDB_MAX_VOXELS, 0, &raw, &timed_out, &e)) return 0;
    st_density_grid g;
    const double t[3] = {0.5, 0, -1}, s[3] = {1, 2, 1};
    if (st_vdb_place(&raw, "fuzz.vdb", "density", FUZZ_VDB_MAX_VOXELS, t, s, &g, &e))
        st_density_grid_free(&g);
    return 0;
}
