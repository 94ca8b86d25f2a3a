// The domain's walls and floor (seen from inside) or a box obstacle (from outside):
// 36 vertices from gl_VertexID.
flat out vec3 normal_world;
out vec3 position_world;
out vec3 position_view;

void main() {
  // Faces -x, +x, -y, +y, -z, +z, two triangles each; box.frag keeps the inner sides that face the eye.
  int face = gl_VertexID / 6, corner = gl_VertexID % 6;
  int axis = face / 2;
  float side = float(face % 2);
  const vec2 quad[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));
  vec2 q = quad[corner];
  vec3 t = axis == 0 ? vec3(side, q.x, q.y) : axis == 1 ? vec3(q.y, side, q.x) : vec3(q.x, q.y, side);
  position_world = (model * vec4(mix(domain_min.xyz, domain_max.xyz, t), 1.0)).xyz;
  vec3 n = vec3(0.0);
  n[axis] = side > 0.5 ? -1.0 : 1.0;  // inward: the tank is seen from inside
  if (pass == PASS_SOLID) n = -n;      // an obstacle from outside
  normal_world = mat3(model) * n;
  position_view = (view * vec4(position_world, 1.0)).xyz;
  gl_Position = proj * vec4(position_view, 1.0);
}
