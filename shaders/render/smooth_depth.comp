// One direction of a separable bilateral filter on linear eye depth: smooths the
// bumps of the sphere splats into a surface while keeping silhouettes (depth jumps)
// sharp. Runs at the surface's size (Renderer's surface_divisor). Reads linear depth, 0
// where there is no fluid (the x pass fill_pits.comp's, the y pass the x pass's); writes
// (depth, coverage 1) where there is fluid, 0 elsewhere.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, rg32f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D depth_texture;
layout(location = 0) uniform ivec2 direction;

bool fluid(float d) { return d > 0.0; }

void main() {
  ivec2 size = textureSize(depth_texture, 0), p;
  if (!tile_texel(size, p)) return;
  float d0 = texelFetch(depth_texture, p, 0).r;
  if (!fluid(d0)) {
    imageStore(result, p, vec4(0.0));
    return;
  }
  // The filter spans about two and a half particle radii on screen: it takes the splats'
  // bumps out (a particle spacing apart) and no more; wider, it rounds the fluid's edges and
  // tilts its faces (the rest is left to smooth_normals.comp). It weighs samples in pairs,
  // one each side, by how far the pair's mean lies from the centre: a sloped face (the tank's
  // top seen at a grazing angle) passes whole, as a plane's pairs average to its centre,
  // while a depth jump on either side drops the pair. Weighed one by one, the far samples
  // on the side that runs away from the eye counted less than the near ones, and the tank's
  // whole top leaned 3 degrees towards the eye. A pair that leaves the fluid ends the filter
  // there, so that an outline's one-sided mean bends nothing. It reads every texel up to 16
  // a side: read sparser, the rows of a face seen at a grazing angle (a radius apart on
  // screen) aliased into bands.
  float radius_px = 0.5 * viewport.y * proj[1][1] * radius / d0;
  int taps = int(clamp(2.5 * radius_px, 1.0, 32.0));
  float sigma = max(float(taps) / 2.0, 0.5);
  int stride = max(taps / 16, 1), samples = taps / stride;
  float depth_sigma = 2.0 * radius;
  float sum = d0, weights = 1.0;
  for (int s = 1; s <= samples; ++s) {
    int k = s * stride;
    float a = texelFetch(depth_texture, clamp(p - k * direction, ivec2(0), size - 1), 0).r;
    float b = texelFetch(depth_texture, clamp(p + k * direction, ivec2(0), size - 1), 0).r;
    if (!fluid(a) || !fluid(b)) break;
    float dd = (0.5 * (a + b) - d0) / depth_sigma;
    float w = exp(-0.5 * float(k * k) / (sigma * sigma) - 0.5 * dd * dd);
    sum += w * (a + b);
    weights += 2.0 * w;
  }
  imageStore(result, p, vec4(sum / weights, 1.0, 0.0, 0.0));
}
