// Directional cascades: stores the light's path from the plane where it
// enters the scene (docs/physics.md), so receivers compare paths directly.
in vec3 v_world;
uniform vec3 u_to_light;
uniform float u_entry;
layout(location = 0) out float o_path;
void main() { o_path = u_entry - dot(v_world, u_to_light); }
