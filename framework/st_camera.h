// strahl: the Camera with its PostProcessor targets (thesis: Camera,
// PostProcessor).
#ifndef ST_CAMERA_H
#define ST_CAMERA_H
#include "st_gpu.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---- Camera / PostProcessor ---------------------------------------------

typedef struct st_camera {
    float position[3], target[3], up[3];
    float fov_y, near_z, far_z;
    int width, height;
    float view[16], proj[16], view_proj[16], inv_view_proj[16];
    // The regular pass draws into `scene` (0 radiance, 1 gbuffer, 2 albedo,
    // depth); the PostProcessor ping-pongs between post[0] and post[1].
    st_target scene, post[2];
    int post_out;   // index of the post target the next pass writes
    GLuint current; // texture holding the latest image (with a box filter: the accumulated mean)
    // Box filter only: running sums (colour 0: RGB, A = sum of luminance^2)
    // and the mean image (colour 1), ping-ponged frame to frame.
    st_target accum[2];
} st_camera;

void st_camera_update(st_camera *c); // recompute matrices from pose and size

#ifdef __cplusplus
}
#endif
#endif
