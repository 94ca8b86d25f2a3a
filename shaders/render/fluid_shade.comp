// Screen-space fluid: a surface from the smoothed depth, normals from its slopes smoothed
// along the surface (surface_normals.comp, smooth_normals.comp),
// Fresnel mix of the surroundings' reflection (the tank's walls and floor, the sky: traced,
// render_common.glsl) and the scene refracted by Snell's law and absorbed through the
// fluid's thickness, and a specular highlight. Written on the tiles that the fluid may
// touch (TILES_NEAR_FLUID, surface_tiles.glsl) over a copy of the tank's image, at the
// image's size: a tile's workgroup covers the image pixels of its surface texels.
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(binding = 0, rgba8) uniform restrict writeonly image2D result;
layout(binding = 0) uniform sampler2D scene_texture;
// Both at the surface's size, read bilinearly at the image's.
layout(binding = 1) uniform sampler2D depth_texture;      // smoothed (linear depth, coverage); 0 = no fluid
layout(binding = 2) uniform sampler2D thickness_texture;  // summed chord lengths, m
layout(binding = 3) uniform sampler2D scene_depth;        // the tank's and obstacles' depth buffer
layout(binding = 5) uniform sampler2D normal_texture;     // smoothed view-space normals, at the surface's size
layout(location = 2) uniform vec2 tile_scale;             // image pixels per surface texel

// The surface's depth seen through pixel p: the covered texels' depths blended, 0 where
// they cover under half of it (the silhouette falls between texels, not on their grid).
float surface_depth(ivec2 p) {
  vec2 s = texture(depth_texture, (vec2(p) + 0.5) / viewport).rg;
  return s.g >= 0.5 ? s.r / s.g : 0.0;
}

// The tank's and obstacles' linear eye depth at pixel p.
float tank_depth(ivec2 p) {
  float z_ndc = 2.0 * texelFetch(scene_depth, p, 0).r - 1.0;
  return proj[3][2] / (z_ndc + proj[2][2]);
}

vec3 view_position(ivec2 p, float d) { return view_ray(vec2(p) + 0.5) * d; }

// The surface's normal at a pixel: read bilinearly (the texels without fluid hold 0 and add
// nothing to the direction), except where the blend parts from the nearest texel's normal by
// more than CREASE, at a crease: there the nearest texel's. Blended across the crease between
// two faces, the normals turned through the half-way direction of light and eye, and the
// highlight drew a bright line along the water's edges (the dam break's front bottom edge).
const float CREASE = 0.985;  // the cosine, 10 degrees
vec3 surface_normal(vec2 uv) {
  vec3 blended = texture(normal_texture, uv).xyz;
  if (dot(blended, blended) <= 1e-6) return vec3(0.0, 0.0, 1.0);
  vec3 n = normalize(blended);
  ivec2 size = textureSize(normal_texture, 0);
  vec3 nearest = texelFetch(normal_texture, min(ivec2(uv * vec2(size)), size - 1), 0).xyz;
  return dot(nearest, nearest) > 1e-6 && dot(nearest, n) < CREASE * length(nearest) ? normalize(nearest) : n;
}

// Where the tank image shows what is seen through the surface at view point `pos` (normal n):
// the view ray bends by Snell's law (water's index 1.33) and crosses the water as through a
// slab of the depth its path implies (the summed chords over the spheres' packing fraction,
// pi/6 for spheres of half a spacing on a lattice), leaves it parallel to the view ray again,
// and meets the tank; that point, projected, is the image's point. Where the bent ray leaves
// the tank inside the water (a still tank: at the floor), that exit is the point.
const float WATER_INDEX = 1.33;
const float PACKING = 0.5236;
vec2 refracted_uv(vec3 pos, vec3 n, float thickness) {
  vec3 v = world_direction(normalize(pos)), nw = world_direction(n);
  vec3 r = refract(v, nw, 1.0 / WATER_INDEX);
  vec3 s = world_position(pos);
  vec3 unused;
  vec3 seen;
  if (dot(r, r) == 0.0) {
    seen = s + v * tank_exit(s, v, unused);
  } else {
    float depth = thickness / PACKING * abs(dot(v, nw));  // the slab's depth along the normal
    float inside = depth / max(abs(dot(r, nw)), 0.2);
    float to_tank = tank_exit(s, r, unused);
    vec3 out_of_water = s + r * min(inside, to_tank);
    seen = inside >= to_tank ? out_of_water : out_of_water + v * tank_exit(out_of_water, v, unused);
  }
  vec4 clip = proj * view * vec4(seen, 1.0);
  return clamp(clip.xy / clip.w * 0.5 + 0.5, vec2(0.0), vec2(1.0));
}

vec3 shade(ivec2 p) {
  vec2 uv = (vec2(p) + 0.5) / viewport;
  vec3 background = texelFetch(scene_texture, p, 0).rgb;
  float d = surface_depth(p);
  // The tank shows where there is no fluid (most of the image, which reads nothing more)
  // and where a surface texel straddling an obstacle's outline lies behind the obstacle
  // (by more than a particle radius, the smoothing's slack).
  if (d <= 0.0 || d > tank_depth(p) + radius) return background;
  vec3 pos = view_position(p, d);
  vec3 n = surface_normal(uv);
  vec3 eye_dir = normalize(-pos);
  if (dot(n, eye_dir) < 0.0) n = -n;
  if (style == STYLE_NORMALS)  // in the tank's frame
    return 0.5 * normalize(world_direction(n)) + 0.5;

  float thickness = texture(thickness_texture, uv).r;
  vec3 behind = texture(scene_texture, refracted_uv(pos, n, thickness)).rgb;
  // Water absorbs red first: thin sheets are clear, deep water turns blue-green.
  vec3 absorbed = behind * exp(-thickness * vec3(7.0, 2.5, 1.2)) + vec3(0.02, 0.10, 0.20) * (1.0 - exp(-thickness * 4.0));
  float fresnel = 0.02 + 0.98 * pow(1.0 - max(dot(n, eye_dir), 0.0), 5.0);
  vec3 surface_world = world_position(pos);
  vec3 reflected = surroundings(surface_world, world_direction(reflect(-eye_dir, n)));
  vec3 h = normalize(light_view.xyz + eye_dir);
  float specular = pow(max(dot(n, h), 0.0), 120.0);
  return mix(absorbed, reflected, fresnel) + vec3(0.8 * specular);
}

void main() {
  // The tile's pixels: where a texel spans a fractional number of pixels, the pixels that
  // any part of its texels covers (a pixel between two tiles is shaded by both, alike).
  ivec2 tile = group_tile();
  ivec2 lo = ivec2(floor(vec2(tile * TILE) * tile_scale));
  ivec2 hi = min(ivec2(ceil(vec2((tile + 1) * TILE) * tile_scale)), ivec2(viewport));
  for (int y = lo.y + int(gl_LocalInvocationID.y); y < hi.y; y += TILE)
    for (int x = lo.x + int(gl_LocalInvocationID.x); x < hi.x; x += TILE)
      imageStore(result, ivec2(x, y), vec4(shade(ivec2(x, y)), 1.0));
}
