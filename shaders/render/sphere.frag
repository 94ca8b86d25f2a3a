// Ray-sphere intersection per fragment: the exact silhouette and depth of each particle
// (PASS_SHADED) or obstacle sphere (PASS_SOLID), lit. The fluid style splats its spheres
// in a compute pass instead (surface_splat.comp).
flat in vec3 centre_view;
flat in float scalar;
layout(location = 0) out vec4 result;

void main() {
  vec3 ray = view_ray(gl_FragCoord.xy);
  float disc = sphere_disc(ray, centre_view, radius);
  if (disc < 0.0) discard;
  vec3 p = (dot(ray, centre_view) - sqrt(disc)) / dot(ray, ray) * ray;
  vec4 clip = proj * vec4(p, 1.0);
  gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
  vec3 base = pass == PASS_SOLID         ? SOLID_COLOUR
              : style == STYLE_PARTICLES ? vec3(0.20, 0.45, 0.85)
                                         : ramp(scalar / colour_scale);
  result = vec4(lit(base, (p - centre_view) / radius, p), 1.0);
}
