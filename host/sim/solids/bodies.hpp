#pragma once
// Rigid bodies the water moves and that move it (scene key "bodies"). Each is an obstacle
// (Obstacle::body) the fluid meets through the same mirrors and projections as any solid. A step:
// Bullet moves the bodies under gravity and their contacts to a predicted pose (BodyWorld::predict);
// after each pass that moves particles for a body, the body gives way by the momentum it gave
// them, as a particle of the same constraint would (BodyPush, give_way), and takes the coarse
// correction's push on the fluid its volume stands for (its buoyancy); at the step's end its
// velocity is its pose's change over the step (BodyWorld::finish), as the fluid's is.
#include <glm/glm.hpp>

#include <memory>
#include <vector>

#include "sim/solids/obstacles.hpp"

namespace pbflow {

// What a pass's pushes gave each body, in momentum times the step (kg m) and its moment about
// the body's centre (kg m^2): a push of a particle of mass m by dx at x gives -m dx there. The
// images' dashpot, a velocity change, gives momentum (kg m/s) the same way (Body::kick).
struct BodyPush {
  glm::dvec3 impulse{0.0}, moment{0.0};
  // A particle of mass m at x, beside a body whose centre is at `centre`, pushed by dx.
  void add(const glm::dvec3& centre, const glm::dvec3& x, const glm::dvec3& dx, double m) {
    impulse -= m * dx;
    moment -= glm::cross(x - centre, m * dx);
  }
};

struct Body {
  double mass = 0;                 // kg
  glm::dvec3 inertia{0.0};         // kg m^2 about the centre of mass, on its principal axes
  glm::dmat3 axes{1.0};            // the principal axes in the body frame (columns; a box's and a ball's: its own)
  glm::dvec3 centre{0.0};          // of mass, in the body frame
  glm::dvec3 velocity{0.0};        // of the centre of mass, m/s (world)
  glm::dvec3 angular_velocity{0.0};  // rad/s (world)
  size_t obstacle = 0;             // its solid, Derived::obstacles
  // Points filling its own volume (body frame), `sample_volume` m^3 each: where the coarse
  // correction's push is read (add_buoyancy).
  std::vector<glm::dvec3> samples;
  double sample_volume = 0;

  glm::dvec3 world_centre(const Pose& p) const { return p.world(centre); }
  // The turn (rad, world axis) a moment gives it at pose p: its inverse inertia times the moment.
  glm::dvec3 turn(const Pose& p, const glm::dvec3& moment) const {
    const glm::dmat3 r = p.rotation * axes;
    return r * ((glm::transpose(r) * moment) / inertia);
  }
  // The angular momentum (kg m^2/s) a spin w (rad/s, world axis) gives it at pose p: turn's inverse.
  glm::dvec3 spin_momentum(const Pose& p, const glm::dvec3& w) const {
    const glm::dmat3 r = p.rotation * axes;
    return r * (inertia * (glm::transpose(r) * w));
  }
  // Its velocities changed by a push of momentum (kg m/s) and its moment, at pose p.
  void kick(const Pose& p, const BodyPush& push);
  // Kinetic and potential energy, J, at pose p under gravity g (heights from `floor`).
  double energy(const Pose& p, const glm::dvec3& g, const glm::dvec3& floor) const;
};

// A solid's mass properties at `density` (kg/m^3) or `mass` (kg, where > 0), and the points
// sampling its volume half a spacing apart: a box's and a ball's exact, a mesh's from the points.
Body make_body(const Obstacle& shape, double density, double mass, double spacing);

// The body's end-of-step pose after a push: its centre moved by impulse / mass, turned about
// it by the inverse inertia times the moment.
Pose give_way(const Body& b, const Pose& pose, const BodyPush& push);

// Bullet's world: the bodies, the box's walls and every other obstacle (moved as kinematic
// solids where they move).
class BodyWorld {
 public:
  BodyWorld(const std::vector<Body>& bodies, const std::vector<Obstacle>& obstacles, const glm::dvec3& wall_min,
            const glm::dvec3& wall_max, const glm::dvec3& gravity);
  ~BodyWorld();
  BodyWorld(const BodyWorld&) = delete;
  BodyWorld& operator=(const BodyWorld&) = delete;
  // Each body's obstacle moved to the end of a step of dt from its pose and velocity under gravity
  // and contacts; the other obstacles where they stand now.
  void predict(const std::vector<Body>& bodies, std::vector<Obstacle>& obstacles, double dt);
  // Each body moved out of whatever it overlaps (the walls, the obstacles, another body: shared by
  // their inverse masses), along the contact's normal, its velocity untouched: the fluid's pushes
  // between Bullet's steps press bodies into the floor and each other, which Bullet undoes only
  // part of a step at a time, and its next step made the rest a velocity (a ball popped off a box
  // at 0.8 m/s). Returns each overlap parted.
  struct Parting {
    int a = -1, b = -1;        // the bodies (-1: a standing solid, or none that moves)
    glm::dvec3 overlap{0.0};  // b's outward normal times the depth: a moved along it, b against it
    double share_a = 0, share_b = 0;  // each one's share of the parting: its inverse mass over the pair's
  };
  std::vector<Parting> separate(const std::vector<Body>& bodies, std::vector<Obstacle>& obstacles);

 private:
  struct World;
  std::unique_ptr<World> world_;
};

// At a step's end: each body's velocity, its pose's change over the step (as the fluid's).
void finish_bodies(std::vector<Body>& bodies, const std::vector<Obstacle>& obstacles, double dt);

}  // namespace pbflow
