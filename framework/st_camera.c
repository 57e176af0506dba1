#include "st_camera.h"
#include <cglm/cglm.h>
#include <string.h>

void st_camera_update(st_camera *c) {
    mat4 view, proj, vp, inv;
    vec3 pos, tgt, up;
    memcpy(pos, c->position, sizeof pos);
    memcpy(tgt, c->target, sizeof tgt);
    memcpy(up, c->up, sizeof up);
    glm_lookat(pos, tgt, up, view);
    float aspect = c->height > 0 ? (float)c->width / (float)c->height : 1.0f;
    glm_perspective(glm_rad(c->fov_y), aspect, c->near_z, c->far_z, proj);
    glm_mat4_mul(proj, view, vp);
    glm_mat4_inv(vp, inv);
    memcpy(c->view, view, sizeof c->view);
    memcpy(c->proj, proj, sizeof c->proj);
    memcpy(c->view_proj, vp, sizeof c->view_proj);
    memcpy(c->inv_view_proj, inv, sizeof c->inv_view_proj);
}
