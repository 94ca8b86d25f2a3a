// SPH kernel properties (as SPlisHSPlasH tests them) and the lattice calibration of the mass.
#include <gtest/gtest.h>

#include "sim/kernels.hpp"
#include "sim/lattice.hpp"
#include "sim/params.hpp"

namespace pbflow {
namespace {

constexpr double h = 0.1;

// Midpoint rule over the cube [-h, h]^3 with n^3 cells.
template <class F>
void integrate(int n, F&& f) {
  double dx = 2 * h / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) f(glm::dvec3(-h + (i + 0.5) * dx, -h + (j + 0.5) * dx, -h + (k + 0.5) * dx), dx * dx * dx);
}

TEST(Kernels, Poly6IntegratesToOne) {
  double sum = 0;
  integrate(120, [&](glm::dvec3 x, double dv) { sum += kernels::poly6(glm::dot(x, x), h) * dv; });
  EXPECT_NEAR(sum, 1.0, 1e-4);
}

TEST(Kernels, SpikyIntegratesToOne) {
  double sum = 0;
  integrate(120, [&](glm::dvec3 x, double dv) { sum += kernels::spiky(glm::length(x), h) * dv; });
  EXPECT_NEAR(sum, 1.0, 1e-3);
}

TEST(Kernels, SpikyGradientIntegratesToZero) {
  glm::dvec3 sum(0.0);
  double scale = 0;
  integrate(80, [&](glm::dvec3 x, double dv) {
    glm::dvec3 g = kernels::spiky_grad(x, h) * dv;
    sum += g;
    scale += glm::length(g);
  });
  EXPECT_LT(glm::length(sum), 1e-9 * scale);
  EXPECT_GT(scale, 1.0);  // the gradient is not zero everywhere
}

TEST(Kernels, NonNegativeAndZeroOutsideSupport) {
  for (double r = 0; r <= 1.5 * h; r += h / 97) {
    EXPECT_GE(kernels::poly6(r * r, h), 0.0);
    EXPECT_GE(kernels::spiky(r, h), 0.0);
    if (r >= h) {
      EXPECT_EQ(kernels::poly6(r * r, h), 0.0);
      EXPECT_EQ(glm::length(kernels::spiky_grad(glm::dvec3(r, 0, 0), h)), 0.0);
    }
  }
}

TEST(Kernels, SpikyGradientMatchesFiniteDifferences) {
  const double e = 1e-7;
  for (glm::dvec3 x : {glm::dvec3(0.03, 0.01, -0.02), glm::dvec3(-0.05, 0.04, 0.02), glm::dvec3(0.0, 0.0, 0.09)}) {
    glm::dvec3 fd;
    for (int a = 0; a < 3; ++a) {
      glm::dvec3 dx(0.0);
      dx[a] = e;
      fd[a] = (kernels::spiky(glm::length(x + dx), h) - kernels::spiky(glm::length(x - dx), h)) / (2 * e);
    }
    glm::dvec3 g = kernels::spiky_grad(x, h);
    EXPECT_LT(glm::length(g - fd), 1e-5 * glm::length(g)) << x.x << "," << x.y << "," << x.z;
  }
}

TEST(Kernels, LatticeMassGivesRestDensity) {
  for (double ratio : {1.5, 2.0, 2.5}) {
    const double s = 0.02, hh = ratio * s, rho0 = 1000;
    double m = lattice_mass(s, hh, rho0);
    double rho = 0;
    for (int i = -4; i <= 4; ++i)
      for (int j = -4; j <= 4; ++j)
        for (int k = -4; k <= 4; ++k) {
          glm::dvec3 d = s * glm::dvec3(i, j, k);
          rho += m * kernels::poly6(glm::dot(d, d), hh);
        }
    EXPECT_NEAR(rho / rho0, 1.0, 1e-12) << "h/spacing " << ratio;
  }
}

}  // namespace
}  // namespace pbflow
