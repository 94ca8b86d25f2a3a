// The solids: the tank's walls and the obstacles (host/sim/solids/obstacles.hpp, stored grown by the
// keep-out margin, half a spacing). Particles are kept out of them (predicted_position,
// project_out_of_solids), and every solid is a mirror for the neighbour passes (mirrors_near,
// as host/sim/solids/mirrors.cpp). The includer defines OBSTACLES_BINDING.
// Layout (pack_obstacles): obstacle_data[0] = (0, margin, 0, 0), [1-7] the tank's kick this
// step (Derived::tank_kick, the tank's frame's velocity change: linear with 1 in w where there is
// any kick, of_x's and of_v's columns); then per obstacle nine
// vec4: its shape in its body frame, box (min, 0) (max, 0) (0, moves), sphere (centre, 1) (radius,
// 0, 0, 0) (0, moves), mesh (field origin, 2) (dims, voxel) (first value, moves, 0, 0), moves 1
// where it has a motion; then its pose at the step's end and at its start, each three rows of
// the world-to-body transform; then the meshes' distance fields, four values a vec4. Boxes and
// spheres are stored grown by the margin, a mesh's field is its own surface.
#ifndef SOLIDS_GLSL
#define SOLIDS_GLSL
#include "contract.h"

layout(std430, binding = OBSTACLES_BINDING) readonly buffer Obstacles { vec4 obstacle_data[]; };
// The same buffer as words, for the fields' values: a component picked from a vec4 at a computed
// index cost a CPU device four loads for one (docs/performance.md).
layout(std430, binding = OBSTACLES_BINDING) readonly buffer ObstacleWords { float obstacle_words[]; };
// And as bits, for the meshes' crease marks (near_crease).
layout(std430, binding = OBSTACLES_BINDING) readonly buffer ObstacleBits { uint obstacle_bits[]; };
// The shapes the scene's obstacles have, a bit each (1 << the shape's code: box 0, sphere 1,
// mesh 2; gpu/key_constants.cpp). A CPU device runs every branch masked for every neighbour, so
// each shape the scene lacks is compiled out: without obstacles their mirrors (3x the step on
// lavapipe), and a box alone skips the sphere's and the mesh's code (2.7x the dam break past a
// box, docs/performance.md).
layout(constant_id = 90) const uint SHAPES = 0u;
const bool OBSTACLES = SHAPES != 0u;
const int BOX = 0, SPHERE = 1, MESH = 2;
bool has_shape(int shape) { return (SHAPES & (1u << shape)) != 0u; }
// How many obstacles the scene has (Derived::obstacles): known when the pipeline is made, the loops
// over them unroll and each one's header is a load all lanes share rather than a gather.
layout(constant_id = 95) const int OBSTACLE_COUNT = 0;
// Obstacle k for a lane, where k is one of them (a count of one makes it a constant).
int one_of_the_obstacles(int k) { return clamp(k, 0, max(OBSTACLE_COUNT - 1, 0)); }
// Whether any obstacle moves (Derived::moving): the work they do is counted only then.
layout(constant_id = 91) const bool MOVING = false;
// Whether the box's walls mirror the fluid: not where the domain is a mesh (Derived::walls_mirror).
layout(constant_id = 92) const bool WALLS = true;
// Whether the obstacles are mirrors in this pass: not in a neighbour pass's list readers of the
// particles no obstacle was within h of when the lists were built (neighbours.glsl), so that the
// obstacles' mirror code, a mesh's field among it, stays out of their neighbour loop. Their
// keeping out of the solids (project_out_of_solids) is compiled in everywhere.
layout(constant_id = 94) const bool OBSTACLE_MIRRORS = true;
const bool MIRRORS_OBSTACLES = OBSTACLES && OBSTACLE_MIRRORS;
// Whether the obstacles' mirrors in this pass include a mesh's: its creases and its field's images.
bool mirrors_mesh() { return OBSTACLE_MIRRORS && has_shape(MESH); }
// Whether the step keeps each particle's distance to every obstacle's surface, from the lists
// pass to the viscosity, beside its position (Derived::keeps_distances): a near reader then reads
// a neighbour's distance there for its image instead of sampling a mesh's field (eight loads) at
// every neighbour (docs/performance.md). Not where bodies move between a step's passes.
layout(constant_id = 96) const bool DISTANCES = false;
#ifdef DISTANCES_BINDING
// Obstacle k's distance from particle j at [k n + j], at the positions this pass reads.
layout(std430, binding = DISTANCES_BINDING) readonly buffer Distances { float distances[]; };
#endif
#ifdef DISTANCES_OUT_BINDING
// The same at the positions this pass writes: each particle's own.
layout(std430, binding = DISTANCES_OUT_BINDING) writeonly buffer DistancesOut { float distances_out[]; };
void keep_distance(int k, uint i, float distance) {
  if (DISTANCES) distances_out[uint(k) * sim.count + i] = distance;
}
#endif
#ifdef WORK_BINDING
// The work moving solids did on each particle slot this frame, per unit mass (J/kg): slots are
// re-sorted every step, but reduce_stats.comp only sums them.
layout(std430, binding = WORK_BINDING) buffer Work { float work[]; };
void add_work(uint i, float w) {
  if (MOVING) work[i] += w;
}
#endif

