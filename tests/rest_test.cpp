// A tank at rest at its own spacing (0.02 m) and step (60 fps x 2 substeps): 0.4 m deep
// like the hydrostatic scene, a smaller cross-section (0.3 x 0.2 m, 3000 particles) to
// keep CI short. Settled into the solver's equilibrium first (the scene's "settle", as
// the hydrostatic scene does), it must lose energy, stay inside and stay at rest.
// (Released from the lattice instead, it must not gain energy: energy_test.cpp.)
#include <algorithm>
#include <cmath>

#include "gpu/gpu_solver.hpp"
#include "sim/settle.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

struct Setting {
  const char* method;
  int iterations;
  double mean_compression;  // the most it may settle at (measured in this tank, docs/physics.md)
};
void PrintTo(const Setting& s, std::ostream* os) { *os << s.method << "@" << s.iterations; }

// docs/design.md asks for max speed well under 0.1 m/s at 2 s. These bounds fail for the
// solver before the dashpot (LDC's free surface jittered at 0.5 m/s, pbf@1's squeezed
// fluid at 0.8 m/s), before the walls were mirrors (ldc@1: a 0.3 m/s jet down every wall),
// before the settle (the column breathing at 0.1-0.2 m/s) and before the relaxation
// (7-9 m/s). The 99th percentile is asserted too: the max is one particle. So is the max
// over every frame of the last second, under 0.08 m/s: ldc@1 read 0.099-0.138 there before a
// single iteration had the coarse correction, as surface particles that read dense were pulled
// into the fluid by LDC and dived (docs/physics.md).
constexpr double kP99Speed = 0.05, kMaxSpeed = 0.1, kLastSecondMaxSpeed = 0.08;

// docs/design.md: walls neither push fluid away nor let it pile up. Under its own weight the
// settled column is squeezed more the deeper it is (a single pass holds it only squeezed);
// the layer against the side walls must be squeezed as much as the fluid inside at the same
// height, not more. Returns the wall layer's and the inner columns' excess density
// (rho/rho0 - 1), each the mean over the lower half of the tank of bins two spacings high
// (heights along y: the caller checks that gravity points down y).
std::pair<double, double> wall_and_inner_excess(const ParticleState& s, const Derived& d) {
  double top = d.domain_min.y;
  for (const glm::dvec3& x : s.x) top = std::max(top, x.y);
  const int bins = int(0.5 * (top - d.domain_min.y) / (2 * d.spacing));
  std::vector<double> wall(bins), wall_n(bins), inner(bins), inner_n(bins);
  for (size_t i = 0; i < s.x.size(); ++i) {
    const glm::dvec3& x = s.x[i];
    const int bin = int((x.y - d.domain_min.y) / (2 * d.spacing));
    if (bin >= bins) continue;
    const double side = std::min({x.x - d.domain_min.x, d.domain_max.x - x.x, x.z - d.domain_min.z, d.domain_max.z - x.z});
    const double excess = s.rho[i] / d.rho0 - 1.0;
    if (side < d.spacing) {
      wall[bin] += excess;
      ++wall_n[bin];
    } else if (side >= 3 * d.spacing) {
      inner[bin] += excess;
      ++inner_n[bin];
    }
  }
  double w = 0, in = 0;
  int used = 0;
  for (int b = 0; b < bins; ++b) {
    if (wall_n[b] == 0 || inner_n[b] == 0) continue;
    w += wall[b] / wall_n[b];
    in += inner[b] / inner_n[b];
    ++used;
  }
  return {w / std::max(used, 1), in / std::max(used, 1)};
}

