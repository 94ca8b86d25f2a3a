// White water (host/sim/solver.hpp's frame layout, after the fluid's arrays: a count, then
// room for white_capacity positions and velocities): one point sprite per particle alive (the
// count heads the frame's white water as the draw's own: white_header in host/sim/solver.hpp),
// sized by its kind (white_water.h's kinds: spray 0, foam 1, bubble 2); a slot past the count,
// were one drawn, is moved out of the clip volume.
flat out vec3 centre_view;
flat out float opacity;

void main() {
  int base = 21 * count;  // the fluid's arrays: 4 + 4 + 1 + 4 + 8 floats a particle
  int i = gl_VertexID, alive = min(floatBitsToInt(particle_data[base]), white_capacity);
  int x = base + 4 + 4 * i, v = base + 4 + 4 * (white_capacity + i);
  centre_view = (view * vec4(particle_data[x], particle_data[x + 1], particle_data[x + 2], 1.0)).xyz;
  uint kind = floatBitsToUint(particle_data[v + 3]) & 3u;
  // Spray as fine droplets, foam as wider flecks, bubbles small and faint.
  float size = kind == 0u ? 0.6 : kind == 1u ? 1.2 : 0.7;
  opacity = kind == 0u ? 0.8 : kind == 1u ? 0.6 : 0.45;
  float depth = max(-centre_view.z, 1e-6);
  gl_PointSize = max(viewport.y * proj[1][1] * size * radius / depth, 1.0);
  gl_Position = i < alive && depth > radius ? proj * vec4(centre_view, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
