// atlas_gi: a bounding volume hierarchy over the scene's world triangles for
// the gather's visibility rays (binned SAH, leaves of up to 4 triangles).
// GPU layout, both as vec4 arrays: node i = (min.xyz, first), (max.xyz,
// count) with the ints bit-cast; count > 0 is a leaf over triangles
// [first, first + count), otherwise the children are first and first + 1.
// Triangle j = v0, e1 = v1 - v0, e2 = v2 - v0 (w unused).
#ifndef ATLAS_GI_BVH_H
#define ATLAS_GI_BVH_H
#include "st_base.h"

#define BVH_MAX_DEPTH 60

typedef struct bvh {
    float *nodes; // 8 floats per node
    uint32_t num_nodes;
    float *tris; // 12 floats per triangle
    uint32_t num_tris;
    int depth;
} bvh;

// `corners`: 9 floats per triangle (three world positions).
bool bvh_build(bvh *b, const float *corners, uint32_t n, st_err *err);
void bvh_free(bvh *b);

#endif
