// One particle = a quad facing the eye that covers its sphere's silhouette; six
// vertices per particle from gl_VertexID, no vertex buffer.
out vec3 corner_view;
flat out vec3 centre_view;
flat out float scalar;

const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

void main() {
  int i = gl_VertexID / 6;
  vec2 c = corners[gl_VertexID % 6];
  centre_view = (view * vec4(particle_x(i), 1.0)).xyz;
  float d = length(centre_view);
  vec3 axis = centre_view / max(d, 1e-9);
  vec3 u = normalize(cross(axis, abs(axis.y) < 0.99 ? vec3(0, 1, 0) : vec3(1, 0, 0)));
  vec3 w = cross(u, axis);
  // The silhouette cone meets the plane through the centre in a circle of this radius.
  float half_size = radius * d / sqrt(max(d * d - radius * radius, 1e-12));
  corner_view = centre_view + half_size * (c.x * u + c.y * w);
  scalar = style == STYLE_DENSITY ? max(particle_rho(i) / rho0 - 1.0, 0.0) : length(particle_v(i));
  // An eye inside a sphere sees nothing of it: such a quad is moved out of the clip volume.
  gl_Position = d > radius ? proj * vec4(corner_view, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
