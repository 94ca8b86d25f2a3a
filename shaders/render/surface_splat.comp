// The fluid style's splat, one invocation per particle at its smoothed position and in its
// drawn shape (the solver's smoothed_positions.comp: an ellipsoid of the sphere's volume,
// flattened at a free surface and stretched along a sheet, so that a surface's rows and
// columns do not show): over the surface texels it covers, the linear eye depth where the
// texel's ray enters it (atomic min: the nearest) and the chord through it (atomic sum: every
// layer's thickness). A compute pass, where a point sprite per particle was drawn: a compute
// GPU's graphics units are few beside its compute, and the sprites' blending took longer than
// the whole frame may (docs/performance.md).
layout(local_size_x = 64) in;
// Positive floats order as their bits: the depth is kept as bits, cleared to NO_FLUID's.
layout(binding = 0, r32ui) uniform restrict uimage2D nearest_depth;
layout(binding = 1, r32ui) uniform restrict uimage2D chord_sum;  // in CHORD_UNIT
layout(binding = 3) uniform sampler2D scene_depth;               // the tank's depth buffer, at the image's size
layout(location = 2) uniform vec2 image_scale;                   // image pixels per surface texel

void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= count) return;
  vec3 c = (view * vec4(particle_x_smooth(i), 1.0)).xyz;
  float longest_axis;
  mat3 shape = particle_shape(i, longest_axis);
  float bound = radius * longest_axis;  // the ellipsoid lies within this sphere
  float d = length(c);
  if (-c.z <= bound) return;  // at or behind the eye: not seen whole, and never in a framed tank
  // The bounding sphere's outline's extent from the projected centre: f r / sqrt(d^2 - r^2) on
  // the axis, stretched by up to sec^2 of the angle off it; plus the depth's growth of half a
  // texel and half a texel of margin.
  float f = 0.5 * viewport.y * proj[1][1];
  float secant = d / -c.z;
  float extent = f * bound / sqrt(d * d - bound * bound) * d / -c.z * secant * secant + 1.0;
  vec4 clip = proj * vec4(c, 1.0);
  vec2 centre = (clip.xy / clip.w * 0.5 + 0.5) * viewport;
  ivec2 lo = max(ivec2(ceil(centre - extent - 0.5)), ivec2(0));
  ivec2 hi = min(ivec2(floor(centre + extent - 0.5)), ivec2(viewport) - 1);
  // The tank hides the particle where its depth buffer is nearer than the bounding sphere's nearest point.
  vec4 near_clip = proj * vec4(c * (1.0 - bound / d), 1.0);
  float near_window = 0.5 * near_clip.z / near_clip.w + 0.5;
  // t ray meets the ellipsoid where a t^2 - 2 b t + e - 1 = 0: a = ray.A ray, b = ray.A c,
  // e = c.A c, A the inverse of its matrix in view space.
  mat3 rotation = mat3(view);
  mat3 inverse_shape = inverse(rotation * shape * transpose(rotation)) / (radius * radius);
  vec3 ac = inverse_shape * c;
  float e = dot(c, ac);
  // The depth samples each texel's centre once: grown by half a texel (its longest axis, the
  // others in proportion), ellipsoids that touch leave no pinholes between them where they
  // are a texel or two wide (a lattice at 2 texels per spacing showed single-texel holes).
  // The chord keeps the true size.
  float grown = 1.0 / pow(1.0 - c.z / (2.0 * f * bound), 2.0);  // A's scale grown
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      ivec2 q = ivec2(x, y);
      vec3 ray = view_ray(vec2(q) + 0.5);
      vec3 a_ray = inverse_shape * ray;
      float a = dot(ray, a_ray), b = dot(a_ray, c);
      float disc_grown = grown * (grown * b * b - a * (grown * e - 1.0));
      if (disc_grown < 0.0) continue;
      if (near_window >= texelFetch(scene_depth, ivec2((vec2(q) + 0.5) * image_scale), 0).r) continue;
      imageAtomicMin(nearest_depth, q, floatBitsToUint((b - sqrt(disc_grown / (grown * grown))) / a));
      float chord = 2.0 * sqrt(max(b * b - a * (e - 1.0), 0.0) * dot(ray, ray)) / a;
      imageAtomicAdd(chord_sum, q, uint(chord / CHORD_UNIT + 0.5));
    }
}
