// Writes the cross-check's cloud (tests/data/crosscheck/cloud.vdb): a soft
// ball of 24^3 voxels of 5 cm, density 1 - (r / 11.5 voxels)^2, grid
// "density" (tools/crosscheck/README.md). Usage: make_cloud_vdb OUT.vdb
#include <stdio.h>
#include "../reference/vdb_writer.h"

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: make_cloud_vdb OUT.vdb\n");
        return 2;
    }
    st_test_vdb spec = {.name = "density",
                        .n = {24, 24, 24},
                        .origin = {-12, -12, -12},
                        .value = 1.0f,
                        .voxel = 0.05,
                        .radius = 11.5,
                        .single_grid = true};
    if (!st_test_write_vdb(argv[1], &spec)) {
        fprintf(stderr, "make_cloud_vdb: cannot write %s\n", argv[1]);
        return 1;
    }
    return 0;
}
