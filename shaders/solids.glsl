// The solids: the tank's walls and the obstacles (host/sim/obstacles.hpp, stored grown by the
// keep-out margin, half a spacing). Particles are kept out of them (predicted_position,
// project_out_of_solids), and every solid is a mirror for the neighbour passes (mirrors_near,
// as host/sim/mirrors.cpp). The includer defines OBSTACLES_BINDING.
// Layout (pack_obstacles): obstacle_data[0] = (count, margin, 0, 0); then per obstacle three
// vec4: box (min, 0) (max, 0) (0), sphere (centre, 1) (radius, 0, 0, 0) (0), mesh (field
// origin, 2) (dims, voxel) (first value, 0, 0, 0); then the meshes' distance fields, four
// values a vec4. Boxes and spheres are stored grown by the margin, a mesh's field is its own
// surface.
#ifndef SOLIDS_GLSL
#define SOLIDS_GLSL
#include "contract.h"

layout(std430, binding = OBSTACLES_BINDING) readonly buffer Obstacles { vec4 obstacle_data[]; };
// Whether the scene has obstacles (gpu/key_constants.hpp): without, their mirrors compile out,
// which a CPU device would otherwise run masked for every neighbour (3x the step on lavapipe).
layout(constant_id = 90) const bool OBSTACLES = false;

int obstacle_header(int k) { return 1 + 3 * k; }
float field_value(int first, ivec3 dims, ivec3 p) {
  int k = first + (p.z * dims.y + p.y) * dims.x + p.x;
  return obstacle_data[obstacle_header(int(obstacle_data[0].x)) + k / 4][k % 4];
}
// A mesh's distance at x, trilinear, and its gradient (DistanceField::sample).
float field_distance(int k, vec3 x, out vec3 gradient) {
  vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
  int first = int(obstacle_data[obstacle_header(k) + 2].x);
  ivec3 dims = ivec3(b.xyz);
  vec3 inside = clamp(x, a.xyz, a.xyz + b.w * vec3(dims - 1)), beyond = x - inside;
  vec3 g = (inside - a.xyz) / b.w;
  ivec3 base = clamp(ivec3(floor(g)), ivec3(0), dims - 2);
  vec3 t = g - vec3(base);
  float c[8];
  for (int q = 0; q < 8; ++q) c[q] = field_value(first, dims, base + ivec3(q & 1, (q >> 1) & 1, (q >> 2) & 1));
  float x00 = mix(c[0], c[1], t.x), x10 = mix(c[2], c[3], t.x), x01 = mix(c[4], c[5], t.x), x11 = mix(c[6], c[7], t.x);
  float y0 = mix(x00, x10, t.y), y1 = mix(x01, x11, t.y);
  float dx0 = mix(c[1] - c[0], c[3] - c[2], t.y), dx1 = mix(c[5] - c[4], c[7] - c[6], t.y);
  gradient = vec3(mix(dx0, dx1, t.z), mix(x10 - x00, x11 - x01, t.z), y1 - y0) / b.w;
  float out_of = length(beyond);
  if (out_of > 0.0) gradient = beyond / out_of;
  return mix(y0, y1, t.z) + out_of;
}

// Obstacle k's own surface (its stored shape less the margin): the signed distance from x
// (negative inside) and the outward normal at the surface point nearest x (Obstacle::surface).
float obstacle_surface(int k, vec3 x, out vec3 normal) {
  vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
  float margin = obstacle_data[0].y;
  if (a.w > 1.5) {  // mesh
    vec3 gradient;
    float d = field_distance(k, x, gradient);
    normal = length(gradient) > 0.0 ? normalize(gradient) : vec3(0.0, 1.0, 0.0);
    return d;
  }
  if (a.w > 0.5) {  // sphere
    vec3 d = x - a.xyz;
    float r = length(d);
    normal = r > 0.0 ? d / r : vec3(0.0, 1.0, 0.0);
    return r - (b.x - margin);
  }
  vec3 lo = a.xyz + margin, hi = b.xyz - margin, out_of = x - clamp(x, lo, hi);
  float outside = length(out_of);
  if (outside > 0.0) {
    normal = out_of / outside;
    return outside;
  }
  float depth = 3.4e38;  // inside: the nearest face
  for (int c = 0; c < 3; ++c) {
    vec3 axis = vec3(0.0);
    axis[c] = 1.0;
    if (x[c] - lo[c] < depth) depth = x[c] - lo[c], normal = -axis;
    if (hi[c] - x[c] < depth) depth = hi[c] - x[c], normal = axis;
  }
  return -depth;
}

