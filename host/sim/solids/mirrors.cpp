#include "sim/solids/mirrors.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "shaders/contract.h"

namespace pbflow {

namespace {
constexpr double kFarAway = 1e18;  // where an image that does not count is put: beyond every kernel

// Where the image of the particle at b (distance phi_b) lies seen from a (phi_a, normal n_a).
glm::dvec3 pair_image(const glm::dvec3& a, double phi_a, const glm::dvec3& n_a, const glm::dvec3& b, double phi_b) {
  const glm::dvec3 apart = a - b, along = apart + 2 * phi_b * n_a;
  const double d2 = std::max(glm::dot(apart, apart) + 4 * phi_a * phi_b, 0.0);
  return a - std::sqrt(d2) * (glm::dot(along, along) > 0 ? glm::normalize(along) : n_a);
}

// A face as the field shows it from a point q at distance phi, gradient g: the surface point
// nearest q (its foot) and the plane there. Where the field blends two faces (|g| off 1, within
// a voxel of a crease's bisector) it shows neither: such a face is never one of a crease.
struct Face {
  glm::dvec3 foot;
  Plane plane;
  bool clean;
  double gap(const glm::dvec3& x) const { return plane.height(x); }
};
Face face_at(const glm::dvec3& q, double phi, const glm::dvec3& g) {
  const double steep = glm::length(g);
  const glm::dvec3 n = steep > 0 ? g / steep : glm::dvec3(0.0);
  return {q - phi * n, {n, glm::dot(n, q) - phi}, std::abs(steep - 1) < 1 - CREASE_STEEP};
}

// The point nearest x of the line where planes p and q meet (they are not parallel).
glm::dvec3 meeting_point(const Plane& p, const Plane& q, const glm::dvec3& x) {
  const double k = glm::dot(p.normal, q.normal), gp = p.height(x), gq = q.height(x);
  return x - ((gp - k * gq) * p.normal + (gq - k * gp) * q.normal) / (1 - k * k);
}

// How far from x the farther of faces p and q lies where they meet in a concave crease within h
// of x (at distance phi from the surface), h where they do not. They do where their normals part
// by over 75 degrees (a crease about square: at wider ones, and inside a cup's round wall, the
// probes' tangent planes and blends of two faces passed as faces and squeezed the fluid there;
// there the obstacle's pair image stands), each face's foot lies `in_front` of the other's
// plane (at a convex edge the feet lie on the edge, or behind) and the nearer plane is as far
// from x as the surface is (within `in_front`: inside a sphere tangent planes apart are farther).
double crease_reach(const Face& p, const Face& q, const glm::dvec3& x, double phi, double h, double in_front) {
  const double gap_p = p.gap(x), gap_q = q.gap(x), reach = std::max(gap_p, gap_q);
  const bool crease = p.clean && q.clean && glm::dot(p.plane.normal, q.plane.normal) < CREASE_COSINE && gap_p > 0 &&
                      gap_q > 0 && reach < h && std::abs(std::min(gap_p, gap_q) - phi) < in_front &&
                      p.gap(q.foot) > in_front && q.gap(p.foot) > in_front;
  return crease ? reach : h;
}

// The faces of a concave crease or corner of a surface within h of x (Mirrors::creases), at
// most `most` of them, nearest first, into `faces`; their count, 0 where there is none. The
// faces' planes are read from the field at probes about x (at distance phi, normal n), on two
// rings of CREASE_PROBES: one h from x along its nearest face, so that every face within h lies
// behind or beside a probe, and one CREASE_REACH h out, lifted CREASE_LIFT of that along n to
// the fluid's side, as the first ring's probes cross a wall a spacing thick (a glass's) and
// read its far side. On a crease's bisector x's own normal blends the two faces' (or, on the
// field's kink, is none), but the probes read each face's own. The nearest pair that meets in a
// crease is one (inside a cup's round wall the probes also see its tangent planes farther
// round), the nearest face meeting both a corner. surface(q, gradient) is the field's distance
// at q and its gradient (not normalised).
constexpr int kProbes = 2 * CREASE_PROBES;
template <class Surface>
int crease_faces(Surface&& surface, const glm::dvec3& x, double phi, const glm::dvec3& n, double h,
                 double in_front, double meet_within, int most, Plane faces[3]) {
  const glm::dvec3 side = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(n, side)), w = glm::cross(n, u);
  Face seen[kProbes];
  for (int k = 0; k < kProbes; ++k) {
    const double turn = k * (2 * M_PI / CREASE_PROBES);
    const glm::dvec3 along = std::cos(turn) * u + std::sin(turn) * w;
    const glm::dvec3 q = x + (k < CREASE_PROBES ? h * along : CREASE_REACH * h * (along + CREASE_LIFT * n));
    glm::dvec3 gradient, unused;
    const double at_q = surface(q, gradient);
    seen[k] = face_at(q, at_q, gradient);
    // A probe in the solid may read the far side of a thin wall: a face is x's only where the
    // way from x to its foot lies in the fluid.
    if (at_q < 0 && surface(0.5 * (x + seen[k].foot), unused) < 0) seen[k].clean = false;
  }
  // A lifted probe's face is taken over the first ring's only where it is nearer by `in_front`:
  // where two readings tie (a corner's trisector), a lifted probe's may be a blend.
  auto lifted = [&](int k) { return k < CREASE_PROBES ? 0.0 : in_front; };
  int chosen[3] = {-1, -1, -1};
  double best = h;
  for (int a = 0; a < kProbes; ++a)
    for (int b = a + 1; b < kProbes; ++b)
      if (const double r = crease_reach(seen[a], seen[b], x, phi, h, in_front); r < best - lifted(b)) best = r, chosen[0] = a, chosen[1] = b;
  // Where a surface curves the tests above can pass two planes that are no crease's. At a
  // crease x moved just behind a face lies in the solid, behind a convex edge's (a cup's rim) in
  // the fluid beside it; and the faces' line of meeting is on the surface, where two tangent
  // planes of a round wall (a cup's inside) meet behind it.
  glm::dvec3 unused;
  auto behind = [&](int k) { return surface(x - (seen[k].gap(x) + 2 * in_front) * seen[k].plane.normal, unused) < 0; };
  auto meet = [&](int a, int b) {
    return std::abs(surface(meeting_point(seen[a].plane, seen[b].plane, x), unused)) < meet_within;
  };
  if (chosen[0] < 0 || most < 2 || !behind(chosen[0]) || !behind(chosen[1]) || !meet(chosen[0], chosen[1])) return 0;
  best = h;
  for (int c = 0; c < kProbes && most > 2; ++c) {
    const double r = std::max(crease_reach(seen[c], seen[chosen[0]], x, phi, h, in_front),
                              crease_reach(seen[c], seen[chosen[1]], x, phi, h, in_front));
    if (r < best - lifted(c)) best = r, chosen[2] = c;
  }
  if (chosen[2] >= 0 && (!behind(chosen[2]) || !meet(chosen[0], chosen[2]) || !meet(chosen[1], chosen[2]))) chosen[2] = -1;
  const int count = chosen[2] < 0 ? 2 : 3;
  std::sort(chosen, chosen + count, [&](int a, int b) { return seen[a].gap(x) < seen[b].gap(x); });
  for (int f = 0; f < count; ++f) faces[f] = seen[chosen[f]].plane;
  return count;
}

// Whether both faces of a crease are flat along it for 1.5 h one way or the other (a crease's end
// is a corner): the field's normal read half a voxel in front of each, two voxels from the
// crease, is the face's to a cosine of CREASE_FLAT. Round a cup's inner floor edge (its wall 2 h
// in radius) the faces' planes are the facets', whose mirrors read the fluid there thin and
// stirred the cup at rest (0.057 m/s after 4 s); there the nearest face's pair image stands.
template <class Surface>
bool flat_crease(Surface&& surface, const glm::dvec3& x, const Plane& p, const Plane& q, double h, double voxel) {
  const glm::dvec3 line = meeting_point(p, q, x), along = glm::normalize(glm::cross(p.normal, q.normal));
  auto flat = [&](const Plane& f, const Plane& g, double way) {
    const glm::dvec3 off = glm::normalize(g.normal - glm::dot(g.normal, f.normal) * f.normal);  // on f, from g
    for (int step = 1; step <= 3; ++step) {
      glm::dvec3 gradient;
      surface(line + way * step * 0.5 * h * along + 2 * voxel * off + 0.5 * voxel * f.normal, gradient);
      if (glm::length(gradient) == 0 || glm::dot(glm::normalize(gradient), f.normal) < CREASE_FLAT) return false;
    }
    return true;
  };
  return (flat(p, q, 1) && flat(q, p, 1)) || (flat(p, q, -1) && flat(q, p, -1));
}

}  // namespace

