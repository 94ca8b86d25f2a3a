// One direction of a separable filter on the surface's normals (surface_normals.comp): a
// wide Gaussian that averages only the normals of the same surface. The depth filter
// (smooth_depth.comp) takes out the spheres' bumps at the particle's scale; what it leaves
// is the fluid's own roughness, a few degrees between particle columns, which a depth
// filter wide enough to remove it would round the fluid's edges with. Here a sample counts
// only where it lies on the centre's tangent plane (within two radii along the ray: not a
// layer behind or in front) and its normal is near the filter's answer (weight
// exp(-(1 - cos)/s), a tenth at 35 degrees): across an edge between two faces, or a crest,
// nothing mixes. The answer is sought in two rounds, the second weighing the samples by
// their likeness to the first round's mean, more sharply (a step of mean shift): near a
// crease the first mean still leans towards the crease's rounded texels, the second goes to
// the normal that most samples share, the face's own (the settled tank's top read 5.2
// degrees at the 95th percentile in one round, 4.8 in two alike, 4.1-4.3 with the second
// sharper over half the reach; docs/rendering.md).
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, rgba16f) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D normal_texture;  // (view-space normal, linear depth); 0 = no fluid
layout(location = 0) uniform ivec2 direction;

// 1 - cos of the normals' difference at weight 1/e, in the first round (~23 degrees) and the
// second (~11 degrees: it picks the mode the first round leans to).
const float SIMILARITY[2] = float[](0.08, 0.02);
const float SPAN = 12.0;  // the filter's reach, in particle radii on screen

void main() {
  ivec2 size = textureSize(normal_texture, 0), p;
  if (!tile_texel(size, p)) return;
  vec4 c = texelFetch(normal_texture, p, 0);
  if (c.w <= 0.0) {
    imageStore(result, p, vec4(0.0));
    return;
  }
  vec3 n0 = c.xyz, p0 = view_ray(vec2(p) + 0.5) * c.w;
  float radius_px = 0.5 * viewport.y * proj[1][1] * radius / c.w;
  int taps = int(clamp(SPAN * radius_px, 1.0, 48.0));
  float sigma = max(float(taps) / 2.0, 0.5);
  int stride = max(taps / 8, 1), samples = taps / stride;
  vec3 n = n0;
  for (int round = 0; round < 2; ++round) {
    vec3 sum = 1e-6 * n0;
    int reach = round == 0 ? samples : samples / 2;
    for (int s = -reach; s <= reach; ++s) {
      int k = s * stride;
      ivec2 q = clamp(p + k * direction, ivec2(0), size - 1);
      vec4 e = texelFetch(normal_texture, q, 0);
      if (e.w <= 0.0) continue;
      float facing = dot(n0, view_ray(vec2(q) + 0.5));
      if (abs(facing) < 1e-4) continue;  // the plane seen edge-on along this ray
      float on_plane = dot(n0, p0) / facing;  // the centre's tangent plane's depth along q's ray
      if (abs(e.w - on_plane) > 2.0 * radius) continue;
      sum += exp(-0.5 * float(k * k) / (sigma * sigma) - (1.0 - dot(e.xyz, n)) / SIMILARITY[round]) * e.xyz;
    }
    n = normalize(sum);
  }
  imageStore(result, p, vec4(n, c.w));
}
