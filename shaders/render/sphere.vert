// One particle = one point sprite that covers its sphere's outline (one vertex where a
// quad took six: docs/performance.md, "Measurements behind the code").
// Obstacle spheres (PASS_SOLID) may grow past the largest point size and stay quads:
// six vertices each from gl_VertexID, no vertex buffer. The fragment shader casts its
// pixel's ray at the sphere either way.
flat out vec3 centre_view;
flat out float scalar;

const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

void main() {
  bool quad = pass == PASS_SOLID;
  int i = quad ? gl_VertexID / 6 : gl_VertexID;
  centre_view = (view * vec4(particle_x(i), 1.0)).xyz;
  scalar = style == STYLE_DENSITY ? max(particle_rho(i) / rho0 - 1.0, 0.0) : length(particle_v(i));
  float d = length(centre_view);
  // The silhouette cone meets the plane through the centre in a circle of this radius.
  float half_size = radius * d / sqrt(max(d * d - radius * radius, 1e-12));
  vec3 corner = centre_view;
  if (quad) {
    vec3 axis = centre_view / max(d, 1e-9);
    vec3 u = normalize(cross(axis, abs(axis.y) < 0.99 ? vec3(0, 1, 0) : vec3(1, 0, 0)));
    vec2 c = corners[gl_VertexID % 6];
    corner += half_size * (c.x * u + c.y * cross(u, axis));
  } else {
    // The outline's extent from the projected centre: f r / sqrt(d^2 - r^2) on the axis,
    // stretched by up to sec^2 of the angle off it, and half a pixel of margin. Every pixel
    // of the sprite runs the fragment shader, the dearest part of a frame on a CPU device: a
    // margin of a few pixels costs a frame a third more (docs/performance.md).
    float secant = d / max(-centre_view.z, 1e-9);
    float pixels = 0.5 * viewport.y * proj[1][1] * half_size / max(-centre_view.z, 1e-9) * secant * secant;
    gl_PointSize = 2.0 * pixels + 1.0;
  }
  // An eye inside a sphere sees nothing of it: it is moved out of the clip volume.
  gl_Position = d > radius ? proj * vec4(corner, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