// Every solid is a mirror (ghost particles; host/sim/mirrors.hpp says why): the fluid behind
// it is the fluid in front of it, reflected. A neighbour j of particle i has an image behind
// every wall within h of i (the nearer wall of each axis), one behind each pair and the triple
// of them at edges and corners, and one behind the nearest obstacle within h, alone and then
// across those walls. Image k is a bit mask: bits 0-2 the walls' axes, bit 3 (OBSTACLE_MIRROR)
// the obstacle. A lattice continued across a plane is the lattice itself, so a wall or a flat
// face reads rho0 exactly.
const int OBSTACLE_MIRROR = 8;
const float FAR_AWAY = 1e18;  // where an image that does not count is put: beyond every kernel
struct Mirrors {
  int axes;        // the mirrors within h, as image bits; the images are the non-empty subsets
  vec3 plane2;     // twice the near wall's coordinate on each wall axis
  int obstacle;    // the nearest obstacle within h (OBSTACLE_MIRROR)
  vec3 at;         // the particle they are seen from
  float distance;  // its distance to that obstacle
  vec3 normal;     // and the obstacle's outward normal at the point nearest it
};
Mirrors mirrors_near(vec3 x) {
  Mirrors m;
  m.axes = 0;
  for (int a = 0; a < 3; ++a) {
    float lo = x[a] - sim.domain_min[a], hi = sim.domain_max[a] - x[a];
    if (min(lo, hi) < sim.h) m.axes |= 1 << a;  // a box narrower than 2h: the nearer wall only
    m.plane2[a] = 2.0 * (lo <= hi ? sim.domain_min[a] : sim.domain_max[a]);
  }
  m.obstacle = -1;
  m.at = x;
  m.distance = sim.h;
  m.normal = vec3(0.0);
  for (int k = 0; OBSTACLES && k < int(obstacle_data[0].x); ++k) {
    vec3 normal;
    float distance = obstacle_surface(k, x, normal);
    if (distance < m.distance) m.distance = distance, m.normal = normal, m.obstacle = k;
  }
  if (m.obstacle >= 0) m.axes |= OBSTACLE_MIRROR;
  return m;
}
// For a pass that sees the fluid only: the cell walk then yields no images.
Mirrors no_mirrors() { return Mirrors(0, vec3(0.0), -1, vec3(0.0), 0.0, vec3(0.0)); }
// Every image of a neighbour: for (int k = m.axes; k != 0; k = next_image(m.axes, k)) ...
int next_image(int axes, int k) { return (k - 1) & axes; }
bvec3 reflected(int k) { return bvec3((k & 1) != 0, (k & 2) != 0, (k & 4) != 0); }

// Where the image of the particle at b (distance phi_b, normal n_b) lies seen from a (phi_a,
// n_a): at D from a, D^2 = |a - b|^2 + 4 phi_a phi_b, along grad_a D (Mirrors::obstacle_image).
vec3 pair_image(vec3 a, float phi_a, vec3 n_a, vec3 b, float phi_b) {
  vec3 apart = a - b, along = apart + 2.0 * phi_b * n_a;
  float d2 = max(dot(apart, apart) + 4.0 * phi_a * phi_b, 0.0);
  return a - sqrt(d2) * (dot(along, along) > 0.0 ? normalize(along) : n_a);
}

// The obstacle's image of neighbour x, seen from the particle (Mirrors::obstacle_image says
// why); far away where the pair's images do not both lie inside the obstacle.
vec3 obstacle_image(Mirrors m, vec3 x) {
  int o = max(m.obstacle, 0);
  vec3 normal, unused;
  float distance = obstacle_surface(o, x, normal);
  vec3 image = pair_image(m.at, m.distance, m.normal, x, distance);
  // An entry listed beside an obstacle that is no longer within h does not count.
  bool inside = (m.axes & OBSTACLE_MIRROR) != 0 && obstacle_surface(o, image, unused) < 0.0 &&
                obstacle_surface(o, pair_image(x, distance, normal, m.at, m.distance), unused) < 0.0;
  return inside ? image : vec3(FAR_AWAY);
}

vec3 mirror(Mirrors m, int k, vec3 x) {
  if (OBSTACLES && (k & OBSTACLE_MIRROR) != 0) x = obstacle_image(m, x);
  return mix(x, m.plane2 - x, reflected(k));
}
// An image moves as its particle, mirrored.
vec3 mirror_velocity(Mirrors m, int k, vec3 v) {
  if (OBSTACLES && (k & OBSTACLE_MIRROR) != 0) v -= 2.0 * dot(v, m.normal) * m.normal;
  return mix(v, -v, reflected(k));
}