void mark_creases(DistanceField& field, double h, double keep_out) {
  const glm::ivec3 dims = field.dims;
  const size_t count = field.values.size();
  std::vector<uint8_t> found(count, 0);
  auto surface = [&](const glm::dvec3& q, glm::dvec3& gradient) { return field.sample(q, gradient); };
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        const glm::dvec3 at = field.origin + field.voxel * glm::dvec3(x, y, z);
        glm::dvec3 gradient;
        const double phi = surface(at, gradient);
        const glm::dvec3 normal = glm::length(gradient) > 0 ? glm::normalize(gradient) : glm::dvec3(0, 1, 0);  // as Obstacle::surface's
        Plane faces[3];
        if (phi > 0 && phi < h && crease_faces(surface, at, phi, normal, h, 0.5 * keep_out, CREASE_MEET * field.voxel, 2, faces) > 0)
          found[field.index({x, y, z})] = flat_crease(surface, at, faces[0], faces[1], h, field.voxel);
      }
  // Each node's neighbours' too: a particle between nodes may see the crease its nearest misses.
  field.creases.assign((count + 31) / 32, 0u);
  for (int z = 0; z < dims.z; ++z)
    for (int y = 0; y < dims.y; ++y)
      for (int x = 0; x < dims.x; ++x) {
        bool near = false;
        for (int c = 0; c < 27 && !near; ++c) {
          const glm::ivec3 p = glm::ivec3(x, y, z) + glm::ivec3(c % 3, c / 3 % 3, c / 9) - 1;
          near = glm::all(glm::greaterThanEqual(p, glm::ivec3(0))) && glm::all(glm::lessThan(p, dims)) &&
                 found[field.index(p)];
        }
        const size_t k = field.index({x, y, z});
        if (near) field.creases[k / 32] |= 1u << (k % 32);
      }
}

