// The splat's depth with its pits filled, before smoothing. Where the spheres are many
// texels wide, the gaps between a layer's spheres (a square lattice's are 0.4 radii across)
// show the layer behind, a spacing deeper; smoothed, those pits dented the surface (the
// settled tank at 720p read 5.2 degrees at the 95th percentile on its open side and 6.6 on
// its top without the filling, 3.1 and 5.7 with it). A texel is a pit where, along one of four
// directions, the surface within 0.6 particle radii on screen is nearer by half a radius on
// both sides; it takes the depth of the deeper of those two rims, the shallowest such bridge
// over the directions. So a groove between two rows is bridged too, as the seam down the
// drop's middle (its start's mirror plane). Two directions were asked for while the tank's
// last row against a wall stood low and one bridged it (the top 5.6 degrees against 4.8); with
// that row level one direction leaves the tank's top as it was (2.6 degrees at 640x360, 3.3 at
// 720p) and its open side at 1.1 (1.3 with two, 720p). A face seen at a grazing angle is no pit
// (along it one side lies deeper), nor is the far side of an outline (one side holds nothing
// or lies nearer only on that side). Writes 0 where no sphere was drawn.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, r32f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D depth_texture;  // the splat's: NO_FLUID where no sphere was drawn

const float PIT_DEPTH = 0.5;  // in particle radii
const float PIT_REACH = 0.6;  // how far from a pit its rims may lie, in particle radii on screen

bool fluid(float d) { return d < NO_FLUID; }

// The depth of the first texel from p along dir, within reach, nearer than `level`; NO_FLUID if none.
float rim(ivec2 p, ivec2 dir, int reach, float level) {
  for (int k = 1; k <= reach; ++k) {
    float d = texelFetch(depth_texture, clamp(p + k * dir, ivec2(0), textureSize(depth_texture, 0) - 1), 0).r;
    if (d < level) return d;
  }
  return NO_FLUID;
}

void main() {
  ivec2 size = textureSize(depth_texture, 0), p;
  if (!tile_texel(size, p)) return;
  float d0 = texelFetch(depth_texture, p, 0).r;
  if (!fluid(d0)) {
    imageStore(result, p, vec4(0.0));
    return;
  }
  float radius_px = 0.5 * viewport.y * proj[1][1] * radius / d0;
  int reach = max(int(PIT_REACH * radius_px), 1);
  float level = d0 - PIT_DEPTH * radius, bridge = NO_FLUID;
  const ivec2 directions[4] = ivec2[](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
  for (int i = 0; i < 4; ++i) {
    float a = rim(p, -directions[i], reach, level);
    if (!fluid(a)) continue;
    float b = rim(p, directions[i], reach, level);
    if (fluid(b)) bridge = min(bridge, max(a, b));
  }
  imageStore(result, p, vec4(fluid(bridge) ? bridge : d0));
}
