// Prepended to the fluid surface's compute passes (capture/gl_objects.cpp). They run on
// the tiles of TILE x TILE surface texels that hold fluid or lie near it, one workgroup a
// tile, from the lists that tile_mask.comp writes: the tank, most of the image, costs
// nothing (when every texel ran, it was most of the shading: docs/performance.md).
const int TILES_HOLDING_FLUID = 0;  // the smoothing's tiles
const int TILES_NEAR_FLUID = 1;     // and those within a margin of them: the shading's

layout(std430, binding = 1) buffer Tiles {
  uvec4 tile_dispatch[2];  // per list, the indirect dispatch (tiles, 1, 1, unused)
  uint tile_list[];        // the two lists interleaved: list k's n-th tile at 2 n + k, x | y << 16
};
layout(location = 1) uniform int tile_kind;  // the list this dispatch runs on

ivec2 group_tile() {
  uint t = tile_list[2u * gl_WorkGroupID.x + uint(tile_kind)];
  return ivec2(t & 0xffffu, t >> 16);
}

// The invocation's surface texel p, in a workgroup of TILE x TILE on the group's tile; false
// past the surface's edge (`size`), which a tile at the border reaches over.
bool tile_texel(ivec2 size, out ivec2 p) {
  p = group_tile() * TILE + ivec2(gl_LocalInvocationID.xy);
  return all(lessThan(p, size));
}
