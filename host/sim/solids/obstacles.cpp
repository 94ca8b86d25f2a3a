#include "sim/solids/obstacles.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "shaders/contract.h"

namespace pbflow {

double DistanceField::sample(const glm::dvec3& x, glm::dvec3& gradient) const {
  const glm::dvec3 inside = glm::clamp(x, origin, extent()), beyond = x - inside;
  const glm::dvec3 g = (inside - origin) / voxel;
  const glm::ivec3 base = glm::clamp(glm::ivec3(glm::floor(g)), glm::ivec3(0), dims - 2);
  const glm::dvec3 t = g - glm::dvec3(base);
  double c[8];
  for (int k = 0; k < 8; ++k) c[k] = at(base + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  // Along x, then y, then z; the gradient from the same corners.
  const double x00 = glm::mix(c[0], c[1], t.x), x10 = glm::mix(c[2], c[3], t.x);
  const double x01 = glm::mix(c[4], c[5], t.x), x11 = glm::mix(c[6], c[7], t.x);
  const double y0 = glm::mix(x00, x10, t.y), y1 = glm::mix(x01, x11, t.y);
  const double d = glm::mix(y0, y1, t.z);
  const double dx0 = glm::mix(c[1] - c[0], c[3] - c[2], t.y), dx1 = glm::mix(c[5] - c[4], c[7] - c[6], t.y);
  gradient = glm::dvec3(glm::mix(dx0, dx1, t.z), glm::mix(x10 - x00, x11 - x01, t.z), y1 - y0) / voxel;
  const double out = glm::length(beyond);
  if (out > 0) gradient = beyond / out;
  return d + out;
}

bool DistanceField::near_crease(const glm::dvec3& x) const {
  const glm::ivec3 p = glm::ivec3(glm::floor((x - origin) / voxel + 0.5));
  if (creases.empty() || glm::any(glm::lessThan(p, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(p, dims))) return false;
  const size_t k = index(p);
  return creases[k / 32] >> (k % 32) & 1;
}

bool Obstacle::contains(const glm::dvec3& x) const {
  const glm::dvec3 b = pose.body(x);
  if (kind == Kind::Box) return glm::all(glm::greaterThan(b, min)) && glm::all(glm::lessThan(b, max));  // body_surface < 0, fast
  glm::dvec3 unused;
  return body_surface(b, unused) < 0;
}

Obstacle Obstacle::grown(double margin) const {
  Obstacle o = *this;
  o.min -= margin;
  o.max += margin;
  o.radius += margin;
  o.margin += margin;
  return o;
}

double Obstacle::surface(const glm::dvec3& x, glm::dvec3& normal) const {
  const double d = body_surface(pose.body(x), normal);
  normal = pose.rotation * normal;
  return d;
}

double Obstacle::mesh_surface(const glm::dvec3& x, glm::dvec3& gradient) const {
  const double d = field->sample(pose.body(x), gradient) - margin;
  gradient = pose.rotation * gradient;
  return d;
}

double Obstacle::body_surface(const glm::dvec3& x, glm::dvec3& normal) const {
  if (kind == Kind::Sphere) {
    const glm::dvec3 d = x - centre;
    const double r = glm::length(d);
    normal = r > 0 ? d / r : glm::dvec3(0, 1, 0);
    return r - radius;
  }
  if (kind == Kind::Mesh) {
    glm::dvec3 gradient;
    const double d = field->sample(x, gradient) - margin;
    normal = glm::length(gradient) > 0 ? glm::normalize(gradient) : glm::dvec3(0, 1, 0);
    return d;
  }
  const glm::dvec3 out = x - glm::clamp(x, min, max);
  if (const double outside = glm::length(out); outside > 0) {
    normal = out / outside;
    return outside;
  }
  double depth = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c) {
    glm::dvec3 axis(0.0);
    axis[c] = 1;
    if (x[c] - min[c] < depth) depth = x[c] - min[c], normal = -axis;
    if (max[c] - x[c] < depth) depth = max[c] - x[c], normal = axis;
  }
  return -depth;
}

namespace {
// A node's reach sampled: each sample's place in (-1, 1) per axis and its tent weight.
struct ReachSamples {
  std::array<glm::dvec3, kReachSamples> t;
  std::array<double, kReachSamples> w;
  double all = 0;
  ReachSamples() {
    const int n = 2 * COARSE_OPEN_SAMPLES;
    for (int k = 0; k < kReachSamples; ++k) {
      t[size_t(k)] = (glm::dvec3(k % n, k / n % n, k / (n * n)) + 0.5) / double(COARSE_OPEN_SAMPLES) - 1.0;
      const glm::dvec3 tent = 1.0 - glm::abs(t[size_t(k)]);
      w[size_t(k)] = tent.x * tent.y * tent.z;
      all += w[size_t(k)];
    }
  }
};
const ReachSamples kSamples;
}  // namespace

void mark_inside(const Obstacle& o, const glm::dvec3& centre, const glm::dvec3& reach, std::span<uint64_t> inside) {
  if (o.kind != Obstacle::Kind::Mesh) {  // a box's or ball's distance is exact: far from its surface
    glm::dvec3 unused;                   // every sample lies on the node's side
    const double d = o.surface(centre, unused);
    if (d > glm::length(reach)) return;
    if (d < -glm::length(reach)) {
      for (int k = 0; k < kReachSamples; ++k) inside[size_t(k) / 64] |= uint64_t(1) << (k % 64);
      return;
    }
  }
  for (size_t k = 0; k < size_t(kReachSamples); ++k) {
    uint64_t& word = inside[k / 64];
    const uint64_t bit = uint64_t(1) << (k % 64);
    if (!(word & bit) && o.contains(centre + kSamples.t[k] * reach)) word |= bit;
  }
}

double open_share(std::span<const uint64_t> inside) {
  double open = 0;
  for (size_t k = 0; k < size_t(kReachSamples); ++k)
    if (!(inside[k / 64] >> (k % 64) & 1)) open += kSamples.w[k];
  return open / kSamples.all;
}

glm::dvec3 project_out(const Obstacle& o, const glm::dvec3& x, const glm::dvec3& wall_min,
                       const glm::dvec3& wall_max) {
  glm::dvec3 normal;
  const double d = o.surface(x, normal);
  if (d >= 0) return x;
  if (o.kind != Obstacle::Kind::Box) return x - d * normal;  // along the normal: onto a sphere, a mesh
  // A box: onto the nearest face from which the walls' clamp does not put x back inside.
  const glm::dvec3 b = o.pose.body(x);
  glm::dvec3 best = x, unused;
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 6; ++k) {
    glm::dvec3 onto = b;
    onto[k % 3] = k < 3 ? o.min[k] : o.max[k - 3];
    const glm::dvec3 w = o.pose.world(onto);
    const double tolerance = 1e-6 * (1 + glm::length(w));  // a rotated face's rounding, in float on the GPU
    if (const double move = std::abs(onto[k % 3] - b[k % 3]);
        move < nearest && o.surface(glm::clamp(w, wall_min, wall_max), unused) > -tolerance)
      nearest = move, best = w;
  }
  return best;
}

namespace {
// A mesh's move is marched (shaders/contract.h, TRACE_STEPS): its surface looked for at points a
// voxel apart and the first met bisected. A sphere trace, each step as long as the free sphere
// about where it is, crawls along a face a particle slides beside and stopped it there: the
// wall layer beside a mesh box stirred at twice the speed it does beside the same box as a box.
// A move the free spheres about its two ends cover crosses no surface.
glm::dvec3 trace(const Obstacle& o, const glm::dvec3& from, const glm::dvec3& d) {
  glm::dvec3 normal;
  if (const double end = o.surface(from + d, normal); end > 0 && glm::length(d) <= o.surface(from, normal) + end)
    return from + d;
  const int steps = std::clamp(int(std::ceil(glm::length(d) / o.field->voxel)), 1, TRACE_STEPS);  // a voxel apart
  double outside = 0;
  for (int k = 1; k <= steps; ++k) {
    double u = double(k) / steps;
    if (o.surface(from + u * d, normal) < 0) {
      for (int b = 0; b < TRACE_BISECTIONS; ++b) {
        const double middle = 0.5 * (outside + u);
        (o.surface(from + middle * d, normal) < 0 ? u : outside) = middle;
      }
      return from + outside * d;
    }
    outside = u;
  }
  return from + d;
}

// stop_at for a solid at rest in its body frame.
glm::dvec3 stop_at_rest(const Obstacle& o, const glm::dvec3& from, const glm::dvec3& to, double contact) {
  if (o.grown(contact).contains(from)) return to;  // touching or inside: project_out handles it
  const glm::dvec3 d = to - from;
  double t_enter = 0, t_exit = 1;
  if (o.kind == Obstacle::Kind::Mesh) return trace(o, from, d);
  if (o.kind == Obstacle::Kind::Sphere) {
    // |from + t d - c|^2 = r^2, the smaller root
    glm::dvec3 f = from - o.centre;
    double a = glm::dot(d, d), b = glm::dot(f, d), c = glm::dot(f, f) - o.radius * o.radius;
    double disc = b * b - a * c;
    if (a == 0 || disc < 0) return to;
    t_enter = (-b - std::sqrt(disc)) / a;
    if (t_enter < 0 || t_enter > 1) return to;
    return from + t_enter * d;
  }
  for (int k = 0; k < 3; ++k) {  // slabs
    if (d[k] == 0) {
      if (from[k] <= o.min[k] || from[k] >= o.max[k]) return to;
      continue;
    }
    double t0 = (o.min[k] - from[k]) / d[k], t1 = (o.max[k] - from[k]) / d[k];
    t_enter = std::max(t_enter, std::min(t0, t1));
    t_exit = std::min(t_exit, std::max(t0, t1));
  }
  return t_enter < t_exit ? from + t_enter * d : to;
}

// Where the move from -> to first meets `o`, carried with the solid where it moves.
glm::dvec3 first_hit(const Obstacle& o, const glm::dvec3& from, const glm::dvec3& to, double contact) {
  if (o.pose == Pose{} && o.previous == Pose{}) return stop_at_rest(o, from, to, contact);
  // Moving: the move as the solid sees it, from its start pose to its end pose.
  Obstacle still = o;
  still.pose = still.previous = Pose{};
  const glm::dvec3 b = o.pose.body(to), hit = stop_at_rest(still, o.previous.body(from), b, contact);
  return hit == b ? to : o.pose.world(hit);
}
}  // namespace

glm::dvec3 stop_at(const Obstacle& o, const glm::dvec3& from, const glm::dvec3& to, double contact, double margin) {
  const glm::dvec3 hit = first_hit(o, from, to, contact);
  if (hit == to || !o.slip) return hit;
  glm::dvec3 normal;
  o.grown(-margin).surface(from, normal);
  return to + glm::dot(hit - to, normal) * normal;
}

bool any_mesh(const std::vector<Obstacle>& solids) {
  return std::ranges::any_of(solids, [](const Obstacle& o) { return o.kind == Obstacle::Kind::Mesh; });
}

size_t packed_obstacle_vec4s(const std::vector<Obstacle>& obstacles) {
  size_t values = 0;
  for (const Obstacle& o : obstacles)
    if (o.kind == Obstacle::Kind::Mesh) values += o.field->values.size() + o.field->creases.size();
  return obstacle_header_vec4s(obstacles.size()) + (values + 3) / 4;
}

namespace {
// A pose as the GPU reads it: the rows of its body transform, x_body = R^T x_world + shift.
void pack_pose(const Pose& p, std::vector<glm::vec4>& data) {
  const glm::dmat3 to_body = glm::transpose(p.rotation);
  const glm::dvec3 shift = -(to_body * p.translation);
  for (int r = 0; r < 3; ++r) data.emplace_back(to_body[0][r], to_body[1][r], to_body[2][r], shift[r]);
}
}  // namespace

std::vector<glm::vec4> pack_obstacle_header(const std::vector<Obstacle>& obstacles, double margin,
                                            const TankKick& tank_kick) {
  std::vector<glm::vec4> data{glm::vec4(0, float(margin), 0, 0),  // the count is the shaders' OBSTACLE_COUNT
                              glm::vec4(glm::vec3(tank_kick.linear), tank_kick.none() ? 0.0f : 1.0f)};
  for (const glm::dmat3* m : {&tank_kick.of_x, &tank_kick.of_v})
    for (int c = 0; c < 3; ++c) data.emplace_back(glm::vec3((*m)[c]), 0.0f);
  size_t first = 0;  // the mesh's first field value
  for (const Obstacle& o : obstacles) {
    if (o.kind == Obstacle::Kind::Sphere) {
      data.emplace_back(glm::vec3(o.centre), 1.0f);
      data.emplace_back(float(o.radius), 0.0f, 0.0f, 0.0f);
      data.emplace_back(0.0f);
    } else if (o.kind == Obstacle::Kind::Mesh) {
      data.emplace_back(glm::vec3(o.field->origin), 2.0f);
      data.emplace_back(glm::vec3(o.field->dims), float(o.field->voxel));
      data.emplace_back(float(first), 0.0f, 0.0f, 0.0f);
      first += o.field->values.size() + o.field->creases.size();
    } else {
      data.emplace_back(glm::vec3(o.min), 0.0f);
      data.emplace_back(glm::vec3(o.max), 0.0f);
      data.emplace_back(0.0f);
    }
    data.back().y = o.moves() ? 1.0f : 0.0f;
    data.back().z = o.dynamic() ? float(o.body + 1) : 0.0f;  // 0: no body moves it (solids.glsl's body_of)
    data.back().w = o.slip ? 0.0f : 1.0f;
    pack_pose(o.pose, data);
    pack_pose(o.previous, data);
  }
  return data;
}

std::vector<glm::vec4> pack_obstacles(const std::vector<Obstacle>& obstacles, double margin, const TankKick& tank_kick) {
  std::vector<glm::vec4> data = pack_obstacle_header(obstacles, margin, tank_kick);
  data.reserve(packed_obstacle_vec4s(obstacles));
  std::vector<float> values;  // the meshes' fields, each's values and then its crease bits, after the header
  for (const Obstacle& o : obstacles)
    if (o.kind == Obstacle::Kind::Mesh) {
      values.insert(values.end(), o.field->values.begin(), o.field->values.end());
      for (uint32_t bits : o.field->creases) values.push_back(std::bit_cast<float>(bits));
    }
  values.resize((values.size() + 3) / 4 * 4, 0.0f);
  for (size_t k = 0; k < values.size(); k += 4) data.emplace_back(values[k], values[k + 1], values[k + 2], values[k + 3]);
  return data;
}

}  // namespace pbflow