// How far along the move d from `from` mesh k's grown surface is met (obstacles.cpp, trace);
// 1 where it is not, 0 where `from` touches it.
float trace(int k, vec3 from, vec3 d, float contact) {
  vec3 normal;
  float margin = obstacle_data[0].y, len = length(d), t = 0.0;
  if (obstacle_surface(k, from, normal) - margin < contact) return 1.0;  // touching: the projection's
  for (int s = 0; len > 0.0 && s < TRACE_STEPS; ++s) {
    float gap = obstacle_surface(k, from + t * d, normal) - margin;
    if (gap <= TRACE_STOP * contact) break;
    t += gap / len;
    if (t >= 1.0) return 1.0;
  }
  return t;
}

// Where the move from -> to first enters an obstacle (host/sim/obstacles.cpp, stop_at): a
// fast particle stops at the first surface it meets instead of tunnelling through. A
// start within 1e-3 h of an obstacle touches it and is left to the projection.
vec3 stop_at_solids(vec3 from, vec3 to) {
  int count = int(obstacle_data[0].x);
  float contact = 1e-3 * sim.h;
  vec3 d = to - from;
  float first = 1.0;
  for (int k = 0; k < count; ++k) {
    vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
    float t_enter = 0.0, t_exit = 1.0;
    if (a.w > 1.5) {
      first = min(first, trace(k, from, d, contact));
      continue;
    }
    if (a.w > 0.5) {  // sphere: the smaller root of |from + t d - c|^2 = r^2
      vec3 f = from - a.xyz;
      float qa = dot(d, d), qb = dot(f, d), qc = dot(f, f) - b.x * b.x;
      float disc = qb * qb - qa * qc;
      if (length(f) < b.x + contact || qa == 0.0 || disc < 0.0) continue;  // touching, still, or a miss
      t_enter = (-qb - sqrt(disc)) / qa;
      if (t_enter >= 0.0 && t_enter <= 1.0) first = min(first, t_enter);
      continue;
    }
    if (all(greaterThan(from, a.xyz - contact)) && all(lessThan(from, b.xyz + contact))) continue;  // touching
    bool miss = false;
    for (int c = 0; c < 3; ++c) {
      if (d[c] == 0.0) {
        miss = miss || from[c] <= a[c] || from[c] >= b[c];
        continue;
      }
      float t0 = (a[c] - from[c]) / d[c], t1 = (b[c] - from[c]) / d[c];
      t_enter = max(t_enter, min(t0, t1));
      t_exit = min(t_exit, max(t0, t1));
    }
    if (!miss && t_enter < t_exit) first = min(first, t_enter);
  }
  return from + first * d;
}

// x moved onto the nearest surface of each obstacle it is inside, then into the walls.
// Box faces outside the walls are no candidates: the clamp would push x back in.
vec3 project_out_of_solids(vec3 x) {
  int count = int(obstacle_data[0].x);
  for (int k = 0; k < count; ++k) {
    vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
    if (a.w > 1.5) {  // mesh: onto its grown surface along the normal
      vec3 normal;
      float d = obstacle_surface(k, x, normal) - obstacle_data[0].y;
      if (d < 0.0) x -= d * normal;
    } else if (a.w > 0.5) {  // sphere
      vec3 d = x - a.xyz;
      float r = length(d);
      if (r < b.x) x = a.xyz + b.x * (r > 0.0 ? d / r : vec3(0.0, 1.0, 0.0));
    } else if (all(greaterThan(x, a.xyz)) && all(lessThan(x, b.xyz))) {
      vec3 best = x;
      float nearest = 3.4e38;
      for (int c = 0; c < 3; ++c) {
        if (a[c] >= sim.wall_min[c] && x[c] - a[c] < nearest) {
          nearest = x[c] - a[c];
          best = x;
          best[c] = a[c];
        }
        if (b[c] <= sim.wall_max[c] && b[c] - x[c] < nearest) {
          nearest = b[c] - x[c];
          best = x;
          best[c] = b[c];
        }
      }
      x = best;
    }
  }
  return project_to_walls(x);
}

// The prediction x* = x + v dt, stopped at the first solid it meets and kept out of them all.
vec3 predicted_position(vec3 x, vec3 v) { return project_out_of_solids(stop_at_solids(x, x + v * sim.dt)); }

#endif
