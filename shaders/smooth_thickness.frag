// One direction of a Gaussian blur of the fluid's thickness (the summed chords through the
// spheres), sigma 1.5 particle radii on screen. The chords of a lattice's spheres rise and
// fall from column to column, and absorption turned that into stripes along the particle
// columns wherever the fluid was seen through; a surface's normals do not show them (with a
// constant thickness the stripes were gone). The blur passes the column pattern (period two
// radii) at e^-44 per direction. Outside the fluid the thickness is 0 and counts as such:
// it is an integral, and the shading reads it only where there is fluid.
layout(location = 0) out vec4 result;
layout(binding = 0) uniform sampler2D thickness_texture;
layout(binding = 1) uniform sampler2D depth_texture;  // smoothed (linear depth, coverage); 0 = no fluid
layout(location = 0) uniform ivec2 direction;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec2 s = texelFetch(depth_texture, p, 0).rg;
  if (s.g <= 0.0) {
    result = vec4(texelFetch(thickness_texture, p, 0).r, 0.0, 0.0, 1.0);
    return;
  }
  float radius_px = 0.5 * viewport.y * proj[1][1] * radius / (s.r / s.g);
  float sigma = max(1.5 * radius_px, 0.5);
  int taps = int(min(2.0 * sigma, 32.0));
  int stride = max(taps / 6, 1), samples = taps / stride;
  ivec2 size = textureSize(thickness_texture, 0);
  float sum = 0.0, weights = 0.0;
  for (int k = -samples * stride; k <= samples * stride; k += stride) {
    float w = exp(-0.5 * float(k * k) / (sigma * sigma));
    sum += w * texelFetch(thickness_texture, clamp(p + k * direction, ivec2(0), size - 1), 0).r;
    weights += w;
  }
  result = vec4(sum / weights, 0.0, 0.0, 1.0);
}
