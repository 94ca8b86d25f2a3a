// The pairwise dashpot (viscosity_vorticity.comp) on the reference: it keeps momentum, only
// removes energy, leaves rigid motion and the slip along walls, and never drives squeezed fluid.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "sim/reference_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

// The same on particles: a block squeezed to 3x rho0 with random velocities, damped over
// and over at the largest accepted damping, loses kinetic energy every time (the
// uncapped dashpot, 0.3 x 5.06 x 2.4 = 3.6 on its fastest mode, multiplies that mode's energy by
// ~7 per pass).
TEST(Damping, SqueezedFluidIsNeverDriven) {
  const Scene scene = load_scene("hydrostatic", {"solver.xsph=0", "solver.damping=0.3"});
  const double spacing = 0.02 / std::cbrt(3.0);
  std::vector<glm::dvec3> x;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      for (int k = 0; k < 12; ++k) x.push_back(glm::dvec3(0.2, 0.1, 0.2) + spacing * glm::dvec3(i, j, k));
  ReferenceSolver ref(derive(scene), x);
  ref.build_grid(ref.state.x);
  ref.density();
  EXPECT_GT(*std::max_element(ref.state.rho.begin(), ref.state.rho.end()), 2.5 * ref.derived().rho0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (glm::dvec3& vi : ref.state.v) vi = glm::dvec3(u(rng), u(rng), u(rng));
  auto energy = [&] {
    double e = 0;
    for (const glm::dvec3& vi : ref.state.v) e += glm::dot(vi, vi);
    return e;
  };
  for (int pass = 0; pass < 12; ++pass) {
    const double before = energy();
    ref.viscosity_vorticity();
    EXPECT_LT(energy(), before) << "pass " << pass;
  }
}
// with velocities v, after one pass.
std::vector<glm::dvec3> lattice_block(glm::dvec3 corner) {
  std::vector<glm::dvec3> x;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k) x.push_back(corner + 0.02 * glm::dvec3(i + 0.5, j + 0.5, k + 0.5));
  return x;
}
std::vector<glm::dvec3> damped(const std::vector<glm::dvec3>& x, const std::vector<glm::dvec3>& v) {
  ReferenceSolver ref(derive(load_scene("hydrostatic", {"solver.xsph=0", "solver.damping=0.2"})), x);
  ref.state.v = v;
  ref.build_grid(ref.state.x);
  ref.density();  // lists the neighbours (and the cap reads the densities)
  ref.viscosity_vorticity();
  return ref.state.v;
}
glm::dvec3 momentum(const std::vector<glm::dvec3>& v) {
  glm::dvec3 p(0.0);
  for (const glm::dvec3& vi : v) p += vi;
  return p;
}
double energy(const std::vector<glm::dvec3>& v) {
  double e = 0;
  for (const glm::dvec3& vi : v) e += glm::dot(vi, vi);
  return e;
}
std::vector<glm::dvec3> random_velocities(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<glm::dvec3> v(n);
  for (glm::dvec3& vi : v) vi = glm::dvec3(u(rng), u(rng), u(rng));
  return v;
}
double largest_change(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  double change = 0;
  for (size_t i = 0; i < a.size(); ++i) change = std::max(change, glm::length(a[i] - b[i]));
  return change;
}

// Away from the walls the block keeps its momentum and loses kinetic energy; a rigid
// rotation passes untouched.
TEST(Damping, KeepsMomentumRemovesEnergyAndLeavesRigidMotion) {
  const std::vector<glm::dvec3> x = lattice_block({0.2, 0.1, 0.2});
  std::vector<glm::dvec3> v = random_velocities(x.size(), 7);
  std::vector<glm::dvec3> after = damped(x, v);
  EXPECT_LT(glm::length(momentum(after) - momentum(v)), 1e-9 * glm::length(momentum(v)) + 1e-12);
  EXPECT_LT(energy(after), 0.9 * energy(v)) << "random velocities lose kinetic energy";
  EXPECT_GT(energy(after), 0.0) << "and are not reversed past zero";

  const glm::dvec3 omega(0.3, -1.0, 0.5), centre(0.28, 0.18, 0.28);
  for (size_t i = 0; i < x.size(); ++i) v[i] = glm::dvec3(0.1, 0.0, -0.2) + glm::cross(omega, x[i] - centre);
  EXPECT_LT(largest_change(damped(x, v), v), 1e-12) << "a rigid motion has no relative normal velocity";
}

// The walls take part through the particles' images: on the floor, a block sliding as a
// whole keeps its velocity (no sticking); falling onto the floor as a whole, the layers
// within h of it slow down and none turns back; random velocities in the tank's corner
// lose energy. The falling block fails for the dashpot without images and for images
// moving as their particle, unmirrored (no slowing).
TEST(Damping, WallsDampNormalMotionAndLeaveTheSlip) {
  const std::vector<glm::dvec3> on_floor = lattice_block({0.2, 0.0, 0.2});
  std::vector<glm::dvec3> slide(on_floor.size(), glm::dvec3(0.3, 0.0, -0.2));
  EXPECT_LT(largest_change(damped(on_floor, slide), slide), 1e-12) << "sliding along the floor is free";

  std::vector<glm::dvec3> fall(on_floor.size(), glm::dvec3(0.0, -1.0, 0.0));
  std::vector<glm::dvec3> after = damped(on_floor, fall);
  const double h = derive(load_scene("hydrostatic")).h;
  double slowest = -1e9;  // the largest vertical velocity in the bottom layers
  for (size_t i = 0; i < after.size(); ++i) {
    EXPECT_LT(after[i].y, 0.0) << "particle " << i << " turned back";
    if (on_floor[i].y < h) slowest = std::max(slowest, after[i].y);
    else EXPECT_LT(glm::length(after[i] - fall[i]), 1e-12) << "particle " << i << " is farther than h from the floor";
  }
  EXPECT_GT(slowest, -0.9) << "the bottom layer is slowed by its images";

  const std::vector<glm::dvec3> in_corner = lattice_block({0.0, 0.0, 0.0});
  const std::vector<glm::dvec3> v = random_velocities(in_corner.size(), 5);
  EXPECT_LT(energy(damped(in_corner, v)), energy(v));
}

}  // namespace
}  // namespace pbflow