Mirrors mirrors_near(const Derived& d, const glm::dvec3& x) {
  Mirrors m;
  m.at = x;
  for (int a = 0; a < 3; ++a) {
    const double lo = x[a] - d.domain_min[a], hi = d.domain_max[a] - x[a];
    if (d.walls_mirror && std::min(lo, hi) < d.h) m.axes |= 1 << a;  // a box narrower than 2h: the nearer wall only
    m.plane2[a] = 2 * (lo <= hi ? d.domain_min[a] : d.domain_max[a]);
  }
  m.distance = d.h;
  for (const Obstacle& grown : d.obstacles) {
    const Obstacle o = grown.grown(-d.keep_out);
    glm::dvec3 normal;
    if (const double distance = o.surface(x, normal); distance < m.distance) {
      m.distance = distance;
      m.normal = normal;
      m.obstacle = o;
      m.axes |= kObstacleMirror;
    }
  }
  if (m.axes & kObstacleMirror) {
    m.solid_velocity = m.obstacle.displacement(x - m.distance * m.normal) / d.dt;
  }
  return m;
}

Creases find_creases(const Derived& d, const Mirrors& m) {
  Creases c;
  int free = ~m.axes & 7;
  if (!(m.axes & kObstacleMirror) || !free || m.obstacle.kind != Obstacle::Kind::Mesh ||
      !m.obstacle.field->near_crease(m.obstacle.pose.body(m.at)))
    return c;
  Plane faces[3];
  auto surface = [&](const glm::dvec3& q, glm::dvec3& gradient) { return m.obstacle.mesh_surface(q, gradient); };
  const int count = crease_faces(surface, m.at, m.distance, m.normal, d.h, 0.5 * d.keep_out, CREASE_MEET * m.obstacle.field->voxel,
                                   1 + std::popcount(unsigned(free)), faces);
  if (count == 0) return c;
  c.first = faces[0];
  for (int f = 1; f < count; ++f) {
    const int bit = free & -free;
    free &= ~bit;
    c.bits |= bit;
    c.faces[std::countr_zero(unsigned(bit))] = faces[f];
  }
  return c;
}

