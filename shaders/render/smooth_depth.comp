// One direction of a separable bilateral filter on linear eye depth: smooths the
// bumps of the sphere splats into a surface while keeping silhouettes (depth jumps)
// sharp. Runs at the surface's size (Renderer's surface_divisor). Reads linear depth
// (the first round: NO_FLUID where no sphere was drawn; later rounds: 0); writes (depth,
// coverage 1) where there is fluid, 0 elsewhere.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, rg32f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D depth_texture;
layout(location = 0) uniform ivec2 direction;

bool fluid(float d) { return d > 0.0 && d < NO_FLUID; }

void main() {
  ivec2 size = textureSize(depth_texture, 0), p;
  if (!tile_texel(size, p)) return;
  float d0 = texelFetch(depth_texture, p, 0).r;
  if (!fluid(d0)) {
    imageStore(result, p, vec4(0.0));
    return;
  }
  // The filter spans about two particle radii on screen (sigma one radius), at most 32
  // pixels: it takes the splats' bumps out (a particle spacing apart, passed at e^-5 per
  // direction) and no more. Wider, or run more than once, it rounded the fluid's edges and
  // tilted its faces: the settled tank's top read 36 degrees (95th percentile) off +y at
  // three radii thrice, 9 at two radii once, the rest left to smooth_normals.comp. It
  // reads every stride-th pixel, half a sigma apart, at most 9 pixels a pass.
  float radius_px = 0.5 * viewport.y * proj[1][1] * radius / d0;
  int taps = int(clamp(2.0 * radius_px, 1.0, 32.0));
  float sigma = max(float(taps) / 2.0, 0.5);
  int stride = max(taps / 4, 1), samples = taps / stride;
  float depth_sigma = 2.0 * radius;
  float sum = 0.0, weights = 0.0;
  for (int s = -samples; s <= samples; ++s) {
    int k = s * stride;
    ivec2 q = clamp(p + k * direction, ivec2(0), size - 1);
    float d = texelFetch(depth_texture, q, 0).r;
    if (!fluid(d)) continue;
    float dd = (d - d0) / depth_sigma;
    float w = exp(-0.5 * float(k * k) / (sigma * sigma) - 0.5 * dd * dd);
    sum += w * d;
    weights += w;
  }
  imageStore(result, p, vec4(sum / weights, 1.0, 0.0, 0.0));
}
