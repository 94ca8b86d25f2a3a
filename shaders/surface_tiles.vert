// The fluid's smoothing and shading run on the tiles of the surface that hold fluid, not
// on the whole image: llvmpipe runs both sides of a fragment shader's branch for every
// pixel, so a full-screen pass cost as much on the tank, most of the image, as on the
// fluid (a dam break at 720p: the shading 20 ms, 16 of them where the tank shows).
// One point sprite per tile of TILE x TILE surface texels (render_common.glsl), drawn where
// tile_mask.frag marked the tile in the pass's channel; moved out of the clip volume
// elsewhere, where the pass's target keeps what it held.
layout(binding = 4) uniform sampler2D tile_mask;  // tile_mask.frag
layout(location = 1) uniform int mask_channel;    // 0: fluid in the tile (smoothing); 1: within a margin (shading)
layout(location = 2) uniform vec2 tile_scale;     // the pass's pixels per surface texel

void main() {
  ivec2 tiles = textureSize(tile_mask, 0);
  ivec2 tile = ivec2(gl_VertexID % tiles.x, gl_VertexID / tiles.x);
  bool fluid = texelFetch(tile_mask, tile, 0)[mask_channel] > 0.0;
  // The tile's pixels: where a texel spans a fractional number of pixels, a pixel more on
  // each side, so that the tiles leave no gaps; kept inside the viewport, since a point
  // whose centre leaves it is clipped.
  float side = ceil(float(TILE) * max(tile_scale.x, tile_scale.y)) + (tile_scale == floor(tile_scale) ? 0.0 : 2.0);
  vec2 centre = (vec2(tile * TILE) + 0.5 * float(TILE)) * tile_scale;
  centre = min(max(centre, vec2(0.5 * side)), max(viewport - 0.5 * side, vec2(0.5 * side)));
  gl_PointSize = side;
  gl_Position = fluid ? vec4(centre / viewport * 2.0 - 1.0, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