// The walls hold the column against them as high as the fluid inside: the mean top of the
// particle columns touching a side wall below the mean top of those three spacings or more
// inside (m). Columns are binned a spacing wide across x and z.
double wall_columns_dip(const ParticleState& s, const Derived& d) {
  const glm::ivec3 bins = glm::ivec3(glm::ceil((d.domain_max - d.domain_min) / d.spacing));
  std::vector<double> top(size_t(bins.x * bins.z), -1e9);
  for (const glm::dvec3& x : s.x) {
    const glm::ivec3 b = glm::clamp(glm::ivec3((x - d.domain_min) / d.spacing), glm::ivec3(0), bins - 1);
    double& t = top[size_t(b.z * bins.x + b.x)];
    t = std::max(t, x.y);
  }
  double wall = 0, inner = 0;
  int wall_n = 0, inner_n = 0;
  for (int z = 0; z < bins.z; ++z)
    for (int x = 0; x < bins.x; ++x) {
      const double t = top[size_t(z * bins.x + x)];
      if (t < -1e8) continue;
      const int side = std::min({x, bins.x - 1 - x, z, bins.z - 1 - z});
      if (side == 0) {
        wall += t;
        ++wall_n;
      } else if (side >= 3) {
        inner += t;
        ++inner_n;
      }
    }
  return inner / std::max(inner_n, 1) - wall / std::max(wall_n, 1);
}

class RestTest : public test::GpuTest, public ::testing::WithParamInterface<Setting> {};

TEST_P(RestTest, TankLosesEnergyAndSettles) {
  const Setting& p = GetParam();
  Scene scene = load_scene("hydrostatic", {"domain.max=[0.3,0.6,0.2]", "fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.3,0.4,0.2]}]",
                                           std::string("solver.method=\"") + p.method + "\"",
                                           "solver.iterations=" + std::to_string(p.iterations)});
  ASSERT_EQ(scene.solver.substeps, 2);
  ASSERT_EQ(scene.particle_spacing, 0.02);
  ASSERT_EQ(scene.gravity, glm::dvec3(0, -9.81, 0));
  Derived d = derive(scene);
  // From the lattice, not the jittered start a run starts from: on the lattice the walls' images
  // continue the fluid exactly, and the wall layer must read what the inside does. From the
  // jittered start the wall layer settles less squeezed than the inside at two to four
  // iterations (pbf@2 0.42 % against 0.48 %, pbf@4 0.23 against 0.34 %): a known problem
  // (docs/physics.md, "The start").
  GpuSolver solver(test::gpu(), d, lattice_particles(scene));
  SettleReport settled = settle(solver, d);
  ASSERT_TRUE(settled.converged) << settled.steps << " steps";
  EXPECT_GT(settled.potential_drop, 0.0);
  FrameStats s = solver.advance(0);
  // With a neighbour's wall images summed into its own term of lambda's denominator
  // (constraint_lambda.comp squares each apart), the wall layer reads 1.08 (ldc@1) to 1.31
  // (pbf@1) here, and the surface sinks along the walls.
  const auto [wall, inner] = wall_and_inner_excess(solver.download(), d);
  std::printf("  settled, lower half: the wall layer's excess density %.5f, the inner fluid's %.5f\n", wall, inner);
  // Within 5 % of the inner fluid's excess (pbf@2 with the coarse correction: 0.81 % against
  // 0.78 %).
  EXPECT_NEAR(wall, inner, 0.05 * inner)
      << "the walls squeeze the fluid beside them more (or less) than it is squeezed inside";
  EnergyGain energy;
  energy.add(s);
  double last_second_max = 0;
  for (int f = 0; f < int(2.0 * scene.fps); ++f) {
    s = solver.advance(scene.solver.substeps);
    ASSERT_FALSE(s.divergence.any()) << "frame " << f;
    energy.add(s);
    if (f >= scene.fps) last_second_max = std::max(last_second_max, s.max_speed);
  }
  const double worst_gain = energy.largest();
  std::printf("  %s@%d settled in %d steps; after 2 s: max speed %.3f m/s (over the last second %.3f), mean "
              "compression %.4f, energy gain %+.4f\n",
              p.method, p.iterations, settled.steps, s.max_speed, last_second_max, s.mean_compression, worst_gain);
  EXPECT_LE(worst_gain, 0.01);
  EXPECT_LT(s.max_speed, kMaxSpeed);
  EXPECT_LT(last_second_max, kLastSecondMaxSpeed);
  ParticleState end = solver.download();
  std::vector<double> speed;
  for (const glm::dvec3& v : end.v) speed.push_back(glm::length(v));
  std::nth_element(speed.begin(), speed.begin() + speed.size() * 99 / 100, speed.end());
  const double p99 = speed[speed.size() * 99 / 100];
  const double dip = wall_columns_dip(end, d);
  std::printf("  99th percentile speed %.3f m/s, the wall columns' dip %.2f mm\n", p99, 1000 * dip);
  EXPECT_LT(p99, kP99Speed);
  // Within 1.5 mm (-0.9 to 0.4 measured); the paired settings' wall columns stood 2.9 (pbf@2)
  // and 5.2 mm (pbf@3) low while the coarse grid's last cell straddled the wall.
  EXPECT_LT(std::abs(dip), 1.5e-3) << "the walls hold the columns beside them lower (or higher) than inside";
  // A single iteration with the coarse correction reads 1.0 % (ldc@1 and pbf@1; 12 % and 35 %
  // without it), two or three 0.3 %.
  EXPECT_LT(s.mean_compression, p.mean_compression) << "the column sits squeezed";
  for (const glm::dvec3& x : end.x)
    ASSERT_TRUE(glm::all(glm::greaterThanEqual(x, d.wall_min - 1e-6)) && glm::all(glm::lessThanEqual(x, d.wall_max + 1e-6)))
        << "a particle left the tank";
}

