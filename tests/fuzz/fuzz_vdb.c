// libFuzzer target: st_vdb_load (OpenVDB behind st_vdb.cpp) on arbitrary
// bytes, written to an in-memory file that is opened by path like a scene's
// .vdb. Must never crash, leak or hang, and its memory stays within what the
// voxel cap allows (-rss_limit_mb). Grid "density", as scenes default to.
#define _GNU_SOURCE
#include "st_scene.h"
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static int fd = -1;
    static char path[64];
    if (fd < 0) {
        fd = memfd_create("fuzz.vdb", MFD_CLOEXEC);
        if (fd < 0) abort();
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    }
    if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != (ssize_t)size) abort();
    st_density_grid g;
    st_err e = {0};
    const double t[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    if (st_vdb_load(path, "density", t, s, &g, &e)) st_density_grid_free(&g);
    return 0;
}
