#pragma once
// The rigid bodies' side of a step, as both solvers take it (sim/solids/bodies.hpp says the
// scheme): a solver sums what each pass gives each body (pushes(), per obstacle push site) and
// calls these at the step's points; Bullet, the give-way, the buoyancy and the kick live here once.
#include <glm/glm.hpp>

#include <memory>
#include <utility>
#include <vector>

#include "sim/params.hpp"

namespace pbflow {

class BodyCoupling {
 public:
  BodyCoupling() = default;
  explicit BodyCoupling(size_t bodies) : pushes_(bodies) {}
  // What the running pass's pushes gave each body (Derived::bodies' order).
  std::vector<BodyPush>& pushes() { return pushes_; }
  // Pass::Move, after the tank's step and before the solids move: the tank's kick into the
  // bodies' velocities, then Bullet's step to the predicted poses.
  void predict(Derived& d);
  void give_way(Derived& d);  // after a pass that pushed: each pose moved by its push, then overlaps parted
  void kick(Derived& d);      // after the dashpot: its momentum into the velocities
  void finish(Derived& d);    // after Pass::Velocity: the velocities, the poses' change over the step
  // The work done on the bodies from outside the water since the last call, J: a viewer's hand's
  // on those it held (their energy's change while held) and the tank's motion's (its kick's):
  // solid work, as a dragged solid's or the tank's on the fluid is.
  double take_work() { return std::exchange(work_, 0.0); }
  // The coarse correction counts a solid as fluid at rest: the push it would give the fluid in a
  // body's place (rho0 strength grad phi per volume, `grad` at the coarse nodes) is the body's,
  // over its volume below its water line (`lines`: the height along up() of the highest particle
  // within a spacing of it and no higher than its top, water lying on it aside; -infinity for
  // none) and that particle's own half spacing: phi is zero only a cell above the surface, and
  // the body's dry part counts as fluid there.
  void add_buoyancy(const Derived& d, const std::vector<glm::dvec3>& grad, const std::vector<double>& lines);
  static double energy(const Derived& d);  // the bodies' kinetic and potential energy, J

 private:
  void part(const Derived& d, const BodyWorld::Parting& p);  // an overlap parted: its velocity's share

  std::vector<BodyPush> pushes_;
  std::shared_ptr<BodyWorld> world_;  // made at the first step
  std::vector<double> held_energy_;   // each body's energy at the step's start (held ones' only)
  struct TankKicked {
    glm::dvec3 velocity{0.0}, spin{0.0};
  };
  std::vector<TankKicked> tank_kicks_;  // what the tank's kick changed each body's velocities by this step
  // How far each body's centre moved this step but for what parting its overlaps moved it past
  // the step's own motion into what it met: its velocity at the step's end times dt.
  std::vector<glm::dvec3> moved_;
  double work_ = 0;
};

// Pass::Move's, to time t (a step's end), in the order each takes the last's: the tank (this
// step's kick), the bodies' prediction (which takes the kick), then every solid to its pose;
// whether the coarse nodes' open shares were measured again (Derived::move_solids).
bool step_solids(Derived& d, BodyCoupling& bodies, double t);

// Against g turned into the tank's frame (+y without g), the tank's acceleration aside (a shake's
// start is a kick, not a tilt): where a water line is measured along.
glm::dvec3 up(const Derived& d);
double body_top(const Body& b, const Obstacle& o, const glm::dvec3& up);  // its samples' highest, along up

}  // namespace pbflow
