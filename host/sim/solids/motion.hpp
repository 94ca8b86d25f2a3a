#pragma once
// Rigid motion of a solid: where it is at time t (a Pose), from a scene's "motion" key. The
// solvers move each solid to the end of every step (Derived::move_solids); the surface's own
// velocity is its displacement over the step (Obstacle::displacement).
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace pbflow {

// Degrees about x, then y, then z, the axes fixed (extrinsic): the convention of every
// "rotation" key (mesh placement, keyframes).
inline glm::dmat3 euler_rotation(const glm::dvec3& degrees) {
  const glm::dvec3 r = glm::radians(degrees);
  const glm::dmat3 x(1, 0, 0, 0, std::cos(r.x), std::sin(r.x), 0, -std::sin(r.x), std::cos(r.x));
  const glm::dmat3 y(std::cos(r.y), 0, -std::sin(r.y), 0, 1, 0, std::sin(r.y), 0, std::cos(r.y));
  const glm::dmat3 z(std::cos(r.z), std::sin(r.z), 0, -std::sin(r.z), std::cos(r.z), 0, 0, 0, 1);
  return z * y * x;
}

// A rigid placement: a point of the solid as the scene places it (its body frame) is at
// world(x) = rotation x + translation.
struct Pose {
  glm::dmat3 rotation{1.0};
  glm::dvec3 translation{0.0};
  glm::dvec3 world(const glm::dvec3& body) const { return rotation * body + translation; }
  glm::dvec3 body(const glm::dvec3& world) const { return glm::transpose(rotation) * (world - translation); }
  bool operator==(const Pose&) const = default;
};

// A solid's motion (the scene key obstacles[].motion, scene/keys.cpp), as a pose at time t;
// Type::None stands still.
struct Motion {
  enum class Type { None, Oscillate, Rotate, Keyframes } type = Type::None;
  glm::dvec3 axis{0.0};   // unit: oscillate's direction, rotate's axis
  double amplitude = 0;   // oscillate: m
  double period = 0;      // oscillate: s
  glm::dvec3 centre{0.0};  // rotate: a point on the axis; keyframes: the point rotations turn about
  double rate = 0;        // rotate: degrees per second
  struct Key {
    double t;
    glm::dvec3 position;  // displacement from where the scene places the solid, m
    glm::dquat rotation;  // about `centre`
  };
  std::vector<Key> keys;  // keyframes: times strictly increasing

  bool moves() const { return type != Type::None; }

  Pose at(double t) const {
    Pose p;
    if (type == Type::Oscillate) p.translation = amplitude * std::sin(2 * std::numbers::pi * t / period) * axis;
    if (type == Type::Rotate) p.rotation = glm::mat3_cast(glm::angleAxis(glm::radians(rate * t), axis));
    if (type == Type::Keyframes) {
      const auto next = std::upper_bound(keys.begin(), keys.end(), t, [](double s, const Key& k) { return s < k.t; });
      const Key& b = next == keys.end() ? keys.back() : *next;
      const Key& a = next == keys.begin() ? keys.front() : *(next - 1);
      const double s = b.t > a.t ? std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0) : 0.0;
      p.rotation = glm::mat3_cast(glm::slerp(a.rotation, b.rotation, s));
      p.translation = glm::mix(a.position, b.position, s);
    }
    if (type != Type::Oscillate) p.translation += centre - p.rotation * centre;  // turned about the centre
    return p;
  }

  // The fastest any point within `reach` of the centre (rotate, keyframes) moves, m/s: the
  // speed the scene's time step is checked against (scene/parse.cpp).
  double top_speed(double reach) const {
    if (type == Type::Oscillate) return amplitude * 2 * std::numbers::pi / period;
    if (type == Type::Rotate) return std::abs(glm::radians(rate)) * reach;
    double top = 0;
    for (size_t k = 1; k < keys.size(); ++k) {
      const double dt = keys[k].t - keys[k - 1].t;
      const double angle = glm::angle(glm::inverse(keys[k - 1].rotation) * keys[k].rotation);
      const double turn = std::min(angle, 2 * std::numbers::pi - angle);  // slerp's shorter way
      top = std::max(top, (glm::length(keys[k].position - keys[k - 1].position) + turn * reach) / dt);
    }
    return top;
  }
};

// The most a solid's surface may move in one step, in particle spacings: the projection then
// moves a particle it meets by less than the gap to its neighbours, and the mirrors' images by
// less than a kernel's fall-off (scene/parse.cpp refuses a faster solid; a viewer's drag is
// held to it, Derived::drag).
constexpr double kSolidStep = 0.5;

// A pose after another: a point placed by `b`, then moved as `a` moves it.
inline Pose compose(const Pose& a, const Pose& b) { return {a.rotation * b.rotation, a.rotation * b.translation + a.translation}; }
inline Pose inverse(const Pose& p) { return {glm::transpose(p.rotation), -(glm::transpose(p.rotation) * p.translation)}; }
// How far the box [lo, hi]'s farthest corner lies from p: the reach of a turn about p.
inline double reach(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& p) {
  double farthest = 0;
  for (int k = 0; k < 8; ++k)
    farthest = std::max(farthest, glm::length(glm::mix(lo, hi, glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1)) - p));
  return farthest;
}
// A turn about a point that stays where it is (a tilt about the tank's floor's centre).
inline Pose turn_about(const glm::dquat& turn, const glm::dvec3& pivot) {
  const glm::dmat3 r = glm::mat3_cast(turn);
  return {r, pivot - r * pivot};
}

