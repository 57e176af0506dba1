// Regular pass, exact primary visibility (docs/physics.md, "Primary
// visibility"). The rasteriser snaps vertices to a sub-pixel grid (8 bits
// on llvmpipe, 4 the least GL allows), so a pixel centre that close to an
// edge falls on either side of it; the CPU reference and Cycles decide by
// the exact ray. Each triangle is drawn as itself (v_exact 1) plus a ring
// ST_PRIMARY_DILATE pixels wide around it (v_exact 2), and regular.frag
// decides with the exact ray through the fragment's sample: the triangle
// drops a sample the ray clearly misses, the ring keeps one only where the
// ray clearly hits. Within float rounding of an edge (a centre exactly on
// it) the rasteriser's coverage stands: the triangle and the ring share
// its snapped edges, so every sample is claimed once. The ring's outer
// corners lie in the triangle's plane (perspective-correct barycentrics),
// so depth and attributes interpolate as before.
#include "common/uniforms.glsl"
layout(triangles) in;
layout(triangle_strip, max_vertices = 11) out;
in vec3 g_world[];
in vec3 g_normal[];
in vec2 g_uv1[];
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv1;
flat out vec3 v_tri0, v_tri1, v_tri2; // the original corners, world space
flat out int v_exact; // 0: not grown (the rasteriser decides), 1 the triangle, 2 its ring

// 1/16 pixel: well above any conforming rasteriser's snapping (GL requires
// 4 sub-pixel bits), and thin enough that the extra fragments cost nothing.
#define ST_PRIMARY_DILATE 0.0625

float st_cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }

void st_emit(vec4 clip, vec3 world, vec3 normal, vec2 uv1, int exact) {
    gl_Position = clip;
    v_world = world;
    v_normal = normal;
    v_uv1 = uv1;
    v_tri0 = g_world[0];
    v_tri1 = g_world[1];
    v_tri2 = g_world[2];
    v_exact = exact;
    gl_PrimitiveID = gl_PrimitiveIDIn; // atlas_gi's triangle table reads it
    EmitVertex();
}

void main() {
    vec4 c[3] = vec4[3](gl_in[0].gl_Position, gl_in[1].gl_Position, gl_in[2].gl_Position);
    vec2 s[3];
    bool front = true;
    for (int i = 0; i < 3; i++) {
        front = front && c[i].w > 0.0;
        s[i] = c[i].xy / c[i].w * 0.5 * st_resolution; // pixels
    }
    float area = st_cross2(s[1] - s[0], s[2] - s[0]);
    // Triangles crossing the camera plane or degenerate on screen are drawn
    // as the rasteriser covers them.
    bool grow = front && abs(area) > 1e-8;
    vec4 outc[3] = c;
    vec3 wo[3] = vec3[3](g_world[0], g_world[1], g_world[2]);
    vec3 no[3] = vec3[3](g_normal[0], g_normal[1], g_normal[2]);
    vec2 uo[3] = vec2[3](g_uv1[0], g_uv1[1], g_uv1[2]);
    if (grow) {
        float o = sign(area);
        vec2 en[3]; // outward unit normal of edge i (from corner i to i + 1)
        for (int i = 0; i < 3; i++) {
            vec2 e = s[(i + 1) % 3] - s[i];
            en[i] = o * vec2(e.y, -e.x) / max(length(e), 1e-20);
        }
        for (int j = 0; j < 3; j++) {
            vec2 na = en[(j + 2) % 3], nb = en[j];
            // Both edges at j move out by the dilation; at a very sharp
            // corner the move is capped (20x), the corner's tip stays thin.
            vec2 q = s[j] + ST_PRIMARY_DILATE * (na + nb) / max(1.0 + dot(na, nb), 0.05);
            float b1 = st_cross2(q - s[0], s[2] - s[0]) / area;
            float b2 = st_cross2(s[1] - s[0], q - s[0]) / area;
            vec3 b = vec3(1.0 - b1 - b2, b1, b2);
            vec3 m = b / vec3(c[0].w, c[1].w, c[2].w);
            float sum = m.x + m.y + m.z;
            if (!(sum > 0.0)) {
                grow = false;
                break;
            }
            m /= sum;
            // As corner 0 plus multiples of the edges: what is constant over
            // the triangle (a wall's coordinate, a flat normal) stays exactly
            // that (a light in a wall's plane must find cos = 0 there).
            outc[j] = c[0] + m.y * (c[1] - c[0]) + m.z * (c[2] - c[0]);
            wo[j] = g_world[0] + m.y * (g_world[1] - g_world[0]) + m.z * (g_world[2] - g_world[0]);
            no[j] = g_normal[0] + m.y * (g_normal[1] - g_normal[0]) +
                    m.z * (g_normal[2] - g_normal[0]);
            uo[j] = g_uv1[0] + m.y * (g_uv1[1] - g_uv1[0]) + m.z * (g_uv1[2] - g_uv1[0]);
        }
    }
    // The triangle itself, exactly as it was.
    for (int j = 0; j < 3; j++)
        st_emit(c[j], g_world[j], g_normal[j], g_uv1[j], grow ? 1 : 0);
    EndPrimitive();
    if (!grow) return;
    // The ring as one strip: outer and inner corners in turn, closed.
    for (int k = 0; k <= 3; k++) {
        int j = k % 3;
        st_emit(outc[j], wo[j], no[j], uo[j], 2);
        st_emit(c[j], g_world[j], g_normal[j], g_uv1[j], 2);
    }
    EndPrimitive();
}
