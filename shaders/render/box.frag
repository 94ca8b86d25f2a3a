// Floor with a 10 cm checker, light grey walls; walls between the eye and the fluid are
// left out (their inward normal points away from the eye). Obstacles: their faces
// towards the eye, in the solid colour.
flat in vec3 normal_world;
in vec3 position_world;
in vec3 position_view;
layout(location = 0) out vec4 result;

void main() {
  vec3 eye_world = -transpose(mat3(view)) * view[3].xyz;
  if (dot(normal_world, eye_world - position_world) <= 0.0) discard;
  if (pass != PASS_SOLID) {
    result = vec4(tank_surface(position_world, normal_world), 1.0);
    return;
  }
  vec3 n = normalize(mat3(view) * normal_world);
  result = vec4(SOLID_COLOUR * (0.55 + 0.45 * max(dot(n, light_view.xyz), 0.0)), 1.0);
}
