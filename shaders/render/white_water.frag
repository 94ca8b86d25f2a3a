// A white water particle: a soft white disc, blended over the shaded fluid (white over any
// colour, so the order of the draws does not matter). The tank and obstacles hide it by the
// depth test; below the fluid's surface (its smoothed depth, unit 1) the water in front dims
// it, the more the deeper it lies.
flat in vec3 centre_view;
flat in float opacity;
layout(binding = 1) uniform sampler2D fluid_depth;  // (linear eye depth, coverage), surface size
layout(location = 0) out vec4 result;

void main() {
  vec2 p = gl_PointCoord * 2.0 - 1.0;
  float r2 = dot(p, p);
  if (r2 > 1.0) discard;
  vec2 surface = texture(fluid_depth, gl_FragCoord.xy / viewport).rg;
  float below = surface.y > 0.05 ? max(-centre_view.z - surface.x / surface.y, 0.0) : 0.0;
  float dimmed = exp(-below / (4.0 * radius));
  result = vec4(1.0, 1.0, 1.0, opacity * (1.0 - r2) * (0.25 + 0.75 * dimmed));
}
