// Static obstacles (host/obstacles.hpp, already grown by half a spacing), for the
// passes that keep particles out of solids. The includer defines OBSTACLES_BINDING.
// Layout: obstacle_data[0].x = count; then per obstacle two vec4: box (min, 0)
// (max, 0), sphere (centre, 1) (radius, 0, 0, 0).

layout(std430, binding = OBSTACLES_BINDING) readonly buffer Obstacles { vec4 obstacle_data[]; };

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
