// The fluid style's splat, one invocation per particle at its smoothed position (the
// solver's smoothed_positions.comp: a surface's rows and columns do not show): over the
// surface texels its sphere covers, the linear eye depth where the texel's ray enters the sphere (atomic min: the
// nearest sphere) and the chord through it (atomic sum: every layer's thickness). A compute
// pass, where a point sprite per particle was drawn: an H200 ran that draw's blending at
// ~20 ms for 1M particles at 1080p, its graphics units being few beside its compute.
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
  float d = length(c);
  if (-c.z <= radius) return;  // at or behind the eye: not seen whole, and never in a framed tank
  // The outline's extent from the projected centre: f r / sqrt(d^2 - r^2) on the axis,
  // stretched by up to sec^2 of the angle off it; plus the depth's growth of half a texel
  // and half a texel of margin.
  float f = 0.5 * viewport.y * proj[1][1];
  float secant = d / -c.z;
  float extent = f * radius / sqrt(d * d - radius * radius) * d / -c.z * secant * secant + 1.0;
  vec4 clip = proj * vec4(c, 1.0);
  vec2 centre = (clip.xy / clip.w * 0.5 + 0.5) * viewport;
  ivec2 lo = max(ivec2(ceil(centre - extent - 0.5)), ivec2(0));
  ivec2 hi = min(ivec2(floor(centre + extent - 0.5)), ivec2(viewport) - 1);
  // The tank hides the sphere where its depth buffer is nearer than the sphere's nearest point.
  vec4 near_clip = proj * vec4(c * (1.0 - radius / d), 1.0);
  float near_window = 0.5 * near_clip.z / near_clip.w + 0.5;
  // The depth samples each texel's centre once: grown by half a texel, spheres that touch
  // leave no pinholes between them where they are a texel or two wide (a lattice at 2
  // texels per spacing showed single-texel holes). The chord keeps the true radius.
  float grown = radius - c.z / (2.0 * f);
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      ivec2 q = ivec2(x, y);
      vec3 ray = view_ray(vec2(q) + 0.5);
      float disc = sphere_disc(ray, c, grown);
      if (disc < 0.0) continue;
      if (near_window >= texelFetch(scene_depth, ivec2((vec2(q) + 0.5) * image_scale), 0).r) continue;
      float a = dot(ray, ray);
      imageAtomicMin(nearest_depth, q, floatBitsToUint((dot(ray, c) - sqrt(disc)) / a));
      float chord = 2.0 * sqrt(max(sphere_disc(ray, c, radius), 0.0) / a);
      imageAtomicAdd(chord_sum, q, uint(chord / CHORD_UNIT + 0.5));
    }
}
