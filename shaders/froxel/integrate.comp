// froxel pass 2: each column front to back (Hillaire 2015). A slice of
// length dt on the column's ray, source S and extinction sigma_t = density
// (sigma_s + sigma_a) adds T S (1 - e^(-sigma_t dt)) / sigma_t (the
// energy-conserving step of docs/physics.md, exact for a constant source);
// T carries e^(-optical depth). Layer k stores the in-scattered radiance
// from the camera to the slice's end and the optical depth in density
// metres (the transmittance is e^(-(sigma_s + sigma_a) tau) per channel).
#include "common/uniforms.glsl"
#include "common/medium.glsl"
#include "froxel/grid.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
// The world binds the target the pass writes at unit 0.
layout(rgba32f, binding = 0) uniform writeonly image2DArray froxel_integrated_img;
layout(rgba32f, binding = 1) uniform readonly image2DArray froxel_inject_img;

void main() {
    ivec2 col = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(col, froxel_grid.xy))) return;
    float c = froxel_cos(froxel_column_dir(col));
    vec3 sigma_t = st_medium_sigma_t();
    float n = float(froxel_grid.z);
    vec3 L = vec3(0.0);
    float tau = 0.0, z0 = 0.0;
    for (int k = 0; k < froxel_grid.z; k++) {
        float z1 = froxel_depth(float(k + 1) / n);
        float dt = (z1 - z0) / c;
        vec4 v = imageLoad(froxel_inject_img, ivec3(col, k));
        L += exp(-sigma_t * tau) * st_step_inscatter(v.rgb, v.a * sigma_t, dt);
        tau += v.a * dt;
        imageStore(froxel_integrated_img, ivec3(col, k), vec4(L, tau));
        z0 = z1;
    }
}
