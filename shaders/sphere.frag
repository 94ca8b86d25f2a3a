// Ray-sphere intersection per fragment: exact silhouette and depth of each particle.
// PASS_SHADED: lit colour; PASS_DEPTH: linear eye depth and coverage 1; PASS_THICKNESS:
// chord length.
flat in vec3 centre_view;
flat in float scalar;
layout(location = 0) out vec4 result;

void main() {
  // This pixel's ray through the eye (view space; the projection is symmetric).
  vec2 ndc = gl_FragCoord.xy / viewport * 2.0 - 1.0;
  vec3 dir = normalize(vec3(ndc.x / proj[0][0], ndc.y / proj[1][1], -1.0));
  float b = dot(dir, centre_view);
  // The surface's depth samples each pixel's centre once: grown by half a pixel, spheres
  // that touch leave no pinholes between them where they are a pixel or two wide (a
  // lattice at 2 pixels per spacing in the half-size surface showed single-texel holes).
  // The sprite's margin (sphere.vert) covers the growth. The thickness, a sum over every
  // layer, keeps the true radius.
  float r = radius;
  if (pass == PASS_DEPTH) r += -centre_view.z / (viewport.y * proj[1][1]);
  float disc = b * b - dot(centre_view, centre_view) + r * r;
  if (disc < 0.0) discard;
  float s = sqrt(disc);
  vec3 p = (b - s) * dir;
  vec4 clip = proj * vec4(p, 1.0);
  gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
  if (pass == PASS_DEPTH) {
    result = vec4(-p.z, 1.0, 0.0, 1.0);  // depth, coverage
  } else if (pass == PASS_THICKNESS) {
    result = vec4(2.0 * s, 0.0, 0.0, 1.0);
  } else {  // PASS_SHADED or PASS_SOLID
    vec3 base = pass == PASS_SOLID         ? SOLID_COLOUR
                : style == STYLE_PARTICLES ? vec3(0.20, 0.45, 0.85)
                                           : ramp(scalar / colour_scale);
    result = vec4(lit(base, (p - centre_view) / radius, p), 1.0);
  }
}
