// A bounding volume hierarchy over world triangles for exact visibility rays
// on the GPU (binned SAH, leaves of up to 4 triangles), shared by atlas_gi's
// gather and shadow_map's refinement; shaders/common/bvh.glsl traverses it.
// GPU layout, both as vec4 arrays: node i = (min.xyz, first), (max.xyz,
// count) with the ints bit-cast; count > 0 is a leaf over triangles
// [first, first + count), otherwise the children are first and first + 1.
// Triangle j = v0, e1 = v1 - v0, e2 = v2 - v0 (w unused).
#ifndef ST_BVH_H
#define ST_BVH_H
#include "st_base.h"
#include "st_gl.h"
#include "st_scene.h"

#define ST_BVH_MAX_DEPTH 60
// The shader storage bindings bvh.glsl reads (ST_BVH_BINDING_NODES, _TRIS
// there); chosen above those atlas_gi's transfer passes use (0..4).
#define ST_BVH_BINDING_NODES 6
#define ST_BVH_BINDING_TRIS 7

typedef struct st_bvh {
    float *nodes; // 8 floats per node
    uint32_t num_nodes;
    float *tris; // 12 floats per triangle
    uint32_t num_tris;
    int depth;
} st_bvh;

// `corners`: 9 floats per triangle (three world positions).
bool st_bvh_build(st_bvh *b, const float *corners, uint32_t n, st_err *err);
void st_bvh_free(st_bvh *b);

// Every triangle of every scene mesh in world space, 9 floats each (free()).
float *st_bvh_scene_corners(const st_scene *sc, uint32_t *count, st_err *err);

// The hierarchy as two shader storage buffers.
typedef struct st_bvh_gpu {
    GLuint nodes, tris;
    uint32_t num_tris;
    long long bytes; // the owner tracks the buffers with st_world_track
} st_bvh_gpu;

bool st_bvh_upload(st_bvh_gpu *g, const st_bvh *b, st_err *err);
// Binds both buffers at ST_BVH_BINDING_NODES / _TRIS.
void st_bvh_bind(const st_bvh_gpu *g);
void st_bvh_gpu_free(st_bvh_gpu *g);

#endif