INSTANTIATE_TEST_SUITE_P(RealStepSlow, RestTest,
                         ::testing::Values(Setting{"ldc", 1, 0.02}, Setting{"pbf", 1, 0.02}, Setting{"pbf", 2, 0.01},
                                           Setting{"pbf", 3, 0.01}),
                         [](const auto& info) {
                           return std::string(info.param.method) + std::to_string(info.param.iterations);
                         });

// A tank whose lid lies a spacing or two above the water (0.3 m tall, the water 0.26 and 0.28 m
// deep): the coarse cells under the lid hold the free surface, so the solve had no node of air
// and no solution (a wall without flux all round), and the settled tank churned at 0.14-0.2 m/s.
// Past a wall the fluid does not touch is air to it now. Settled, then 1 s: still, as the tank
// with room above. Filled to the lid no node has air, and the solve takes its source's mean
// away (without it, 0.23 m/s); the settled lattice, squeezed 1.4-3.3 % with nowhere to go,
// rearranges in the first two seconds (up to 0.065 m/s, a few particles), so it runs 4 s and
// the last second counts.
struct Lid {
  const char* name;
  double depth;
  const char* method;
  int iterations;
  int seconds = 1;
};
void PrintTo(const Lid& l, std::ostream* os) { *os << l.name; }

class LidTest : public test::GpuTest, public ::testing::WithParamInterface<Lid> {};

