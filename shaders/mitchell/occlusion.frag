// Mitchell occlusion image: emitters bright, everything else black. Models
// write their emission radiance (front side, as in the regular pass); the
// clear colour is the sky; the light's disc follows (disc.frag). Depth
// testing lets every non-emitting surface occlude what lies behind it.
#include "common/uniforms.glsl"
#include "common/facet.glsl"
in vec3 v_world;
in vec3 v_normal;
uniform vec3 st_emission;
uniform int st_double_sided;
layout(location = 0) out vec4 o_color;
void main() {
    // The facet's side, as the regular pass decides it (common/facet.glsl):
    // a smooth emitter's silhouette stays bright.
    bool front = st_facet_front(v_world, v_normal, st_cam_pos) || st_double_sided != 0;
    vec3 L = front ? st_emission : vec3(0.0);
    // The blur sums up to 512 weighted taps; bounded inputs keep it finite.
    o_color = vec4(clamp(L, vec3(0.0), vec3(1e30)), 1.0);
}
