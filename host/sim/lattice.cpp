#include "sim/lattice.hpp"

#include <cmath>
#include <glm/glm.hpp>

#include "sim/kernels.hpp"

namespace pbflow {

double lattice_mass(double spacing, double h, double rho0) {
  int n = int(std::ceil(h / spacing));
  double sum = 0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        glm::dvec3 d = spacing * glm::dvec3(i, j, k);
        sum += kernels::poly6(glm::dot(d, d), h);
      }
  return rho0 / sum;
}

double lattice_gradient_sq(double spacing, double h, double mass, double rho0) {
  int n = int(std::ceil(h / spacing));
  glm::dvec3 grad_i(0.0);
  double sum = 0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        glm::dvec3 g = (mass / rho0) * kernels::spiky_grad(spacing * glm::dvec3(i, j, k), h);
        grad_i += g;
        sum += glm::dot(g, g);
      }
  return sum + glm::dot(grad_i, grad_i);
}

}  // namespace pbflow