TEST_P(LidTest, WaterUpToTheLidStandsStill) {
  const Lid& l = GetParam();
  Scene scene = load_scene("hydrostatic", {"domain.max=[0.3,0.3,0.3]",
                                           "fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.3," + std::to_string(l.depth) + ",0.3]}]",
                                           std::string("solver.method=\"") + l.method + "\"",
                                           "solver.iterations=" + std::to_string(l.iterations)});
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, lattice_particles(scene));
  ASSERT_TRUE(settle(solver, d).converged);
  EnergyGain energy;
  energy.add(solver.advance(0));
  double fastest = 0;  // over the last second
  for (int f = 0; f < l.seconds * scene.fps; ++f) {
    const FrameStats s = solver.advance(scene.solver.substeps);
    ASSERT_FALSE(s.divergence.any()) << "frame " << f;
    energy.add(s);
    if (f >= (l.seconds - 1) * scene.fps) fastest = std::max(fastest, s.max_speed);
  }
  std::printf("  %s: the largest speed over the last of %d s %.3f m/s, energy gain %+.5f\n", l.name, l.seconds, fastest,
              energy.largest());
  EXPECT_LT(fastest, 0.05);
  EXPECT_LE(energy.largest(), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(RealStepSlow, LidTest,
                         ::testing::Values(Lid{"pbf2_two_spacings", 0.26, "pbf", 2}, Lid{"pbf2_one_spacing", 0.28, "pbf", 2},
                                           Lid{"ldc1_two_spacings", 0.26, "ldc", 1}, Lid{"pbf2_filled", 0.3, "pbf", 2, 4},
                                           Lid{"ldc1_filled", 0.3, "ldc", 1, 4}),
                         [](const auto& info) { return std::string(info.param.name); });

// Finer than the scenes' spacing and deeper than their water, at 60 fps x 2 substeps: the
// paired passes churned in both (0.23-0.58 m/s in the tank at 0.0154 m; +2.8 % of PE0 and
// 3.6 m/s in 0.9 m of water at 0.02 m) until the coarse correction took the column's weight,
// and the deep column's top particles glided along the walls at 0.1 m/s until its cells
// tiled the walls' span. ldc@1 held them still but squeezed (24 % in the deep column) until a
// single iteration got the coarse correction too. A column 0.2 x 0.2 m across, settled, then
// 2 s: no energy made, the time-averaged mean compression at most 2 %, the last second's max
// speed under 0.1 m/s.
struct Column {
  const char* name;
  double spacing, depth;
  const char* method;
  int iterations;
};
void PrintTo(const Column& c, std::ostream* os) { *os << c.name; }

class DeepOrFineTest : public test::GpuTest, public ::testing::WithParamInterface<Column> {};

TEST_P(DeepOrFineTest, ColumnHeldStillAndUnsqueezed) {
  const Column& c = GetParam();
  const std::string top = std::to_string(c.depth);
  Scene scene = load_scene(
      "hydrostatic", {"particle_spacing=" + std::to_string(c.spacing), "domain.max=[0.2," + std::to_string(c.depth + 0.1) + ",0.2]",
                      "fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.2," + top + ",0.2]}]", "solver.substeps=2",
                      std::string("solver.method=\"") + c.method + "\"", "solver.iterations=" + std::to_string(c.iterations)});
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, initial_particles(scene));
  relax_start(solver);  // as a run starts
  // The settle may stop at its step limit still moving (fine_pbf2 does): what follows is judged.
  const SettleReport settled = settle(solver, d);
  std::printf("  settle: %d steps, %s\n", settled.steps, settled.converged ? "converged" : "at its step limit");
  EnergyGain energy;
  energy.add(solver.advance(0));
  double sum_mean = 0, last_second_max = 0;
  const int frames = int(2.0 * scene.fps);
  for (int f = 0; f < frames; ++f) {
    FrameStats s = solver.advance(scene.solver.substeps);
    ASSERT_FALSE(s.divergence.any()) << "frame " << f;
    energy.add(s);
    sum_mean += s.mean_compression;
    if (f >= scene.fps) last_second_max = std::max(last_second_max, s.max_speed);
  }
  std::printf("  %s (%zu particles): energy gain %+.4f, mean compression %.4f, last second's max speed %.3f m/s\n",
              c.name, solver.particle_count(), energy.largest(), sum_mean / frames, last_second_max);
  EXPECT_LE(energy.largest(), 0.01);
  EXPECT_LE(sum_mean / frames, 0.02);
  EXPECT_LT(last_second_max, 0.1);
}

INSTANTIATE_TEST_SUITE_P(
    ColumnsSlow, DeepOrFineTest,
    ::testing::Values(Column{"fine_pbf2", 0.0154, 0.4, "pbf", 2}, Column{"fine_pbf3", 0.0154, 0.4, "pbf", 3},
                      Column{"deep_pbf2", 0.02, 1.0, "pbf", 2}, Column{"deep_ldc2", 0.02, 1.0, "ldc", 2},
                      Column{"fine_ldc1", 0.0154, 0.4, "ldc", 1}, Column{"deep_ldc1", 0.02, 1.0, "ldc", 1}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace pbflow
