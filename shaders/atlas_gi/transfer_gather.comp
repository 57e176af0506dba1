// Precomputed transfer, step 2 of a relight: per chunk of one receiver's
// links the sum of w/A_s times the sender node's flux (its area-weighted
// mean radiance times w), attenuated by the medium along the segment
// between the two nodes' centroids (per channel), and the same sum weighted
// by each link's gradient factor along the receiver's tangents: the
// gathered value's derivatives, which remove the steps between
// neighbouring receiver nodes. Everything but the sender's flux was
// computed at upload.
#include "atlas_gi/transfer.glsl"
#include "common/medium.glsl"
layout(local_size_x = 64) in;
uniform int ag_num_chunks; // link j of chunk c is at j ag_num_chunks + c (transfer_gpu.c)

// Two halves (no inf/NaN) to floats with integer and float vector ops: the
// exponent rebias as one multiply by 2^112 also covers subnormals. llvmpipe
// runs unpackHalf2x16 lane by lane.
vec2 ag_halves(uint h) {
    uvec2 v = uvec2(h & 0xffffu, h >> 16);
    vec2 m = uintBitsToFloat((v & 0x7fffu) << 13) * 5.192296858534828e+33;
    return uintBitsToFloat(floatBitsToUint(m) | ((v & 0x8000u) << 16));
}

void main() {
    int c = int(gl_GlobalInvocationID.x); // every chunk is real or weight-0 padding
    vec3 sum = vec3(0.0), g1 = vec3(0.0), g2 = vec3(0.0);
#ifdef AG_MEDIUM
    vec3 cr = texelFetch(ag_nodes_tex, 4 * int(texelFetch(ag_chunk_recv_tex, c).r)).xyz;
#endif
    for (int j = 0; j < AG_CHUNK; j++) { // the same trip count in every lane
        uvec4 l = texelFetch(ag_links_tex, j * ag_num_chunks + c);
        vec3 wl = uintBitsToFloat(l.y) * texelFetch(ag_flux_tex, int(l.x)).rgb;
        vec2 g = uintBitsToFloat(l.zw);
#ifdef AG_MEDIUM // a variant: llvmpipe runs both sides of a branch in a loop
        wl *= st_path_transmittance(distance(cr, texelFetch(ag_nodes_tex, 4 * int(l.x)).xyz));
#endif
        sum += wl;
        g1 += wl * g.x;
        g2 += wl * g.y;
    }
    int o = 3 * c;
    ag_partial[o] = vec4(sum, 0.0);
    ag_partial[o + 1] = vec4(g1, 0.0);
    ag_partial[o + 2] = vec4(g2, 0.0);
}
