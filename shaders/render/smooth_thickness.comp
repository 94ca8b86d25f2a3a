// One direction of a Gaussian blur of the fluid's thickness (the summed chords through the
// spheres), sigma 1.5 particle radii on screen. The chords of a lattice's spheres rise and
// fall from column to column, and absorption turned that into stripes along the particle
// columns wherever the fluid was seen through; a surface's normals do not show them (with a
// constant thickness the stripes were gone). The blur passes the column pattern (period two
// radii) at e^-44 per direction. Outside the fluid the thickness is 0 and counts as such:
// it is an integral, and the shading reads it only where there is fluid.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, r32f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform usampler2D chord_sum;  // the splat's, in CHORD_UNIT: the x pass reads it
layout(binding = 6) uniform sampler2D blurred_x;   // the x pass's result: the y pass reads it
layout(binding = 1) uniform sampler2D depth_texture;  // smoothed (linear depth, coverage); 0 = no fluid
layout(location = 0) uniform ivec2 direction;

float thickness(ivec2 q) {
  return direction.x == 1 ? CHORD_UNIT * float(texelFetch(chord_sum, q, 0).r) : texelFetch(blurred_x, q, 0).r;
}

void main() {
  ivec2 size = textureSize(depth_texture, 0), p;
  if (!tile_texel(size, p)) return;
  vec2 s = texelFetch(depth_texture, p, 0).rg;
  if (s.g <= 0.0) {
    imageStore(result, p, vec4(thickness(p)));
    return;
  }
  float radius_px = 0.5 * viewport.y * proj[1][1] * radius / (s.r / s.g);
  float sigma = max(1.5 * radius_px, 0.5);
  int taps = int(min(2.0 * sigma, 32.0));
  int stride = max(taps / 6, 1), samples = taps / stride;
  float sum = 0.0, weights = 0.0;
  for (int k = -samples * stride; k <= samples * stride; k += stride) {
    float w = exp(-0.5 * float(k * k) / (sigma * sigma));
    sum += w * thickness(clamp(p + k * direction, ivec2(0), size - 1));
    weights += w;
  }
  imageStore(result, p, vec4(sum / weights));
}
