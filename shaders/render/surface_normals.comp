// The fluid surface's view-space normal per surface texel, from the smoothed depth's slopes
// (each from the neighbour on the side with the smaller step, so that silhouettes do not
// smear), facing the eye; written with the texel's depth beside it for smooth_normals.comp.
// 0 where there is no fluid.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, rgba16f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D depth_texture;  // smoothed (linear depth, coverage); 0 = no fluid

float surface_depth(ivec2 p) {
  vec2 s = texelFetch(depth_texture, p, 0).rg;
  return s.g > 0.0 ? s.r / s.g : 0.0;
}

vec3 view_position(ivec2 p, float d) { return view_ray(vec2(p) + 0.5) * d; }

void main() {
  ivec2 p;
  if (!tile_texel(textureSize(depth_texture, 0), p)) return;
  float d = surface_depth(p);
  if (d <= 0.0) {
    imageStore(result, p, vec4(0.0));
    return;
  }
  vec3 pos = view_position(p, d);
  vec3 ddx = vec3(0.0), ddy = vec3(0.0);
  for (int s = -1; s <= 1; s += 2) {
    float dx = surface_depth(p + ivec2(s, 0));
    float dy = surface_depth(p + ivec2(0, s));
    vec3 ex = dx > 0.0 ? float(s) * (view_position(p + ivec2(s, 0), dx) - pos) : vec3(0.0);
    vec3 ey = dy > 0.0 ? float(s) * (view_position(p + ivec2(0, s), dy) - pos) : vec3(0.0);
    if (ddx == vec3(0.0) || (ex != vec3(0.0) && abs(ex.z) < abs(ddx.z))) ddx = ex;
    if (ddy == vec3(0.0) || (ey != vec3(0.0) && abs(ey.z) < abs(ddy.z))) ddy = ey;
  }
  vec3 n = (ddx == vec3(0.0) || ddy == vec3(0.0)) ? vec3(0.0, 0.0, 1.0) : normalize(cross(ddx, ddy));
  if (dot(n, pos) > 0.0) n = -n;
  imageStore(result, p, vec4(n, d));
}
