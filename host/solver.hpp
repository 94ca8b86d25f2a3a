#pragma once
// What the run loop, the tests and the benchmarks see of a solver, GPU or reference.
#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace pbflow {

// DESIGN.md's measures, taken at the end of the last step from a fresh density pass.
struct FrameStats {
  double mean_compression = 0, max_compression = 0, kinetic_energy = 0, max_speed = 0;
  double step_ms = 0;  // mean time of one step (GPU timestamps, else wall time); 0 when no step ran
};

// Host copy of the per-particle state, indexed by particle id (the order of initial_particles).
struct ParticleState {
  std::vector<glm::dvec3> x, v, x_pred, omega;
  std::vector<double> rho, lambda;
};

class Solver {
 public:
  virtual ~Solver() = default;
  // Runs `steps` time steps (0: none), then measures at the final positions.
  virtual FrameStats advance(int steps) = 0;
  virtual size_t particle_count() const = 0;
  virtual std::string device_name() const = 0;
};

}  // namespace pbflow
