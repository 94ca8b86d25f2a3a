// The GPU solver agrees with the reference at the edges of particle_spacing's range, not only
// at the built-in scenes' 2 cm: the shaders run in float, where a kernel constant in 1/h^9
// once left its range at 1e-5 m (density 0, and garbage reported as a result).
//
// The scene is the dam break scaled by k = spacing / 0.02 m with gravity scaled by k too, so
// that it is the same flow at every scale (the same substeps, the same compressions): what
// changes is only where float's range and rounding fall.
#include <cmath>
#include <sstream>

#include "gpu/gpu_solver.hpp"
#include "scene/keys.hpp"
#include "sim/reference_solver.hpp"
#include "sim/settle.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

// The dam break at `spacing` with 2 000 particles (the column 10 x 20 x 10 spacings), of a
// fluid of `rest_density`.
Scene scaled_dam_break(double spacing, double rest_density) {
  const double k = spacing / 0.02;
  auto number = [](double x) {
    std::ostringstream s;
    s.precision(17);
    s << x;
    return s.str();
  };
  auto v = [&](double x, double y, double z) {
    return "[" + number(x * k) + "," + number(y * k) + "," + number(z * k) + "]";
  };
  return load_scene("dam_break", {"domain={\"min\":[0,0,0],\"max\":" + v(0.8, 0.5, 0.2) + "}",
                                  "fluid_blocks=[{\"min\":[0,0,0],\"max\":" + v(0.2, 0.4, 0.2) + "}]",
                                  "gravity=[0," + number(-std::min(9.81 * k, 1e4)) + ",0]",
                                  "solver.rest_density=" + number(rest_density), "particle_spacing=" + number(spacing),
                                  "solver.xsph=0.05"});
}

struct Scale {
  double spacing, rest_density;
};
void PrintTo(const Scale& c, std::ostream* os) { *os << c.spacing << " m, " << c.rest_density << " kg/m^3"; }

class ScaleTest : public test::GpuTest, public ::testing::WithParamInterface<Scale> {};

// The relax and four steps of the flow: compressions, energies (relative to the initial
// potential energy) and positions (relative to the spacing) as the reference has them.
TEST_P(ScaleTest, StepsAgreeWithTheReference) {
  const double spacing = GetParam().spacing;
  const Scene scene = scaled_dam_break(spacing, GetParam().rest_density);
  const Derived d = derive(scene);
  const auto x0 = initial_particles(scene);
  GpuSolver gpu(test::gpu(), d, x0);
  ReferenceSolver ref(d, x0);
  relax_start(gpu);
  relax_start(ref);
  const FrameStats r0 = ref.advance(0), g0 = gpu.advance(0);
  std::printf("  spacing %g m, relaxed: mean compression %.5f (reference %.5f), potential energy %.6g J (%.6g)\n", spacing,
              g0.mean_compression, r0.mean_compression, g0.potential_energy, r0.potential_energy);
  EXPECT_NEAR(g0.mean_compression, r0.mean_compression, 1e-4 + 1e-2 * r0.mean_compression);
  const double pe0 = r0.potential_energy;
  ASSERT_GT(pe0, 0.0);
  EXPECT_NEAR(g0.potential_energy, pe0, 1e-5 * pe0);
  for (int frame = 0; frame < 2; ++frame) {
    const FrameStats g = gpu.advance(2), r = ref.advance(2);
    std::printf("  spacing %g m, frame %d: mean compression %.5f (reference %.5f), kinetic energy %.5f PE0 (%.5f)\n",
                spacing, frame + 1, g.mean_compression, r.mean_compression, g.kinetic_energy / pe0,
                r.kinetic_energy / pe0);
    EXPECT_GT(r.mean_compression, 0.0);
    EXPECT_NEAR(g.mean_compression, r.mean_compression, 1e-4 + 1e-2 * r.mean_compression);
    EXPECT_NEAR(g.kinetic_energy, r.kinetic_energy, 1e-3 * r.kinetic_energy);
    EXPECT_NEAR(g.potential_energy, r.potential_energy, 1e-5 * pe0);
    EXPECT_NEAR(g.max_speed, r.max_speed, 1e-3 * r.max_speed);
  }
  const test::ErrorReport e = test::compare(gpu.download().x, ref.state.x, "positions after 4 steps");
  EXPECT_LT(e.max_abs, 1e-3 * spacing);  // the 2 cm StepTest's 1e-5 m is 5e-4 spacings
}

// The ends of the ranges of particle_spacing and solver.rest_density, together and apart, and
// the built-in scenes' values. The largest spacing a scene can have is bounded by its domain
// (coordinates within 1e6 m of the origin): 2e4 m makes this scene's tank 8e5 m long.
const SceneKey& key(std::string_view name) {
  for (const SceneKey& k : scene_keys())
    if (k.name == name) return k;
  throw std::invalid_argument(std::string(name));
}
std::vector<Scale> scales() {  // called by gtest after static initialisation, when the key table is there
  const KeyRange spacing = *key("particle_spacing").range, density = *key("solver.rest_density").range;
  return {{spacing.lo, 1000},  {spacing.lo, density.lo}, {spacing.lo, density.hi}, {1e-4, 1000},
          {0.02, 1000},        {0.02, density.lo},       {0.02, density.hi},       {20, 1000},
          {2e4, 1000},         {2e4, density.lo},        {2e4, density.hi}};
}
INSTANTIATE_TEST_SUITE_P(Ranges, ScaleTest, ::testing::ValuesIn(scales()),
                         [](const auto& info) {  // 1e-06 m, 1000 kg/m^3 -> 1em06_m_1000_kg
                           std::ostringstream text;
                           text << info.param.spacing << "_m_" << info.param.rest_density << "_kg";
                           std::string name;
                           for (char c : text.str()) name += c == '.' ? "p" : c == '-' ? "m" : c == '+' ? "" : std::string(1, c);
                           return name;
                         });

}  // namespace
}  // namespace pbflow
