// Precomputed transfer, step 2: per receiver node the sum over its links of
// w times the sender node's area-weighted mean radiance, attenuated by the
// medium along the segment between the two nodes' centroids (per channel).
// Also the sum's gradient with respect to the receiver point: per link
// grad ln(cos_x cos_j / d^2) at the centroids (receiver nodes are flat),
// which removes the steps between neighbouring receiver nodes.
#include "atlas_gi/transfer.glsl"
#include "common/medium.glsl"
layout(local_size_x = 64) in;
uniform int ag_num_nodes;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= ag_num_nodes) return;
    uint b = ag_link_off[i], e = ag_link_off[i + 1];
    vec3 sum = vec3(0.0), gx = vec3(0.0), gy = vec3(0.0), gz = vec3(0.0);
    bool medium = st_has_medium != 0;
    vec3 c = ag_nodes[i].ca.xyz, nr = ag_nodes[i].nc.xyz;
    bool flat_r = ag_nodes[i].nc.w > 0.9; // the first-order correction needs one receiver plane
    for (uint k = b; k < e; k++) {
        uvec2 l = ag_links[k];
        int s = int(l.x);
        vec4 sa = ag_nodes[s].ca;
        vec3 L = ag_flux[s].rgb / sa.w;
        float w = uintBitsToFloat(l.y);
        if (medium) L *= st_path_transmittance(distance(c, sa.xyz)); // sender -> receiver
        vec3 wl = w * L;
        sum += wl;
        // grad_x ln k, k = (nr.d)(-ns.d)/|d|^4, d = y - x; terms whose cosine
        // is not well defined (a curved sender node) are left out.
        if (!flat_r) continue;
        vec3 d = sa.xyz - c;
        float d2 = max(dot(d, d), 1e-12);
        vec3 g = 4.0 * d / d2;
        float cr = dot(nr, d);
        if (cr > 1e-3 * sqrt(d2)) g -= nr / cr;
        vec4 ns = ag_nodes[s].nc;
        float cs = -dot(ns.xyz, d);
        if (ns.w > 0.9 && cs > 0.2 * sqrt(d2)) g += ns.xyz / cs;
        gx += wl * g.x;
        gy += wl * g.y;
        gz += wl * g.z;
    }
    int o = 4 * i;
    ag_gathered[o] = vec4(sum, 0.0);
    ag_gathered[o + 1] = vec4(gx, 0.0);
    ag_gathered[o + 2] = vec4(gy, 0.0);
    ag_gathered[o + 3] = vec4(gz, 0.0);
}