void Mirrors::take(const Creases& c) {
  if (!(axes & kObstacleMirror) || !c.bits) return;
  creases = c;
  axes |= c.bits;
}

// x's image across a crease's face: far away where x lies behind the face's plane, in the fluid
// beyond a thin wall, which is really there (counted, a glass's wall layer read up to 40 % dense).
namespace {
glm::dvec3 across_face(const Plane& face, const glm::dvec3& x) {
  return face.height(x) > 0 ? face.reflect(x) : glm::dvec3(kFarAway);
}
}  // namespace

glm::dvec3 Mirrors::obstacle_image(const glm::dvec3& x, bool listed) const {
  if (creases.bits) return across_face(creases.first, x);
  glm::dvec3 n, unused;
  const double phi = obstacle.surface(x, n);
  const glm::dvec3 image = pair_image(at, distance, normal, x, phi);
  // An entry listed beside an obstacle that is no longer within h does not count.
  const bool inside = (axes & kObstacleMirror) &&
                      (listed || (obstacle.surface(image, unused) < 0 &&
                                  obstacle.surface(pair_image(x, phi, n, at, distance), unused) < 0));
  return inside ? image : glm::dvec3(kFarAway);
}

glm::dvec3 Mirrors::of(int k, const glm::dvec3& x, bool listed) const {
  glm::dvec3 y = k & kObstacleMirror ? obstacle_image(x, listed) : x;
  for (int a = 0; a < 3; ++a)
    if ((k & creases.bits) >> a & 1) y = across_face(creases.faces[a], y);
  for (int a = 0; a < 3; ++a)
    if ((k & ~creases.bits) >> a & 1) {
      // A point behind the wall (an obstacle's image through a glass's floor standing on the
      // tank's) is no fluid's: reflected, it folded the fluid above onto the particle.
      if ((2 * y[a] - plane2[a]) * (2 * at[a] - plane2[a]) <= 0) return glm::dvec3(kFarAway);
      y[a] = plane2[a] - y[a];
    }
  return y;
}

glm::dvec3 Mirrors::stick(int k, const glm::dvec3& v_i, const glm::dvec3& v) const {
  if (k != kObstacleMirror || obstacle.slip) return glm::dvec3(0.0);
  const glm::dvec3 n = creases.bits ? creases.first.normal : normal;
  const glm::dvec3 both = v_i + v - 2.0 * solid_velocity;  // u_i + u_j, each relative to the solid
  return glm::dot(both, n) * n - both;
}

glm::dvec3 Mirrors::velocity(int k, const glm::dvec3& v) const {
  glm::dvec3 u = v;
  auto across = [&](const glm::dvec3& n) { u -= 2 * glm::dot(u - solid_velocity, n) * n; };
  if (k & kObstacleMirror) across(creases.bits ? creases.first.normal : normal);
  for (int a = 0; a < 3; ++a)
    if ((k & creases.bits) >> a & 1) across(creases.faces[a].normal);
  for (int a = 0; a < 3; ++a)
    if ((k & ~creases.bits) >> a & 1) u[a] = -u[a];
  return u;
}

}  // namespace pbflow
