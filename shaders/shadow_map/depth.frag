// Stores the Euclidean distance to the light: one value serves every face
// and the lookup needs no per-face projection.
in vec3 v_world;
uniform vec3 u_light_pos;
layout(location = 0) out float o_dist;
void main() { o_dist = distance(v_world, u_light_pos); }
