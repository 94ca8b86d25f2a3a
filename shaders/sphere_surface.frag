// The fluid style's splat (PASS_SURFACE), in one draw into two targets: the linear eye
// depth where the pixel's ray enters the sphere (blended by min: the nearest sphere) and
// the chord through it (blended by sum: the thickness of every layer).
// No gl_FragDepth: the tank's depth test then runs before the shader, at the depth of
// the sphere's nearest point (sphere.vert), so that fluid up to a radius behind an
// obstacle's face may show at its outline, which the shading's slack allows anyway.
flat in vec3 centre_view;
layout(location = 0) out vec4 depth;
layout(location = 1) out vec4 chord;

void main() {
  vec3 ray = view_ray(gl_FragCoord.xy);
  // The depth samples each pixel's centre once: grown by half a pixel, spheres that touch
  // leave no pinholes between them where they are a pixel or two wide (a lattice at 2
  // pixels per spacing in the half-size surface showed single-texel holes). The sprite's
  // margin (sphere.vert) covers the growth. The chord keeps the true radius.
  float grown = radius - centre_view.z / (viewport.y * proj[1][1]);
  float disc = sphere_disc(ray, centre_view, grown);
  if (disc < 0.0) discard;
  float a = dot(ray, ray);
  depth = vec4((dot(ray, centre_view) - sqrt(disc)) / a, 0.0, 0.0, 1.0);
  chord = vec4(2.0 * sqrt(max(sphere_disc(ray, centre_view, radius), 0.0) / a), 0.0, 0.0, 1.0);
}