int obstacle_header(int k) { return 1 + TANK_KICK_VEC4S + OBSTACLE_VEC4S * k; }
// The kick's matrix whose columns start at `first`: of_x at 2, of_v at 5.
mat3 kick_matrix(int first) {
  return mat3(obstacle_data[first].xyz, obstacle_data[first + 1].xyz, obstacle_data[first + 2].xyz);
}
// The velocity a particle at x moving at v gains this step from the tank's motion, in its frame.
vec3 tank_kick(vec3 x, vec3 v) {
  return MOVING ? obstacle_data[1].xyz + kick_matrix(2) * x + kick_matrix(5) * v : vec3(0.0);
}
// Whether the tank's frame kicks the fluid this step (a scene's moving obstacles alone do not).
bool tank_kicks() { return MOVING && obstacle_data[1].w > 0.5; }
// The kick a particle at x took this step, from its velocity after it (v + g dt + kick): I + of_v
// is a turn, so v comes back through its transpose (TankKick::taken).
vec3 tank_kick_taken(vec3 x, vec3 after) {
  mat3 turn = mat3(1.0) + kick_matrix(5);
  vec3 free = after - sim.gravity * sim.dt;  // v + kick
  return MOVING ? free - transpose(turn) * (free - obstacle_data[1].xyz - kick_matrix(2) * x) : vec3(0.0);
}
// g as the tank's frame feels it over the last step: turned into the frame, less the tank's
// acceleration; its rotation's terms left out (white water, Derived::tank_gravity).
vec3 tank_gravity() { return sim.gravity + (MOVING ? obstacle_data[1].xyz / sim.dt : vec3(0.0)); }
const int POSE_NOW = 3, POSE_BEFORE = 6;  // the poses' first row in an obstacle's header
// x in obstacle k's body frame, from the pose at `pose` (Pose::body). Where nothing moves every
// pose is the identity (a scene places each solid in its own frame): that costs nothing.
vec3 to_body(int k, int pose, vec3 x) {
  if (!MOVING) return x;
  int r = obstacle_header(k) + pose;
  vec4 x1 = vec4(x, 1.0);
  return vec3(dot(obstacle_data[r], x1), dot(obstacle_data[r + 1], x1), dot(obstacle_data[r + 2], x1));
}
// A body-frame direction in the world (the rows' transpose).
vec3 to_world_direction(int k, int pose, vec3 d) {
  if (!MOVING) return d;
  int r = obstacle_header(k) + pose;
  return d.x * obstacle_data[r].xyz + d.y * obstacle_data[r + 1].xyz + d.z * obstacle_data[r + 2].xyz;
}
// A body-frame point in the world (Pose::world): R (b - shift).
vec3 to_world(int k, int pose, vec3 b) {
  if (!MOVING) return b;
  int r = obstacle_header(k) + pose;
  return to_world_direction(k, pose, b - vec3(obstacle_data[r].w, obstacle_data[r + 1].w, obstacle_data[r + 2].w));
}
// Rigid bodies (host/sim/solids/coupling.hpp): an obstacle that is a body takes every push its
// solid gives a particle back as momentum instead of counting it as work. The scene's bodies
// compile in only where it has them (Derived::bodies).
layout(constant_id = 93) const bool BODIES = false;
int body_of(int k) { return BODIES && k >= 0 ? int(obstacle_data[obstacle_header(k) + 2].z) - 1 : -1; }
#ifdef BODY_PUSH_BINDING
// Per body BODY_PUSH_WORDS words (contract.h): the sums of -dx and of -(x - o) x dx over its
// pushes (o: its body frame's origin, where it stands now), each a 64-bit fixed-point number in
// two words, low first; then its water line (body_water_line.comp).
layout(std430, binding = BODY_PUSH_BINDING) buffer BodyPushes { uint body_push[]; };
// value / BODY_FIXED_UNIT added to the 64-bit sum at `word`: integer sums, so the total is the
// same in any order, as the coarse deposit's.
void add_fixed(int word, float value) {
  float f = value * (BODY_FIXED_UNIT / 4294967296.0), whole = floor(f);
  uint low = uint((f - whole) * 4294967296.0), high = uint(int(whole));
  uint before = atomicAdd(body_push[word], low);
  if (before + low < before) high += 1u;  // the low word's carry
  if (high != 0u) atomicAdd(body_push[word + 1], high);
}
#endif
// Whether obstacle k is a body; if so, its push dx of the particle at x is recorded for it.
bool push_body(int k, vec3 x, vec3 dx) {
  int b = body_of(k);
  if (b < 0) return false;
#ifdef BODY_PUSH_BINDING
  if (dx == vec3(0.0)) return true;
  vec3 moment = cross(x - to_world(k, POSE_NOW, vec3(0.0)), dx);
  for (int c = 0; c < 3; ++c) {
    add_fixed(b * BODY_PUSH_WORDS + 2 * c, -dx[c]);
    add_fixed(b * BODY_PUSH_WORDS + 6 + 2 * c, -moment[c]);
  }
#endif
  return true;
}

