// atlas_gi in the regular pass: the indirect radiance of the surface point,
// looked up in the atlas at the point's atlas uv, and the display modes.
// A generated atlas splits vertices along chart borders, which the world's
// vertex buffer does not, so the uv comes from a triangle table: the
// fragment's triangle (st_model_index, gl_PrimitiveID) and that triangle's
// affine map from world to atlas. With TEXCOORD_1 the interpolated uv1 is
// the atlas uv.
#ifndef AG_REGULAR_GLSL
#define AG_REGULAR_GLSL
#include "common/uniforms.glsl"
#include "common/facet.glsl"
#define ST_HAS_INDIRECT 1
#define ST_HAS_COMPOSE 1
uniform sampler2D ag_indirect_tex; // mean indirect, dilated
uniform sampler2D ag_combined_tex; // direct + emission + indirect of the atlas, dilated
uniform samplerBuffer ag_tri_tex;  // 3 texels per triangle: atlas.lookup (modules/atlas_gi/atlas.h)
uniform isamplerBuffer ag_base_tex; // per scene mesh: first front, first back triangle (-1)
uniform int ag_lookup;  // 0: uv1 is the atlas uv, 1: triangle table
uniform int ag_display; // 0 combined, 1 direct, 2 indirect, 3 atlas
uniform int st_model_index;

vec2 ag_atlas_uv(vec3 p, vec3 n, vec2 uv1) {
    if (ag_lookup == 0) return uv1;
    ivec2 base = texelFetch(ag_base_tex, st_model_index).xy;
    int tri = base.x + gl_PrimitiveID;
    vec4 a = texelFetch(ag_tri_tex, 3 * tri), gu = texelFetch(ag_tri_tex, 3 * tri + 1);
    vec4 gv = texelFetch(ag_tri_tex, 3 * tri + 2);
    // Double-sided: the side the (already flipped) normal is on has its own
    // texels; gu x gv points to the front of the side a table entry maps.
    if (base.y >= 0 && dot(cross(gu.xyz, gv.xyz), n) < 0.0) {
        tri = base.y + gl_PrimitiveID;
        a = texelFetch(ag_tri_tex, 3 * tri);
        gu = texelFetch(ag_tri_tex, 3 * tri + 1);
        gv = texelFetch(ag_tri_tex, 3 * tri + 2);
    }
    vec3 q = p - a.xyz;
    return vec2(a.w, gu.w) + vec2(dot(q, gu.xyz), dot(q, gv.xyz));
}

vec3 st_indirect(vec3 p, vec3 n, vec2 uv1) {
    if (ag_display == 1) return vec3(0.0);
    return texture(ag_indirect_tex, ag_atlas_uv(p, n, uv1)).rgb;
}

vec3 st_compose(vec3 direct, vec3 emission, vec3 indirect, vec3 p, vec3 n, vec2 uv1) {
    if (ag_display == 1) return direct + emission;
    if (ag_display == 2) return indirect;
    if (ag_display == 3) {
        // The thesis' display: the combined atlas textured onto the scene,
        // on the side the camera sees (the facet's side, as the regular pass
        // decides it: the interpolated normal turns away at a silhouette).
        bool front = st_facet_front(p, n, st_cam_pos);
        return front ? texture(ag_combined_tex, ag_atlas_uv(p, n, uv1)).rgb : vec3(0.0);
    }
    return direct + emission + indirect;
}

// What the camera sees (times the view ray's transmittance in the regular
// pass): every display but indirect, which is the surface AOV the reference's
// --aov indirect gives (direct is the image without atlas_gi, as a plain
// render shows it).
bool st_compose_viewed() { return ag_display != 2; }
#endif
