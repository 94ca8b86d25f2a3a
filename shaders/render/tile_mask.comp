// One invocation per tile of TILE x TILE surface texels, after the splat: lists the tiles
// where a sphere was splatted (TILES_HOLDING_FLUID) and those where one was within MARGIN
// texels (TILES_NEAR_FLUID: the shading's bilinear reads and slopes reach one texel further
// each), for the passes that follow (surface_tiles.glsl). The smoothing keeps the splat's
// outline, so the lists hold for every pass.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D depth_texture;  // the splat's: NO_FLUID where no sphere was drawn

const int MARGIN = 2;

void main() {
  ivec2 size = textureSize(depth_texture, 0);
  ivec2 tile = ivec2(gl_GlobalInvocationID.xy);
  ivec2 lo = tile * TILE, hi = min(lo + TILE, size);
  if (any(greaterThanEqual(lo, size))) return;
  bool inside = false, near = false;
  for (int y = max(lo.y - MARGIN, 0); y < min(hi.y + MARGIN, size.y); ++y)
    for (int x = max(lo.x - MARGIN, 0); x < min(hi.x + MARGIN, size.x); ++x) {
      bool fluid = texelFetch(depth_texture, ivec2(x, y), 0).r < NO_FLUID;
      near = near || fluid;
      inside = inside || (fluid && x >= lo.x && x < hi.x && y >= lo.y && y < hi.y);
    }
  uint tile_bits = uint(tile.x) | uint(tile.y) << 16;
  if (inside) tile_list[2u * atomicAdd(tile_dispatch[TILES_HOLDING_FLUID].x, 1u) + TILES_HOLDING_FLUID] = tile_bits;
  if (near) tile_list[2u * atomicAdd(tile_dispatch[TILES_NEAR_FLUID].x, 1u) + TILES_NEAR_FLUID] = tile_bits;
}
