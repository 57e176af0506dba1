// libFuzzer target: the EXR readers that compare, merge and bench use
// (st_image_read_exr, _stderr, _meta and _channels) on arbitrary bytes. The
// bytes sit in a memfd opened by path (/proc/self/fd/N), so the whole input
// path runs, st_open_input's checks included. Must never crash, leak or hang.
#define _GNU_SOURCE
#include "st_image.h"
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/mman.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static int fd = -1;
    static char path[64];
    if (fd < 0) {
        fd = memfd_create("fuzz.exr", MFD_CLOEXEC);
        if (fd < 0) return 0;
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    }
    if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != (ssize_t)size) return 0;
    static const char *const names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    st_image img = {0};
    st_err e = {0};
    if (st_image_read_exr(path, &img, &e)) (void)st_image_count_nonfinite(&img);
    st_image_free(&img);
    if (st_image_read_exr_stderr(path, &img, &e)) (void)st_image_count_nonfinite(&img);
    st_image_free(&img);
    if (st_image_read_exr_channels(path, names, 6, &img, &e)) (void)st_image_count_nonfinite(&img);
    st_image_free(&img);
    st_exr_meta meta;
    st_image_read_exr_meta(path, &meta, &e);
    return 0;
}
