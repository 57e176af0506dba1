// The fuzzed bytes as a file for the VDB targets (fuzz_vdb, fuzz_vdb_guard):
// one in-memory file, reused across inputs, rewound; the cap on voxels is
// lowered like the fuzzed scenes' triangle limit.
#ifndef FUZZ_VDB_FILE_H
#define FUZZ_VDB_FILE_H
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

#define FUZZ_VDB_MAX_VOXELS 4000000ull

static int fuzz_vdb_file(const uint8_t *data, size_t size) {
    static int fd = -1;
    if (fd < 0) {
        fd = memfd_create("fuzz.vdb", MFD_CLOEXEC);
        if (fd < 0) abort();
    }
    if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != (ssize_t)size) abort();
    if (lseek(fd, 0, SEEK_SET) != 0) abort();
    return fd;
}

#endif
