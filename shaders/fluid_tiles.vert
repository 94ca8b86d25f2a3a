// The fluid's shading runs on the tiles of the image that the fluid may touch, not on the
// whole image: llvmpipe runs both sides of a fragment shader's branch for every pixel, so
// a full-screen pass cost as much on the tank, most of the image, as on the fluid (a dam
// break at 720p: 20 ms, 16 of them spent where the tank shows). One point sprite per tile of TILE x TILE surface texels; a tile whose texels,
// and a margin for the shading's bilinear reads and slopes, hold no fluid is moved out of
// the clip volume. The tank's image, copied beforehand, shows everywhere else.
layout(binding = 1) uniform sampler2D depth_texture;  // smoothed (linear depth, coverage)

const int TILE = 8;
const int MARGIN = 2;  // a pixel's bilinear read and its slopes' reach one texel further each

void main() {
  ivec2 size = textureSize(depth_texture, 0);
  int tiles_x = (size.x + TILE - 1) / TILE;
  ivec2 tile = ivec2(gl_VertexID % tiles_x, gl_VertexID / tiles_x);
  ivec2 lo = max(tile * TILE - MARGIN, ivec2(0)), hi = min(tile * TILE + TILE + MARGIN, size);
  bool fluid = false;
  for (int y = lo.y; y < hi.y; ++y)
    for (int x = lo.x; x < hi.x; ++x) fluid = fluid || texelFetch(depth_texture, ivec2(x, y), 0).g > 0.0;
  // The tile's pixels, a pixel more on each side so that tiles of a fractional size leave
  // no gaps; kept inside the image, since a point whose centre leaves it is clipped.
  vec2 scale = viewport / vec2(size);
  float side = ceil(float(TILE) * max(scale.x, scale.y)) + 2.0;
  vec2 centre = (vec2(tile * TILE) + 0.5 * float(TILE)) * scale;
  centre = min(max(centre, vec2(0.5 * side)), max(viewport - 0.5 * side, vec2(0.5 * side)));
  gl_PointSize = side;
  gl_Position = fluid ? vec4(centre / viewport * 2.0 - 1.0, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
