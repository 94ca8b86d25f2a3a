// Static obstacles (host/sim/obstacles.hpp, already grown by half a spacing), for the
// passes that keep particles out of solids. The includer defines OBSTACLES_BINDING.
// Layout: obstacle_data[0].x = count; then per obstacle two vec4: box (min, 0)
// (max, 0), sphere (centre, 1) (radius, 0, 0, 0).

layout(std430, binding = OBSTACLES_BINDING) readonly buffer Obstacles { vec4 obstacle_data[]; };

// Where the move from -> to first enters an obstacle (host/sim/obstacles.cpp, stop_at): a
// fast particle stops at the first surface it meets instead of tunnelling through. A
// start within 1e-3 h of an obstacle touches it and is left to the projection.
vec3 stop_at_solids(vec3 from, vec3 to) {
  int count = int(obstacle_data[0].x);
  float contact = 1e-3 * sim.h;
  vec3 d = to - from;
  float first = 1.0;
  for (int k = 0; k < count; ++k) {
    vec4 a = obstacle_data[1 + 2 * k], b = obstacle_data[2 + 2 * k];
    float t_enter = 0.0, t_exit = 1.0;
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
    vec4 a = obstacle_data[1 + 2 * k], b = obstacle_data[2 + 2 * k];
    if (a.w > 0.5) {  // sphere
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