// What the tank's frame does to the fluid over a step, beside g dt: every particle's velocity
// (x, v in the tank's frame) changes by at(x, v). of_x and of_v are zero unless the tank turns.
struct TankKick {
  glm::dvec3 linear{0.0};
  glm::dmat3 of_x{0.0}, of_v{0.0};
  // The tank's turn over the last step, R+^T R, with R and R+ its rotations at the last step's
  // end and this one, in its frame at this one (a body's spin, BodyCoupling).
  glm::dmat3 turn_now{1.0};
  glm::dvec3 at(const glm::dvec3& x, const glm::dvec3& v) const { return linear + of_x * x + of_v * v; }
  // Its turn over the last two steps, R+^T R-: of_v is that less the identity.
  glm::dmat3 turn_before() const { return glm::dmat3(1.0) + of_v; }
  // The kick a particle at x took, from its velocity after it (v + g dt + kick): turn_before is a
  // rotation, so v comes back through its transpose.
  glm::dvec3 taken(const glm::dvec3& x, const glm::dvec3& after, const glm::dvec3& g, double dt) const {
    const glm::dvec3 free = after - g * dt;  // v + kick
    return free - glm::transpose(turn_before()) * (free - linear - of_x * x);
  }
  bool none() const { return linear == glm::dvec3(0.0) && of_x == glm::dmat3(0.0) && of_v == glm::dmat3(0.0); }
};

// The tank's pose P(t) under its motion and a viewer's tilt, either of which may change while it
// runs (pbflow serve): a new motion starts where the tank is, a tilt turns the tank smoothly to an
// angle about its floor's centre and holds it there. The solvers work in the tank's frame: it
// keeps P at the last two steps' ends, so that each step's kick is what the world's step
// (v += g dt, x += v dt) does to a particle the walls carry, seen from the tank. Its acceleration,
// and where it turns the Coriolis, centrifugal and Euler terms and g turned into its frame, come
// out of the three poses exactly, and a change or stop takes away exactly the velocity the tank had.
class TankMotion {
 public:
  explicit TankMotion(const Motion& m = {}, const glm::dvec3& pivot = glm::dvec3(0.0)) : motion_(m), pivot_(pivot) {
    past_ = {at(0), at(0)};
  }
  const Motion& motion() const { return motion_; }
  bool moves() const { return motion_.moves() || tilt_.to != glm::dquat(1, 0, 0, 0) || tilt_.from != tilt_.to; }
  const Pose& pose() const { return past_[0]; }  // at the last step's end
  bool upright() const { return past_[0] == Pose{} && past_[1] == Pose{}; }  // the world's frame, still
  // The velocity in the world, at the last step's end, of a particle at x moving at v in the
  // tank's frame: what the world's step gave it (step_to).
  glm::dvec3 world_velocity(const glm::dvec3& x, const glm::dvec3& v, double dt) const {
    return (past_[0].world(x) - past_[1].world(x - dt * v)) / dt;
  }
  // The kick of the step ending at t, g the world's gravity.
  TankKick step_to(double t, double dt, const glm::dvec3& g) {
    const Pose next = at(t);
    const glm::dmat3 to_next = glm::transpose(next.rotation), now = to_next * past_[0].rotation,
                     before = to_next * past_[1].rotation, one(1.0);
    TankKick k;
    k.of_x = (2.0 * now - before - one) / dt;
    k.of_v = before - one;
    k.turn_now = now;
    k.linear = to_next * (2.0 * past_[0].translation - past_[1].translation - next.translation) / dt +
               dt * (to_next * g - g);
    past_ = {next, past_[0]};
    return k;
  }
  // A step that holds the tank where it is: g turned into its frame alone.
  TankKick held(double dt, const glm::dvec3& g) const { return {dt * (glm::transpose(pose().rotation) * g - g)}; }
  // From the last step's end, `now`, on: m, from where the tank is.
  void change(const Motion& m, double now) {
    const Pose moved = compose(from_, motion_.at(std::max(now - since_, 0.0)));
    motion_ = m, since_ = now, from_ = compose(moved, inverse(m.at(0)));
  }
  // From `now` on: turned smoothly to `to` (about the floor's centre) over `seconds`, then held.
  void tilt(const glm::dquat& to, double now, double seconds) { tilt_ = {tilt_.at(now), to, now, seconds}; }
  glm::dquat tilt_at(double t) const { return tilt_.at(t); }
  bool tilting(double t) const { return t < tilt_.start + tilt_.seconds; }  // turning still at t
  const glm::dquat& tilt_target() const { return tilt_.to; }
  const glm::dvec3& pivot() const { return pivot_; }  // what a tilt turns about

 private:
  // A turn from one orientation to another along smoothstep's ease, at rest at both ends.
  struct Tilt {
    glm::dquat from{1, 0, 0, 0}, to{1, 0, 0, 0};
    double start = 0, seconds = 0;
    glm::dquat at(double t) const {
      const double s = seconds > 0 ? std::clamp((t - start) / seconds, 0.0, 1.0) : 1.0;
      return glm::slerp(from, to, s * s * (3 - 2 * s));
    }
  };
  Pose at(double t) const {
    return compose(turn_about(tilt_.at(t), pivot_), compose(from_, motion_.at(std::max(t - since_, 0.0))));
  }
  Motion motion_;
  glm::dvec3 pivot_;
  double since_ = 0;
  Pose from_;
  Tilt tilt_;
  std::array<Pose, 2> past_{};
};

}  // namespace pbflow
