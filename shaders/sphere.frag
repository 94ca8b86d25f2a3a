// Ray-sphere intersection per fragment: exact silhouette and depth of each particle.
// PASS_SHADED, PASS_SOLID: lit colour. PASS_SURFACE: linear eye depth (blended by min:
// the nearest sphere) and the chord through the sphere (blended by sum: the thickness of
// every layer) into two targets at once.
flat in vec3 centre_view;
flat in float scalar;
layout(location = 0) out vec4 result;
layout(location = 1) out vec4 chord;  // PASS_SURFACE only

void main() {
  // This pixel's ray through the eye (view space; the projection is symmetric).
  vec2 ndc = gl_FragCoord.xy / viewport * 2.0 - 1.0;
  vec3 dir = normalize(vec3(ndc.x / proj[0][0], ndc.y / proj[1][1], -1.0));
  float b = dot(dir, centre_view);
  float centre_sq = dot(centre_view, centre_view);
  // The surface's depth samples each pixel's centre once: grown by half a pixel, spheres
  // that touch leave no pinholes between them where they are a pixel or two wide (a
  // lattice at 2 pixels per spacing in the half-size surface showed single-texel holes).
  // The sprite's margin (sphere.vert) covers the growth. The chord keeps the true radius.
  float r = radius;
  if (pass == PASS_SURFACE) r += -centre_view.z / (viewport.y * proj[1][1]);
  float disc = b * b - centre_sq + r * r;
  if (disc < 0.0) discard;
  float s = sqrt(disc);
  vec3 p = (b - s) * dir;
  vec4 clip = proj * vec4(p, 1.0);
  gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
  if (pass == PASS_SURFACE) {
    result = vec4(-p.z, 0.0, 0.0, 1.0);
    chord = vec4(2.0 * sqrt(max(b * b - centre_sq + radius * radius, 0.0)), 0.0, 0.0, 1.0);
  } else {
    vec3 base = pass == PASS_SOLID         ? SOLID_COLOUR
                : style == STYLE_PARTICLES ? vec3(0.20, 0.45, 0.85)
                                           : ramp(scalar / colour_scale);
    result = vec4(lit(base, (p - centre_view) / radius, p), 1.0);
    chord = vec4(0.0);
  }
}