// How far the solid moves at x over a step: the chord centred on x (Obstacle::displacement).
vec3 obstacle_displacement(int k, vec3 x) {
  if (!MOVING) return vec3(0.0);
  return 0.5 * (to_world(k, POSE_NOW, to_body(k, POSE_BEFORE, x)) - to_world(k, POSE_BEFORE, to_body(k, POSE_NOW, x)));
}
// The work per unit mass of a push dx by a solid whose surface moved by `moved` over the step:
// its force m dx / dt^2 times its velocity moved / dt, for dt (push_work in sim/solids/mirrors.hpp).
float push_work(vec3 dx, vec3 moved) { return MOVING ? dot(dx, moved) / (sim.dt * sim.dt) : 0.0; }
// Whether mesh k's field marks a crease near the body-frame point b, at the node nearest it
// (DistanceField::near_crease); the marks follow the field's values.
bool near_crease(int k, vec3 b) {
  vec4 a = obstacle_data[obstacle_header(k)], c = obstacle_data[obstacle_header(k) + 1];
  ivec3 dims = ivec3(c.xyz), p = ivec3(floor((b - a.xyz) / c.w + 0.5));
  if (any(lessThan(p, ivec3(0))) || any(greaterThanEqual(p, dims))) return false;
  int node = (p.z * dims.y + p.y) * dims.x + p.x;
  int first = int(obstacle_data[obstacle_header(k) + 2].x) + dims.x * dims.y * dims.z;
  uint bits = obstacle_bits[4 * obstacle_header(OBSTACLE_COUNT) + first + node / 32];
  return ((bits >> uint(node % 32)) & 1u) != 0u;
}
float field_value(int first, ivec3 dims, ivec3 p) {
  int k = first + (p.z * dims.y + p.y) * dims.x + p.x;
  return obstacle_words[4 * obstacle_header(OBSTACLE_COUNT) + k];
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

// Obstacle k's own surface (its stored shape less the margin) in its body frame: the signed
// distance from x (negative inside) and the outward normal at the surface point nearest x.
float body_surface(int k, vec3 x, out vec3 normal) {
  vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
  float margin = obstacle_data[0].y;
  if (has_shape(MESH) && a.w > 1.5) {
    vec3 gradient;
    float d = field_distance(k, x, gradient);
    normal = length(gradient) > 0.0 ? normalize(gradient) : vec3(0.0, 1.0, 0.0);
    return d;
  }
  if (has_shape(SPHERE) && a.w > 0.5) {
    vec3 d = x - a.xyz;
    float r = length(d);
    normal = r > 0.0 ? d / r : vec3(0.0, 1.0, 0.0);
    return r - (b.x - margin);
  }
  normal = vec3(0.0, 1.0, 0.0);
  if (!has_shape(BOX)) return 3.4e38;
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
// The same where the solid is now, in the world (Obstacle::surface).
float obstacle_surface(int k, vec3 x, out vec3 normal) {
  float d = body_surface(k, to_body(k, POSE_NOW, x), normal);
  normal = to_world_direction(k, POSE_NOW, normal);
  return d;
}

#ifdef DISTANCES_OUT_BINDING
// Each obstacle's distance from particle i, now at x, kept where the step keeps them
// (DISTANCES); the nearest (3.4e38 without obstacles).
float keep_distances(uint i, vec3 x) {
  float nearest = 3.4e38;
  for (int k = 0; k < OBSTACLE_COUNT; ++k) {
    vec3 unused;
    float distance = obstacle_surface(k, x, unused);
    keep_distance(k, i, distance);
    nearest = min(nearest, distance);
  }
  return nearest;
}
#endif

// The distance from x to the nearest moving obstacle's own surface (3.4e38 where none moves),
// its outward normal and the velocity of the solid's point at x over the step
// (Derived::nearest_moving_solid).
float nearest_moving_solid(vec3 x, out vec3 normal, out vec3 velocity) {
  float nearest = 3.4e38;
  normal = velocity = vec3(0.0);
  for (int k = 0; MOVING && k < OBSTACLE_COUNT; ++k) {
    if (obstacle_data[obstacle_header(k) + 2].y < 0.5 || body_of(k) >= 0) continue;  // it stands still; a body's is no work
    vec3 n;
    float d = obstacle_surface(k, x, n);
    if (d < nearest) nearest = d, normal = n, velocity = obstacle_displacement(k, x) / sim.dt;
  }
  return nearest;
}

// Every solid is a mirror (ghost particles; host/sim/solids/mirrors.hpp says why): the fluid behind
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
  vec3 solid_velocity;  // the velocity of that point over the step (0: it stands still)
  bool listed;     // the images come from a neighbour list, tested when it was built
  // At a mesh's concave crease or corner (find_creases): the wall bits its other faces take,
  // the nearest face's plane (normal, offset: n . y = offset) and theirs (faces[a] for bit a).
  int creases;
  vec4 first;
  vec4 faces[3];
};
// y's height above the plane (normal, offset: n . y = offset), and y reflected across it.
float height(vec4 plane, vec3 y) { return dot(plane.xyz, y) - plane.w; }
vec3 reflect_across(vec4 plane, vec3 y) { return y - 2.0 * height(plane, y) * plane.xyz; }
// How far from x the farther of faces p and q lies where they meet in a concave crease within h
// of x (at distance phi from the surface), h where they do not (host/sim/solids/mirrors.cpp,
// crease_reach). A face is its plane (normal, offset: n . y = offset) and the surface point it
// was read from (its foot).
float crease_reach(vec4 p, vec3 foot_p, vec4 q, vec3 foot_q, vec3 x, float phi, float in_front) {
  float gap_p = height(p, x), gap_q = height(q, x), reach = max(gap_p, gap_q);
  bool crease = dot(p.xyz, q.xyz) < CREASE_COSINE && gap_p > 0.0 && gap_q > 0.0 && reach < sim.h &&
                abs(min(gap_p, gap_q) - phi) < in_front && height(p, foot_q) > in_front && height(q, foot_p) > in_front;
  return crease ? reach : sim.h;
}
// Whether the particle moved `depth` behind a face's plane lies inside the obstacle.
bool behind_face(Mirrors m, vec4 plane, float depth) {
  vec3 unused;
  return obstacle_surface(one_of_the_obstacles(m.obstacle), m.at - (height(plane, m.at) + depth) * plane.xyz, unused) < 0.0;
}
// Whether two faces' planes meet on the surface (within `tolerance`), at their line's point
// nearest the particle: two tangent planes of a round wall meet behind it.
bool faces_meet(Mirrors m, vec4 p, vec4 q, float tolerance) {
  float k = dot(p.xyz, q.xyz), gp = height(p, m.at), gq = height(q, m.at);
  vec3 line = m.at - ((gp - k * gq) * p.xyz + (gq - k * gp) * q.xyz) / (1.0 - k * k), unused;
  return abs(obstacle_surface(one_of_the_obstacles(m.obstacle), line, unused)) < tolerance;
}
// The faces of a crease or corner, nearest first: the obstacle's mirror; the others take the
// free wall bits in order (a corner's third face is none where it is zero).
void take_faces(inout Mirrors m, int free, vec4 first, vec4 second, vec4 third) {
  int faces = third.xyz != vec3(0.0) ? 3 : 2;
  if (height(second, m.at) < height(first, m.at)) {
    vec4 t = first;
    first = second, second = t;
  }
  if (faces == 3 && height(third, m.at) < height(second, m.at)) {
    vec4 t = second;
    second = third, third = t;
    if (height(second, m.at) < height(first, m.at)) t = first, first = second, second = t;
  }
  m.first = first;
  for (int f = 1; f < faces; ++f) {
    int bit = free & -free;
    free &= ~bit;
    m.creases |= bit;
    vec4 face = f == 1 ? second : third;
    if (bit == 1) m.faces[0] = face;
    else if (bit == 2) m.faces[1] = face;
    else m.faces[2] = face;
  }
  m.axes |= m.creases;
}
// A mesh's concave crease or corner near the particle, from the faces its probes read on two
// rings (host/sim/solids/mirrors.cpp, crease_faces, says how and why): the nearest pair that
// meets in a crease, and the nearest face meeting both, become mirrors (take_faces).
void probe_creases(inout Mirrors m, int o, int free) {
  vec3 n = m.normal, side = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 u = normalize(cross(n, side)), w = cross(n, u);
  vec4 planes[2 * CREASE_PROBES];
  vec3 feet[2 * CREASE_PROBES];
  for (int k = 0; k < 2 * CREASE_PROBES; ++k) {
    float turn = float(k) * (6.283185307 / float(CREASE_PROBES));
    vec3 along = cos(turn) * u + sin(turn) * w;
    vec3 q = m.at + (k < CREASE_PROBES ? sim.h * along : CREASE_REACH * sim.h * (along + CREASE_LIFT * n)), gradient, unused;
    float phi = field_distance(o, to_body(o, POSE_NOW, q), gradient), steep = length(gradient);
    vec3 normal = steep > 0.0 ? to_world_direction(o, POSE_NOW, gradient / steep) : vec3(0.0);
    feet[k] = q - phi * normal;
    // A blend of two faces' normals (within a voxel of a crease's bisector) is neither's, nor a
    // face whose foot the particle sees through the solid (a thin wall's far side): its plane
    // is put beyond h, where it meets none (CREASE_STEEP, mirrors.cpp).
    bool seen = phi >= 0.0 || field_distance(o, to_body(o, POSE_NOW, 0.5 * (m.at + feet[k])), unused) >= 0.0;
    planes[k] = vec4(normal, abs(steep - 1.0) < 1.0 - CREASE_STEEP && seen ? dot(normal, feet[k]) : -3.4e38);
  }
  // The chosen faces are kept as values, not indices: an array indexed at run time lives in
  // memory on a CPU device.
  float in_front = 0.5 * obstacle_data[0].y, best = sim.h;  // half the keep-out margin
  float meet = CREASE_MEET * obstacle_data[obstacle_header(o) + 1].w;  // the field reads an edge up to a voxel in
  vec4 first = vec4(0.0), second = vec4(0.0), third = vec4(0.0);
  vec3 first_foot = vec3(0.0), second_foot = vec3(0.0);
  for (int p = 0; p < 2 * CREASE_PROBES; ++p)
    for (int q = p + 1; q < 2 * CREASE_PROBES; ++q) {
      float r = crease_reach(planes[p], feet[p], planes[q], feet[q], m.at, m.distance, in_front);
      if (r < best - (q < CREASE_PROBES ? 0.0 : in_front))  // the first ring's where they tie (mirrors.cpp)
        best = r, first = planes[p], first_foot = feet[p], second = planes[q], second_foot = feet[q];
    }
  // Where a surface curves the tests above can pass two planes that are no crease's: a crease's
  // faces lie behind the particle's moves behind them and meet on the surface (mirrors.cpp,
  // crease_faces).
  if (best >= sim.h || !behind_face(m, first, 2.0 * in_front) || !behind_face(m, second, 2.0 * in_front) ||
      !faces_meet(m, first, second, meet))
    return;
  best = sim.h;
  for (int c = 0; c < 2 * CREASE_PROBES && bitCount(free) > 1; ++c) {
    float r = max(crease_reach(planes[c], feet[c], first, first_foot, m.at, m.distance, in_front),
                  crease_reach(planes[c], feet[c], second, second_foot, m.at, m.distance, in_front));
    if (r < best - (c < CREASE_PROBES ? 0.0 : in_front)) best = r, third = planes[c];
  }
  bool corner = best < sim.h && behind_face(m, third, 2.0 * in_front) && faces_meet(m, first, third, meet) &&
                faces_meet(m, second, third, meet);
  take_faces(m, free, first, second, corner ? third : vec4(0.0));
}
// A mesh's concave crease or corner near the particle, where its field marks one, once a step in
// the lists pass (Mirrors::creases, find_creases in mirrors.cpp).
void find_creases(inout Mirrors m) {
  int free = ~m.axes & 7;
  if (m.obstacle < 0 || free == 0) return;
  int o = one_of_the_obstacles(m.obstacle);
  if (obstacle_data[obstacle_header(o)].w < 1.5 || !near_crease(o, to_body(o, POSE_NOW, m.at))) return;
  probe_creases(m, o, free);
}

// The obstacle whose own surface is nearest x within h (-1: none), its distance from x and its
// outward normal at the point nearest x (h and 0 where none is).
int nearest_obstacle(vec3 x, out float distance, out vec3 normal) {
  int nearest = -1;
  distance = sim.h;
  normal = vec3(0.0);
  for (int k = 0; OBSTACLES && k < OBSTACLE_COUNT; ++k) {
    vec3 n;
    float d = obstacle_surface(k, x, n);
    if (d < distance) distance = d, normal = n, nearest = k;
  }
  return nearest;
}

Mirrors mirrors_near(vec3 x) {
  Mirrors m;
  m.axes = 0;
  for (int a = 0; a < 3; ++a) {
    float lo = x[a] - sim.domain_min[a], hi = sim.domain_max[a] - x[a];
    if (WALLS && min(lo, hi) < sim.h) m.axes |= 1 << a;  // a box narrower than 2h: the nearer wall only
    m.plane2[a] = 2.0 * (lo <= hi ? sim.domain_min[a] : sim.domain_max[a]);
  }
  m.at = x;
  m.distance = sim.h;
  m.normal = vec3(0.0);
  m.obstacle = MIRRORS_OBSTACLES ? nearest_obstacle(x, m.distance, m.normal) : -1;
  m.solid_velocity = vec3(0.0);
  m.listed = false;
  m.creases = 0;
  m.first = vec4(0.0);
  m.faces = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  if (m.obstacle >= 0) {
    m.axes |= OBSTACLE_MIRROR;
    m.solid_velocity = obstacle_displacement(one_of_the_obstacles(m.obstacle), x - m.distance * m.normal) / sim.dt;
  }
  return m;
}
// For a pass that sees the fluid only: the cell walk then yields no images.
Mirrors no_mirrors() {
  vec4 none = vec4(0.0);
  return Mirrors(0, vec3(0.0), -1, vec3(0.0), 0.0, vec3(0.0), vec3(0.0), false, 0, none, vec4[3](none, none, none));
}
// A particle's creases as a record of four vec4 (the lists pass writes it, every pass of the
// step reads it: Creases in host/sim/solids/mirrors.hpp): the nearest face's plane, then the
// face of each wall bit, (0, 0, 0, 0) where none.
vec4 crease_record(Mirrors m, int slot) {
  if (slot == 0) return m.creases != 0 ? m.first : vec4(0.0);
  return ((m.creases >> (slot - 1)) & 1) != 0 ? m.faces[slot - 1] : vec4(0.0);
}
// Takes a particle's record where it is within h of the obstacle (Mirrors::take).
void take_creases(inout Mirrors m, vec4 first, vec4 face0, vec4 face1, vec4 face2) {
  if (m.obstacle < 0 || first.xyz == vec3(0.0)) return;
  m.first = first;
  m.faces = vec4[3](face0, face1, face2);
  m.creases = (face0.xyz != vec3(0.0) ? 1 : 0) | (face1.xyz != vec3(0.0) ? 2 : 0) | (face2.xyz != vec3(0.0) ? 4 : 0);
  m.axes |= m.creases;
}
// Every image of a neighbour: for (int k = m.axes; k != 0; k = next_image(m.axes, k)) ...
int next_image(int axes, int k) { return (k - 1) & axes; }
bvec3 reflected(int k) { return bvec3((k & 1) != 0, (k & 2) != 0, (k & 4) != 0); }

// x's image across a crease's face: far away where x lies behind the face's plane, in the fluid
// beyond a thin wall, which is really there (Mirrors::of).
vec3 across_face(vec4 face, vec3 x) { return height(face, x) > 0.0 ? reflect_across(face, x) : vec3(FAR_AWAY); }

// Where the image of the particle at b (distance phi_b, normal n_b) lies seen from a (phi_a,
// n_a): at D from a, D^2 = |a - b|^2 + 4 phi_a phi_b, along grad_a D (Mirrors::obstacle_image).
vec3 pair_image(vec3 a, float phi_a, vec3 n_a, vec3 b, float phi_b) {
  vec3 apart = a - b, along = apart + 2.0 * phi_b * n_a;
  float d2 = max(dot(apart, apart) + 4.0 * phi_a * phi_b, 0.0);
  return a - sqrt(d2) * (dot(along, along) > 0.0 ? normalize(along) : n_a);
}

// Neighbour j's distance (at x) from obstacle o's surface, and the outward normal at the point
// nearest it: read from the pass's distances where the image is listed (its normal is not
// wanted then), else from o's shape.
float neighbour_distance(int o, uint j, vec3 x, bool listed, out vec3 normal) {
  normal = vec3(0.0);
#ifdef DISTANCES_BINDING
  if (DISTANCES && listed) return distances[uint(o) * sim.count + j];
#endif
  return obstacle_surface(o, x, normal);
}

// The obstacle's image of neighbour j at x, seen from the particle (Mirrors::obstacle_image says
// why); far away where the pair's images do not both lie inside the obstacle, which a listed
// image was tested for when the list was built.
vec3 obstacle_image(Mirrors m, uint j, vec3 x) {
  if (mirrors_mesh() && m.creases != 0) return across_face(m.first, x);
  int o = one_of_the_obstacles(m.obstacle);
  vec3 normal, unused;
  float distance = neighbour_distance(o, j, x, m.listed, normal);
  vec3 image = pair_image(m.at, m.distance, m.normal, x, distance);
  // An entry listed beside an obstacle that is no longer within h does not count.
  bool inside = (m.axes & OBSTACLE_MIRROR) != 0;
  if (!m.listed)
    inside = inside && obstacle_surface(o, image, unused) < 0.0 &&
             obstacle_surface(o, pair_image(x, distance, normal, m.at, m.distance), unused) < 0.0;
  return inside ? image : vec3(FAR_AWAY);
}

// x reflected across the walls of image k, and across the faces of a mesh's crease that took
// wall bits.
vec3 across_walls(Mirrors m, int k, vec3 x) {
  if (mirrors_mesh() && m.creases != 0) {
    for (int a = 0; a < 3; ++a)
      if (((k & m.creases) >> a & 1) != 0) x = across_face(m.faces[a], x);
    k &= ~m.creases;
  }
  // A point behind a wall (an obstacle's image through a glass's floor standing on the tank's)
  // is no fluid's: its reflection would fold the fluid above onto the particle (Mirrors::of).
  vec3 beyond = (2.0 * x - m.plane2) * (2.0 * m.at - m.plane2);
  if (MIRRORS_OBSTACLES && any(lessThanEqual(mix(vec3(1.0), beyond, reflected(k)), vec3(0.0)))) return vec3(FAR_AWAY);
  return mix(x, m.plane2 - x, reflected(k));
}
// Whether the fluid sticks to any obstacle (Derived::sticky): the pull along it is compiled in.
layout(constant_id = 97) const bool STICKY = false;
bool sticks(int k) { return STICKY && obstacle_data[obstacle_header(k) + 2].w > 0.5; }
// The pull of image k of a neighbour moving at vj on the particle moving at vi where the fluid
// does not slip along the obstacle, per kernel volume (Mirrors::stick).
vec3 stick(Mirrors m, int k, vec3 vi, vec3 vj) {
  if (k != OBSTACLE_MIRROR || !sticks(one_of_the_obstacles(m.obstacle))) return vec3(0.0);
  vec3 n = mirrors_mesh() && m.creases != 0 ? m.first.xyz : m.normal;
  vec3 both = vi + vj - 2.0 * m.solid_velocity;  // u_i + u_j, each relative to the solid
  return dot(both, n) * n - both;
}
// Whether image k lies behind the obstacle (Mirrors::solid): its share of a push is the solid's.
bool solid_image(Mirrors m, int k) { return (k & (OBSTACLE_MIRROR | m.creases)) != 0; }
// Neighbour j at x as image k shows it.
vec3 mirror(Mirrors m, int k, uint j, vec3 x) {
  if (MIRRORS_OBSTACLES && (k & OBSTACLE_MIRROR) != 0) x = obstacle_image(m, j, x);
  return across_walls(m, k, x);
}
// An image moves as its particle, mirrored; across an obstacle, relative to its surface
// (Mirrors::velocity).
vec3 mirror_velocity(Mirrors m, int k, vec3 v) {
  if (MIRRORS_OBSTACLES && (k & OBSTACLE_MIRROR) != 0) {
    vec3 across = mirrors_mesh() && m.creases != 0 ? m.first.xyz : m.normal;
    v -= 2.0 * dot(v - m.solid_velocity, across) * across;
  }
  if (mirrors_mesh() && m.creases != 0) {
    for (int a = 0; a < 3; ++a)
      if (((k & m.creases) >> a & 1) != 0) v -= 2.0 * dot(v - m.solid_velocity, m.faces[a].xyz) * m.faces[a].xyz;
    k &= ~m.creases;
  }
  return mix(v, -v, reflected(k));
}

// How far along the move d from `from` mesh k's grown surface is met, in its body frame
// (obstacles.cpp, trace); 1 where it is not, 0 where `from` touches it.
float trace(int k, vec3 from, vec3 d, float contact) {
  vec3 normal;
  float margin = obstacle_data[0].y, len = length(d);
  float start = body_surface(k, from, normal) - margin;
  if (start < contact) return 1.0;  // touching: the projection's
  float end = body_surface(k, from + d, normal) - margin;
  if (end > 0.0 && len <= start + end) return 1.0;  // the free spheres about its ends cover the move
  int steps = clamp(int(ceil(len / obstacle_data[obstacle_header(k) + 1].w)), 1, TRACE_STEPS);  // a voxel apart
  float outside = 0.0;
  for (int s = 1; s <= steps; ++s) {
    float u = float(s) / float(steps);
    if (body_surface(k, from + u * d, normal) - margin < 0.0) {
      for (int b = 0; b < TRACE_BISECTIONS; ++b) {
        float middle = 0.5 * (outside + u);
        if (body_surface(k, from + middle * d, normal) - margin < 0.0) u = middle;
        else outside = middle;
      }
      return outside;
    }
    outside = u;
  }
  return 1.0;
}

// How far along the move from -> to, in obstacle k's body frame, its grown shape is first
// entered (stop_at_rest); 1 where it is not. A start within `contact` touches it and is left
// to the projection.
float first_entry(int k, vec3 from, vec3 to, float contact) {
  vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
  vec3 d = to - from;
  if (has_shape(MESH) && a.w > 1.5) return trace(k, from, d, contact);
  if (has_shape(SPHERE) && a.w > 0.5) {  // the smaller root of |from + t d - c|^2 = r^2
    vec3 f = from - a.xyz;
    float qa = dot(d, d), qb = dot(f, d), qc = dot(f, f) - b.x * b.x;
    float disc = qb * qb - qa * qc;
    if (length(f) < b.x + contact || qa == 0.0 || disc < 0.0) return 1.0;  // touching, still, or a miss
    float t = (-qb - sqrt(disc)) / qa;
    return t >= 0.0 && t <= 1.0 ? t : 1.0;
  }
  if (!has_shape(BOX)) return 1.0;
  if (all(greaterThan(from, a.xyz - contact)) && all(lessThan(from, b.xyz + contact))) return 1.0;  // touching
  float t_enter = 0.0, t_exit = 1.0;
  for (int c = 0; c < 3; ++c) {  // slabs
    if (d[c] == 0.0) {
      if (from[c] <= a[c] || from[c] >= b[c]) return 1.0;
      continue;
    }
    float t0 = (a[c] - from[c]) / d[c], t1 = (b[c] - from[c]) / d[c];
    t_enter = max(t_enter, min(t0, t1));
    t_exit = min(t_exit, max(t0, t1));
  }
  return t_enter < t_exit ? t_enter : 1.0;
}

// Where the move from -> to first enters an obstacle (host/sim/solids/obstacles.cpp, stop_at): a
// fast particle stops at the first surface it meets instead of tunnelling through. Each
// obstacle sees the move in its body frame, from its pose at the step's start to its end;
// each can only shorten it.
vec3 stop_at_solids(vec3 from, vec3 to, inout float work) {
  float contact = 1e-3 * sim.h;
  for (int k = 0; k < OBSTACLE_COUNT; ++k) {
    vec3 a = to_body(k, POSE_BEFORE, from), b = to_body(k, POSE_NOW, to);
    float t = first_entry(k, a, b, contact);
    if (t >= 1.0) continue;
    vec3 stopped = to_world(k, POSE_NOW, a + t * (b - a));
    if (!sticks(k)) {  // only the move's part into the solid is stopped (obstacles.cpp, stop_at)
      vec3 normal;
      obstacle_surface(k, from, normal);
      stopped = to + dot(stopped - to, normal) * normal;
    }
    if (!push_body(k, stopped, stopped - to)) work += push_work(stopped - to, obstacle_displacement(k, stopped));
    to = stopped;
  }
  return to;
}

// x moved onto the nearest surface of each obstacle it is inside (project_out), then into the
// walls. A box's face from which the walls' clamp would put x back inside is no candidate.
vec3 project_out_of_solids(vec3 x, inout float work) {
  float margin = obstacle_data[0].y;
  for (int k = 0; k < OBSTACLE_COUNT; ++k) {
    vec4 a = obstacle_data[obstacle_header(k)], b = obstacle_data[obstacle_header(k) + 1];
    if (!has_shape(BOX) || a.w > 0.5) {  // a sphere, a mesh: along the normal
      vec3 normal;
      float d = obstacle_surface(k, x, normal) - margin;
      if (d < 0.0) {
        if (!push_body(k, x - d * normal, -d * normal)) work += push_work(-d * normal, obstacle_displacement(k, x - d * normal));
        x -= d * normal;
      }
      continue;
    }
    vec3 body = to_body(k, POSE_NOW, x), best = x;
    if (!(all(greaterThan(body, a.xyz)) && all(lessThan(body, b.xyz)))) continue;
    float nearest = 3.4e38;
    for (int f = 0; f < 6; ++f) {
      int c = f % 3;
      vec3 onto = body;
      onto[c] = f < 3 ? a[c] : b[c];
      vec3 w = to_world(k, POSE_NOW, onto);
      float tolerance = 1e-6 * (1.0 + length(w));  // a rotated face's rounding
      vec3 kept = to_body(k, POSE_NOW, clamp(w, sim.wall_min, sim.wall_max));
      bool back_inside = all(greaterThan(kept, a.xyz + tolerance)) && all(lessThan(kept, b.xyz - tolerance));
      float move = abs(onto[c] - body[c]);
      if (move < nearest && !back_inside) nearest = move, best = w;
    }
    if (!push_body(k, best, best - x)) work += push_work(best - x, obstacle_displacement(k, best));
    x = best;
  }
  return project_to_walls(x);
}


// The prediction x* = x + v dt, stopped at the first solid it meets and kept out of them all;
// `work` gains what moving solids did in it.
vec3 predicted_position(vec3 x, vec3 v, inout float work) {
  return project_out_of_solids(stop_at_solids(x, x + v * sim.dt, work), work);
}

#endif
