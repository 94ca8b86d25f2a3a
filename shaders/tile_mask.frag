// One texel per tile of TILE x TILE surface texels (render_common.glsl), drawn once a
// frame after the splat: r = 1 where a sphere was splatted into the tile, g = 1 where one
// was within MARGIN texels of it (the shading's bilinear reads and slopes reach one texel
// further each). The smoothing (r) and the shading (g) run on the marked tiles
// (surface_tiles.vert); the smoothing keeps the splat's outline, so the marks hold for
// every round.
layout(location = 0) out vec4 result;
layout(binding = 0) uniform sampler2D depth_texture;  // the splat's: NO_FLUID where no sphere was drawn

const int MARGIN = 2;

void main() {
  ivec2 size = textureSize(depth_texture, 0);
  ivec2 lo = ivec2(gl_FragCoord.xy) * TILE, hi = min(lo + TILE, size);
  bool inside = false, near = false;
  for (int y = max(lo.y - MARGIN, 0); y < min(hi.y + MARGIN, size.y); ++y)
    for (int x = max(lo.x - MARGIN, 0); x < min(hi.x + MARGIN, size.x); ++x) {
      bool fluid = texelFetch(depth_texture, ivec2(x, y), 0).r < NO_FLUID;
      near = near || fluid;
      inside = inside || (fluid && x >= lo.x && x < hi.x && y >= lo.y && y < hi.y);
    }
  result = vec4(inside ? 1.0 : 0.0, near ? 1.0 : 0.0, 0.0, 1.0);
}
