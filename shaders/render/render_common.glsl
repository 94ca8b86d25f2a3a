// Shared by the render shaders (prepended after #version and shape_layout.glsl by
// capture/gl_objects.cpp):
// the per-frame uniforms and the particle buffer in the solver's frame layout
// (vec4 x[n], vec4 v[n], float rho[n], vec4 x_smooth[n], vec4 shape[2n], then white water's
// count and room: frame_offsets in solver.hpp).

const int STYLE_FLUID = 0, STYLE_PARTICLES = 1, STYLE_DENSITY = 2, STYLE_SPEED = 3, STYLE_NORMALS = 4;
const int PASS_SHADED = 0;
const int PASS_SOLID = 1;  // obstacles: boxes seen from outside, spheres in the solid colour
const int TILE = 8;  // surface texels on a side of a tile of the fluid's smoothing and shading (surface_tiles.glsl)
const float NO_FLUID = 1e30;  // the splat's depth where no sphere was drawn (surface_splat.comp)
const float CHORD_UNIT = 1e-6;  // m: the splat sums chords as integers of this (image atomics)
const vec3 SOLID_COLOUR = vec3(0.62, 0.48, 0.34);

layout(std140, binding = 0) uniform Frame {
  mat4 view;
  mat4 proj;
  mat4 model;       // box.vert: where an obstacle's pose puts its box (the identity for the tank)
  vec4 light_view;  // unit vector towards the light, view space
  vec4 domain_min;  // the tank's frame; w unused (box.vert: the box drawn, the domain or an obstacle)
  vec4 domain_max;
  vec4 world_up;    // the world's up in the tank's frame: the sky's horizon
  vec2 viewport;    // pixels
  float radius;     // particle radius, m
  int count;        // particles
  int style;
  int pass;
  float colour_scale;  // the value drawn at the top of the colour ramp (density, speed styles)
  float rho0;
  int white_capacity;  // white water's room in the particle buffer (white_water.vert)
};

layout(std430, binding = 0) readonly buffer Particles { float particle_data[]; };

vec3 particle_x(int i) { return vec3(particle_data[4 * i], particle_data[4 * i + 1], particle_data[4 * i + 2]); }
vec3 particle_v(int i) {
  int o = 4 * (count + i);
  return vec3(particle_data[o], particle_data[o + 1], particle_data[o + 2]);
}
float particle_rho(int i) { return particle_data[8 * count + i]; }
// Where the fluid's surface draws the particle: its smoothed position (or x, where the solver has none).
vec3 particle_x_smooth(int i) {
  int o = 9 * count + 4 * i;
  return vec3(particle_data[o], particle_data[o + 1], particle_data[o + 2]);
}
// The shape the fluid's surface draws the particle with (shape_layout.glsl): the ellipsoid
// {p : (p - c)^T inverse(T) (p - c) <= radius^2} (the identity: the sphere), and its longest
// semi-axis in radii.
mat3 particle_shape(int i, out float longest_axis) {
  int o = 13 * count + 8 * i;
  return decode_shape(vec4(particle_data[o], particle_data[o + 1], particle_data[o + 2], particle_data[o + 3]),
                      vec4(particle_data[o + 4], particle_data[o + 5], particle_data[o + 6], particle_data[o + 7]),
                      longest_axis);
}

// The view-space ray through a point of the viewport (pixels): the point at linear eye
// depth d on it is d times the ray (its z is -1; the projection is symmetric).
vec3 view_ray(vec2 pixel) {
  vec2 ndc = pixel / viewport * 2.0 - 1.0;
  return vec3(ndc.x / proj[0][0], ndc.y / proj[1][1], -1.0);
}

// Where t * ray meets the sphere (centre, r): t = (b -+ sqrt(disc)) / a, with
// a = |ray|^2, b = ray . centre and disc = b^2 - a (|centre|^2 - r^2); a miss where disc < 0.
float sphere_disc(vec3 ray, vec3 centre, float r) {
  float b = dot(ray, centre);
  return b * b - dot(ray, ray) * (dot(centre, centre) - r * r);
}

