#include "sim/stability.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "sim/kernels.hpp"
#include "sim/lattice.hpp"

namespace pbflow {

namespace {

using cvec3 = glm::tvec3<std::complex<double>>;

// A lattice of rest spacing 1 and rest density 1, squeezed uniformly to (1 + compression)
// rho0: the neighbour offsets o = x_i - x_j inside h.
struct Lattice {
  double h, mass, spacing;
  std::vector<glm::dvec3> offsets;
  explicit Lattice(double kernel_ratio, double compression = 0)
      : h(kernel_ratio), mass(lattice_mass(1.0, kernel_ratio, 1.0)), spacing(std::cbrt(1.0 / (1.0 + compression))) {
    int n = int(std::ceil(h / spacing));
    for (int i = -n; i <= n; ++i)
      for (int j = -n; j <= n; ++j)
        for (int k = -n; k <= n; ++k) {
          glm::dvec3 o = spacing * glm::dvec3(i, j, k);
          double r = glm::length(o);
          if (r > 0 && r < h) offsets.push_back(o);
        }
  }
  // d(rho_i / rho0) for the mode u e^{ik.x} is c . u: rho_i moves with x_i - x_j for every j.
  cvec3 density_change(const glm::dvec3& k) const {
    cvec3 c(0.0);
    for (const glm::dvec3& o : offsets) c += cvec3(mass * kernels::poly6_grad(o, h)) * (1.0 - phase(k, o));
    return c;
  }
  // rho / rho0 as the solver reads it (poly6 sum): a little under 1 + compression.
  double density() const {
    double sum = kernels::poly6(0.0, h);
    for (const glm::dvec3& o : offsets) sum += kernels::poly6(glm::dot(o, o), h);
    return mass * sum;
  }
  // e^{-ik.o}: the mode at x_j = x_i - o relative to x_i.
  static std::complex<double> phase(const glm::dvec3& k, const glm::dvec3& o) {
    return std::polar(1.0, -glm::dot(k, o));
  }
};

// Every mode up to the lattice's Nyquist limit; the cubic lattice's symmetry leaves [0, pi]^3.
template <class F>
void for_each_mode(double spacing, F&& visit) {
  constexpr int kSamples = 24;
  for (int a = 0; a <= kSamples; ++a)
    for (int b = 0; b <= a; ++b)
      for (int c = 0; c <= b; ++c) visit(std::numbers::pi / (kSamples * spacing) * glm::dvec3(a, b, c));
}

template <class F>
double max_over_modes(double spacing, F&& eigenvalue) {
  double worst = 0;
  for_each_mode(spacing, [&](const glm::dvec3& k) { worst = std::max(worst, eigenvalue(k)); });
  return worst;
}

// Of a symmetric positive semi-definite 3x3 matrix, by power iteration (converges fast
// enough for the few hundred matrices a scene needs; exactness to 1e-9 is not needed).
double largest_eigenvalue(const glm::dmat3& m) {
  glm::dvec3 v(1.0, 0.7, 0.3);
  double eigenvalue = 0;
  for (int it = 0; it < 200; ++it) {
    const glm::dvec3 w = m * v;
    const double len = glm::length(w);
    if (len == 0) return 0;
    eigenvalue = glm::dot(v, w) / glm::dot(v, v);
    v = w / len;
  }
  return eigenvalue;
}

std::complex<double> dot(const cvec3& a, const cvec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// One Jacobi pass of the density constraint on a lattice: its gain on each mode.
class JacobiPass {
 public:
  JacobiPass(double kernel_ratio, double relaxation, double compression, int smoothing)
      : l_(kernel_ratio, compression), smoothing_(smoothing) {
    // sum_j |grad_j C_i|^2 (grad_i C_i vanishes on a lattice); eps is sized at rest, as the solver's
    auto gradient_sq = [](const Lattice& lattice) {
      double sum = 0;
      for (const glm::dvec3& o : lattice.offsets) {
        glm::dvec3 g = lattice.mass * kernels::spiky_grad(o, lattice.h);
        sum += glm::dot(g, g);
      }
      return sum;
    };
    denominator_ = gradient_sq(l_) + relaxation * gradient_sq(Lattice(kernel_ratio));
    for (const glm::dvec3& o : l_.offsets) weights_ += kernels::smoothing_weight(o, l_.h);
  }
  double spacing() const { return l_.spacing; }

  // lambda_i = -c.u / denominator, then smoothed: times F(k)^smoothing (F: the weighted mean of cos(k.o));
  // dx_i = m sum_j (lambda_i + lambda_j) grad W_spiky = -g (c.u) F^smoothing / denominator:
  // a rank-one map whose eigenvalue is (c.g) F^smoothing / denominator.
  double gain(const glm::dvec3& k) const {
    cvec3 g(0.0);
    double cosines = 1.0;  // the particle itself, at r = 0
    for (const glm::dvec3& o : l_.offsets) {
      g += cvec3(l_.mass * kernels::spiky_grad(o, l_.h)) * (1.0 + Lattice::phase(k, o));
      cosines += kernels::smoothing_weight(o, l_.h) * std::cos(glm::dot(k, o));
    }
    const double average = cosines / weights_;
    return dot(l_.density_change(k), g).real() * std::pow(average, smoothing_) / denominator_;
  }

 private:
  Lattice l_;
  int smoothing_;
  double denominator_;
  double weights_ = 1.0;  // the smoothing weights' sum: the particle itself (1 at r = 0) and its neighbours
};

}  // namespace

double jacobi_gain_max(double kernel_ratio, double relaxation, double compression, int smoothing) {
  const JacobiPass pass(kernel_ratio, relaxation, compression, smoothing);
  return max_over_modes(pass.spacing(), [&](const glm::dvec3& k) { return pass.gain(k); });
}

double jacobi_gain_min(double kernel_ratio, double relaxation, int smoothing) {
  const JacobiPass pass(kernel_ratio, relaxation, 0.0, smoothing);
  double least = 0;
  for_each_mode(pass.spacing(), [&](const glm::dvec3& k) { least = std::min(least, pass.gain(k)); });
  return least;
}

double jacobi_long_mode_gain(double kernel_ratio, double relaxation, int smoothing) {
  constexpr double k = 1e-3;  // a wavelength of ~6000 spacings, along an axis
  return JacobiPass(kernel_ratio, relaxation, 0.0, smoothing).gain(glm::dvec3(k, 0.0, 0.0)) / (k * k);
}

double lattice_density(double kernel_ratio, double compression) {
  return Lattice(kernel_ratio, compression).density();
}

double ldc_stiffness_max(double kernel_ratio, double compression) {
  const Lattice l(kernel_ratio, compression);
  // a_i = -K sum_j (drho_j - drho_i) (h - r) e_ij with e_ij = (x_j - x_i)/r = -o/r: again rank one,
  // a = K a_dir (c.u), and the stiffness is -(c . a_dir).
  return max_over_modes(l.spacing, [&](const glm::dvec3& k) {
    cvec3 a_dir(0.0);
    for (const glm::dvec3& o : l.offsets) {
      double r = glm::length(o);
      a_dir -= cvec3(-o / r * (l.h - r)) * (Lattice::phase(k, o) - 1.0);
    }
    return -dot(l.density_change(k), a_dir).real();
  });
}

double damping_gain_max(double kernel_ratio, double compression) {
  const Lattice l(kernel_ratio, compression);
  // dv_i = -c sum_j (1 - r/h) e e^T (v_i - v_j), e = o/r: the mode v = u e^{ik.x} sees the
  // real symmetric matrix sum_j (1 - r/h)(1 - cos k.o) e e^T (the sine parts cancel in +-o).
  return max_over_modes(l.spacing, [&](const glm::dvec3& k) {
    glm::dmat3 m(0.0);
    for (const glm::dvec3& o : l.offsets) {
      const double r = glm::length(o);
      const glm::dvec3 e = o / r;
      m += (1.0 - r / l.h) * (1.0 - std::cos(glm::dot(k, o))) * glm::outerProduct(e, e);
    }
    return largest_eigenvalue(m);
  });
}

std::vector<double> jacobi_schedule(int passes, double gain, double gain_max) {
  // A pair of passes at w = 1.5 / gain_max leaves (1 - w lambda)^2 of a mode of gain lambda,
  // within [0.25, 1] for every mode (2 / gain_max would reach 0 and left pbf@2 unstable in a
  // dam break); a lone pass at 1 / gain_max leaves 1 - lambda / gain_max. Bolder schedules
  // (Chebyshev roots, which the linear picture allows) blew up at 3-4 passes: the clamp
  // C >= 0 undoes the cancellation they rely on.
  std::vector<double> w(size_t(passes), 1.5 * gain / gain_max);
  if (passes % 2) w.back() = gain / gain_max;
  return w;
}

}  // namespace pbflow
