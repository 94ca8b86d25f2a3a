#pragma once
// Every solid is a mirror (shaders/solids.glsl runs the same): behind each wall within h of a
// particle, behind each pair and the triple of them at edges and corners, and behind the
// nearest obstacle within h (obstacle_image; at a mesh's square crease or corner behind each of
// its faces, as at walls: Creases) lies the reflection of its neighbours. Ghost particles made this way continue
// any lattice exactly across a plane, so walls and flat faces read rho0 at faces, edges and
// corners alike; and they mirror the fluid that is really there, so a solid next to a free
// surface does not add density that is not there (the earlier wall term counted a full
// lattice behind every wall, which pushed surface particles off the walls).
#include <glm/glm.hpp>

#include "sim/params.hpp"

namespace pbflow {

// An image is a bit mask of mirrors: bits 0-2 the walls of each axis, this bit the obstacle.
// At a mesh's concave crease or corner its other faces take wall bits the particle has free.
constexpr int kObstacleMirror = 8;
constexpr int kImages = 16;  // masks 0 (the neighbour itself) to 15

// A mirror plane: the points y with dot(normal, y) = offset, normal out of the solid.
struct Plane {
  glm::dvec3 normal{0.0};
  double offset = 0;
  double height(const glm::dvec3& y) const { return glm::dot(normal, y) - offset; }  // y's above it
  glm::dvec3 reflect(const glm::dvec3& y) const { return y - 2 * height(y) * normal; }
};

// A mesh's concave crease or corner near a particle (find_creases): the wall bits its faces
// other than the nearest take (0: none), the nearest face's plane and theirs (faces[a] for bit
// a). Found once a step, when the neighbour lists are built, and taken by every pass of it.
struct Creases {
  int bits = 0;
  Plane first, faces[3];
};

struct Mirrors {
  int axes = 0;               // the mirrors within h, as image bits
  glm::dvec3 plane2{0.0};     // twice the nearer wall's coordinate on each wall axis
  Obstacle obstacle;          // the nearest obstacle within h, its own surface
  glm::dvec3 at{0.0};         // the particle they are seen from
  double distance = 0;        // its distance to that obstacle
  glm::dvec3 normal{0.0};     // and the obstacle's outward normal at the point nearest it
  glm::dvec3 solid_velocity{0.0};  // the velocity of that point over the step (0: it stands still)
  // At a mesh's concave crease or corner (taken from the step's record): each face is a plane
  // mirror, as walls meeting at an edge or corner are, the nearest the obstacle's bit.
  Creases creases;
  void take(const Creases& c);  // where the particle is within h of the obstacle

  // Whether image k lies behind the obstacle (its share of a pass's push is the solid's).
  bool solid(int k) const { return (k & (kObstacleMirror | creases.bits)) != 0; }

  // Neighbour x's image `k` (0: x itself); far away where an obstacle's image does not count.
  // A `listed` image was tested when the lists were built and counts until they are rebuilt.
  glm::dvec3 of(int k, const glm::dvec3& x, bool listed = false) const;
  // An image moves as its particle, mirrored: across an obstacle, its velocity relative to the
  // solid's surface is (the normal part reversed, so the fluid slips along a moving solid too).
  glm::dvec3 velocity(int k, const glm::dvec3& v) const;
  // Where the fluid does not slip along the obstacle (Obstacle::slip), the pull of the image k
  // of a neighbour moving at v on the particle moving at v_i, per kernel volume: the image
  // moves as the neighbour reversed relative to the solid, and the pull is the difference's
  // part along the surface. A pair's two pulls see one distance, so the pull only removes
  // energy (in the solid's frame: -|P (u_i + u_j)|^2 W for the pair). Zero for other images.
  glm::dvec3 stick(int k, const glm::dvec3& v_i, const glm::dvec3& v) const;

  // The obstacle's image of neighbour x: at D from the particle, D^2 = |x_i - x|^2 + 4 phi_i
  // phi_x with phi the distance to the surface, along grad_i D. Across a plane this is the
  // reflection (|x_i - R x|^2 expands to it). Across a curve it stays a pair's term: D is the
  // same seen from either particle, where a tangent plane (the particle's own, or one shared
  // by the pair) turns with the particles.
  // It counts only where the pair's images (each seen from the other) both lie inside the
  // obstacle: round a box's edge or across a thin plate the fluid they would stand for is
  // really there (a lattice beside a box read up to 2.5 % high one spacing from an edge
  // without it). The test is made when the neighbour lists are built, once a step: made in
  // every pass, it was 60 % of a mesh obstacle's constraint passes on lavapipe.
  glm::dvec3 obstacle_image(const glm::dvec3& x, bool listed) const;
};

// The work per unit mass (J/kg) a solid does pushing a particle by dx while its surface there
// moves by `moved` over a step of dt: its force m dx / dt^2 times its velocity moved / dt, for
// dt. A pass that moves a particle for a moving solid (a projection, an image's term) adds it;
// the frame's sum is FrameStats::solid_work.
inline double push_work(const glm::dvec3& dx, const glm::dvec3& moved, double dt) {
  return glm::dot(dx, moved) / (dt * dt);
}

// The mirrors seen from x: the walls within h and the nearest obstacle within h.
Mirrors mirrors_near(const Derived& d, const glm::dvec3& x);

// The creases of the mesh among mirrors `m` near its particle, where its field marks one near
// (DistanceField::creases): the faces' planes read from the field at points about the particle
// (mirrors.cpp, crease_faces, says how). shaders/solids.glsl runs the same.
Creases find_creases(const Derived& d, const Mirrors& m);

// Marks field.creases (DistanceField) at the nodes within h of a concave crease or corner of
// the field's surface, found as a particle's mirrors find one's faces, and at their neighbours.
void mark_creases(DistanceField& field, double h, double keep_out);

// One image of a neighbour, as a pass visits it.
struct Image {
  const Mirrors* mirrors;
  int k;
  bool listed;  // from a neighbour list (Mirrors::of)
  glm::dvec3 of(const glm::dvec3& x) const { return mirrors->of(k, x, listed); }
  glm::dvec3 velocity(const glm::dvec3& v) const { return mirrors->velocity(k, v); }
};

}  // namespace pbflow