// The tank's frame (the solver's, where the tank stands in the world: Renderer::uniforms), "world"
// below, from view space: the view matrix is a rotation and a shift.
vec3 world_direction(vec3 dir_view) { return transpose(mat3(view)) * dir_view; }
vec3 world_position(vec3 p_view) { return transpose(mat3(view)) * (p_view - view[3].xyz); }

// The sky seen along a world direction: a pale horizon, deeper blue above, a sun towards the
// light and, below the horizon, the dull ground the open tank stands on.
vec3 sky(vec3 dir) {
  float h = dot(dir, world_up.xyz);
  vec3 above = mix(vec3(0.82, 0.87, 0.92), vec3(0.30, 0.50, 0.82), clamp(h * 1.6, 0.0, 1.0));
  vec3 below = mix(vec3(0.55, 0.55, 0.52), vec3(0.35, 0.34, 0.32), clamp(-h * 3.0, 0.0, 1.0));
  float towards_sun = max(dot(dir, world_direction(light_view.xyz)), 0.0);
  float sun = pow(towards_sun, 600.0) * 6.0 + pow(towards_sun, 12.0) * 0.25;
  return (h >= 0.0 ? above : below) + vec3(1.0, 0.95, 0.85) * sun;
}

// The tank's inside at a world point on its floor or a wall, lit: a 10 cm checker on the
// floor, light grey walls (box.frag draws it; the fluid reflects and refracts it).
vec3 tank_surface(vec3 p, vec3 inward_normal) {
  vec3 base = vec3(0.86, 0.86, 0.84);
  if (inward_normal.y > 0.5) {
    ivec2 cell = ivec2(floor(p.xz / 0.1));
    base = ((cell.x + cell.y) & 1) == 0 ? vec3(0.62, 0.60, 0.56) : vec3(0.80, 0.78, 0.74);
  }
  // Walls take more ambient light than the fluid so that the tank reads as a bright backdrop.
  return base * (0.55 + 0.45 * max(dot(inward_normal, world_direction(light_view.xyz)), 0.0));
}

// How far a ray from a point inside the tank goes before it leaves through a face, and that
// face's inward normal.
float tank_exit(vec3 origin, vec3 dir, out vec3 inward_normal) {
  vec3 safe = mix(vec3(1e-8), dir, greaterThan(abs(dir), vec3(1e-8)));
  vec3 t = (mix(domain_min.xyz, domain_max.xyz, greaterThan(safe, vec3(0.0))) - origin) / safe;
  float exit = min(t.x, min(t.y, t.z));
  inward_normal = -sign(safe) * vec3(equal(t, vec3(exit)));
  return max(exit, 0.0);
}

// What a ray from inside the tank sees: a wall or the floor, or the sky through the open top
// (obstacles are not in it).
vec3 surroundings(vec3 origin, vec3 dir) {
  vec3 inward;
  float t = tank_exit(origin, dir, inward);
  return inward.y < -0.5 ? sky(dir) : tank_surface(origin + t * dir, inward);
}

// A ramp from deep blue through cyan, green and yellow to red, t in [0, 1].
vec3 ramp(float t) {
  const vec3 stops[5] = vec3[](vec3(0.10, 0.15, 0.60), vec3(0.10, 0.65, 0.85), vec3(0.25, 0.80, 0.30),
                               vec3(0.95, 0.85, 0.15), vec3(0.85, 0.15, 0.10));
  float x = clamp(t, 0.0, 1.0) * 4.0;
  int k = min(int(x), 3);
  return mix(stops[k], stops[k + 1], x - float(k));
}

vec3 lit(vec3 base, vec3 n, vec3 p) {
  float diffuse = max(dot(n, light_view.xyz), 0.0);
  vec3 h = normalize(light_view.xyz - normalize(p));
  float specular = pow(max(dot(n, h), 0.0), 48.0);
  return base * (0.30 + 0.70 * diffuse) + vec3(0.25 * specular);
}
