// A mesh obstacle's triangles (three corners each, in its body frame), placed by its pose
// (model) and shaded as a box obstacle is (box.frag); each triangle flat, its normal from its
// winding (outward, counter-clockwise seen from outside).
layout(std430, binding = 0) readonly buffer Corners { vec4 corner[]; };
flat out vec3 normal_world;
out vec3 position_world;
out vec3 position_view;

void main() {
  int first = gl_VertexID / 3 * 3;
  vec3 a = corner[first].xyz, b = corner[first + 1].xyz, c = corner[first + 2].xyz;
  position_world = (model * vec4(corner[gl_VertexID].xyz, 1.0)).xyz;
  normal_world = normalize(mat3(model) * cross(b - a, c - a));
  position_view = (view * vec4(position_world, 1.0)).xyz;
  gl_Position = proj * vec4(position_view, 1.0);
}
