// Test helper (vdb_writer.cpp): a .vdb file with grid `name`, a block of
// n[0] x n[1] x n[2] voxels at index origin `origin` all holding `value`
// (voxel size `voxel`, no rotation), optionally one voxel `bad` set to
// `bad_value`, and a second float grid "temperature". vector_grid: grid
// `name` holds Vec3s values instead (one voxel). radius > 0: a soft ball
// instead, value (1 - (r / radius)^2) at r voxels from the block's centre
// (0 beyond), for a cloud whose density varies inside.
#ifndef ST_TEST_VDB_WRITER_H
#define ST_TEST_VDB_WRITER_H
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_test_vdb {
    const char *name;
    int n[3], origin[3];
    float value, background;
    double voxel;
    bool has_bad;
    int bad[3];
    float bad_value;
    bool vector_grid;
    double radius;
    bool single_grid; // without the second grid "temperature"
} st_test_vdb;

bool st_test_write_vdb(const char *path, const st_test_vdb *spec);

#ifdef __cplusplus
}
#endif
#endif
