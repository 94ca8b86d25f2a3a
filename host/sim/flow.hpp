#pragma once
// Water that enters and leaves a run (scene keys emitters, drains, capacity): an emitter adds
// particles at an inlet in layers at the rest spacing, so that a jet holds its density from its
// first layer; a drain removes every particle inside it. Both solvers apply a frame's flow on
// the host before its steps, the drains first, through apply_flow: one place for both.
#include <glm/glm.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace pbflow {

// The most particles a run may hold (positions alone are 2 GiB on the GPU).
constexpr long long kMaxParticles = 1LL << 27;

struct Emitter {
  glm::dvec3 centre{0.0}, normal{0.0, 1.0, 0.0};  // normal: unit, the way the water leaves
  double radius = 0;                               // a disc of this radius, or
  glm::dvec2 size{0.0};                            // a rectangle, across and along normal x across
  double speed = 0;                                // m/s, along the normal
  double start = 0, stop = std::numeric_limits<double>::infinity();  // s
  std::vector<glm::dvec3> inlet;                   // one layer's points (inlet_points)
  long layers = 0;                                 // layers emitted or skipped so far
  // The time layer k leaves the inlet: one every spacing / speed seconds from `start`.
  double layer_time(long k, double spacing) const { return start + double(k) * spacing / speed; }
};

struct Drain {
  glm::dvec3 min{0.0}, max{0.0};
  bool contains(const glm::dvec3& x) const {
    return glm::all(glm::greaterThan(x, min)) && glm::all(glm::lessThan(x, max));
  }
};

// One layer of an inlet: the points of a square lattice at `spacing` in the emitter's plane that
// lie on its disc or rectangle (a lattice point at its centre).
std::vector<glm::dvec3> inlet_points(const Emitter& e, double spacing);

// A frame's flow: how many particles entered and left and the energy they carried (kinetic and
// potential, J, what entered less what left), and whether an emitter waited for room.
struct FlowCount {
  uint32_t emitted = 0, drained = 0;
  double energy = 0;
  bool paused = false;
};

// What the flow reads of the run: the particle's mass, gravity and the height potential energy
// is measured from (the domain's lowest corner along g, as the measures).
struct FlowFrame {
  double mass = 0, spacing = 0;
  glm::dvec3 gravity{0.0}, lowest{0.0};
  size_t capacity = 0;
  bool emitting = true;  // false: every layer due is skipped (a viewer turned the emitters off)
  double energy(const glm::dvec3& x, const glm::dvec3& v) const {
    return mass * (0.5 * glm::dot(v, v) + glm::dot(-gravity, x - lowest));
  }
};

// The particles at time t: those inside a drain removed (order kept), then every layer due by t
// appended (each moved on from its inlet by the time since it was due, ids from next_id up).
// Layers that find no room under the capacity are skipped whole, and `paused` says so; while the
// emitters are off (FlowFrame::emitting) every layer due is skipped. The
// other arrays in `carried` are kept or dropped with x (their new entries zero).
struct FlowParticles {
  std::vector<glm::dvec3>& x;
  std::vector<glm::dvec3>& v;
  std::vector<uint32_t>& id;
  std::vector<std::vector<glm::dvec3>*> carried;
  std::vector<std::vector<double>*> carried_scalars;
};
FlowCount apply_flow(std::vector<Emitter>& emitters, const std::vector<Drain>& drains, const FlowFrame& f,
                     double t, FlowParticles p, uint32_t& next_id);

// Whether a frame at time t has any flow to apply: a drain, or an emitter's layer due.
bool flow_due(const std::vector<Emitter>& emitters, const std::vector<Drain>& drains, double t, double spacing);

}  // namespace pbflow
