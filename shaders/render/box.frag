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
  vec3 base = pass == PASS_SOLID ? SOLID_COLOUR : vec3(0.86, 0.86, 0.84);
  if (pass != PASS_SOLID && normal_world.y > 0.5) {
    ivec2 cell = ivec2(floor(position_world.xz / 0.1));
    base = ((cell.x + cell.y) & 1) == 0 ? vec3(0.62, 0.60, 0.56) : vec3(0.80, 0.78, 0.74);
  }
  vec3 n = normalize(mat3(view) * normal_world);
  // Walls take more ambient light than the fluid so that the tank reads as a bright backdrop.
  result = vec4(base * (0.55 + 0.45 * max(dot(n, light_view.xyz), 0.0)), 1.0);
}
