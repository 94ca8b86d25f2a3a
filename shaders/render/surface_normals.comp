// The fluid surface's view-space normal per surface texel, from the smoothed depth's slopes,
// facing the eye; written with the texel's depth beside it for smooth_normals.comp. 0 where
// there is no fluid.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, rgba16f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D depth_texture;  // smoothed (linear depth, coverage); 0 = no fluid

float surface_depth(ivec2 p) {
  if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, textureSize(depth_texture, 0)))) return 0.0;
  vec2 s = texelFetch(depth_texture, p, 0).rg;
  return s.g > 0.0 ? s.r / s.g : 0.0;
}

vec3 view_position(ivec2 p, float d) { return view_ray(vec2(p) + 0.5) * d; }

// The surface's step to the next texel along one axis, taken on the side where the surface
// runs straight on (the smaller second difference): so that neither a crease nor a
// silhouette bends it. The side with the smaller step, taken before, gave the crease
// between the tank's top and its open side the side's slope on the top's texels. 0 where
// neither neighbour holds fluid.
vec3 tangent(ivec2 p, vec3 pos, ivec2 axis) {
  vec3 best = vec3(0.0);
  float best_bend = 1e30;
  for (int s = -1; s <= 1; s += 2) {
    ivec2 q = p + s * axis;
    float d1 = surface_depth(q);
    if (d1 <= 0.0) continue;
    vec3 e1 = float(s) * (view_position(q, d1) - pos);
    float d2 = surface_depth(q + s * axis);
    float bend = d2 > 0.0 ? length(float(s) * (view_position(q + s * axis, d2) - view_position(q, d1)) - e1) : 1e20;
    if (bend < best_bend) {
      best = e1;
      best_bend = bend;
    }
  }
  return best;
}

void main() {
  ivec2 p;
  if (!tile_texel(textureSize(depth_texture, 0), p)) return;
  float d = surface_depth(p);
  if (d <= 0.0) {
    imageStore(result, p, vec4(0.0));
    return;
  }
  vec3 pos = view_position(p, d);
  vec3 ddx = tangent(p, pos, ivec2(1, 0)), ddy = tangent(p, pos, ivec2(0, 1));
  vec3 n = (ddx == vec3(0.0) || ddy == vec3(0.0)) ? vec3(0.0, 0.0, 1.0) : normalize(cross(ddx, ddy));
  if (dot(n, pos) > 0.0) n = -n;
  imageStore(result, p, vec4(n, d));
}
