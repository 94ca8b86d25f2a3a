// The local density correction force: its sign, its zeros and its linearity in K,
// on the reference and on the GPU.
#include "gpu/gpu_solver.hpp"
#include "sim/reference_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

// A slab of fluid whose left half is denser: its particles sit closer together in x.
ParticleState two_density_slab(const Scene& scene) {
  ParticleState st;
  const double s = scene.particle_spacing;
  double x = 0.5 * s;
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k) st.x.emplace_back(x, (j + 0.5) * s, (k + 0.5) * s);
    x += i < 8 ? 0.85 * s : s;
  }
  size_t n = st.x.size();
  st.v.assign(n, glm::dvec3(0.0));
  st.x_pred = st.x;
  st.curl.assign(n, glm::dvec3(0.0));
  st.rho.assign(n, 0.0);
  st.lambda.assign(n, 0.0);
  return st;
}

Scene slab_scene(const std::string& method, double k, bool clamp = true) {
  return load_scene("hydrostatic", {"solver.method=\"" + method + "\"", "solver.ldc_k=" + std::to_string(k),
                                    std::string("solver.ldc_clamp=") + (clamp ? "true" : "false")});
}

std::vector<glm::dvec3> reference_forces(const Scene& scene, const ParticleState& st) {
  ReferenceSolver ref(derive(scene), st.x);
  ref.state = st;
  ref.build_grid(ref.state.x);
  ref.density();
  std::vector<glm::dvec3> f;
  for (size_t i = 0; i < st.x.size(); ++i) f.push_back(ref.correction_force(i));
  return f;
}

// A 10^3 lattice block floating in the middle of the hydrostatic tank, away from the walls.
ParticleState floating_block() {
  ParticleState st;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) st.x.push_back(glm::dvec3(0.2, 0.1, 0.2) + 0.02 * glm::dvec3(i + 0.5, j + 0.5, k + 0.5));
  st.v.assign(st.x.size(), glm::dvec3(0.0));
  return st;
}

double largest(const std::vector<glm::dvec3>& f) {
  double m = 0;
  for (const auto& fi : f) m = std::max(m, glm::length(fi));
  return m;
}

TEST(LdcForce, ZeroForUniformDensity) {
  // Interior lattice particles all have rho0: no density difference, no force.
  auto f = reference_forces(slab_scene("ldc", 2000, false), floating_block());
  size_t centre = (5 * 10 + 5) * 10 + 5;  // more than h from every face of the block
  EXPECT_LT(glm::length(f[centre]), 1e-9);
  EXPECT_GT(largest(f), 1.0);  // the LDC paper's force: the surface's density deficit pulls
}

TEST(LdcForce, ClampedForceIgnoresTheFreeSurface) {
  // Clamped (the default), a density deficit is no signal: the free block feels nothing.
  double raw = largest(reference_forces(slab_scene("ldc", 2000, false), floating_block()));
  double clamped = largest(reference_forces(slab_scene("ldc", 2000, true), floating_block()));
  EXPECT_LT(clamped, 1e-6 * raw) << "raw " << raw << ", clamped " << clamped;
}

TEST(LdcForce, PointsFromDenserToLessDense) {
  Scene scene = slab_scene("ldc", 2000);
  ParticleState st = two_density_slab(scene);
  auto f = reference_forces(scene, st);
  // Particles at the density step (x-columns 6..9), away from the y/z faces.
  int checked = 0;
  for (size_t i = 0; i < st.x.size(); ++i) {
    int column = int(i / 64), j = int(i / 8 % 8), k = int(i % 8);
    if (column < 6 || column > 9 || j < 3 || j > 4 || k < 3 || k > 4) continue;
    EXPECT_GT(f[i].x, 0.0) << "particle " << i << " is pushed toward the denser side";
    ++checked;
  }
  EXPECT_EQ(checked, 16);
}

TEST(LdcForce, LinearInK) {
  ParticleState st = two_density_slab(slab_scene("ldc", 1));
  auto f1 = reference_forces(slab_scene("ldc", 1000), st);
  auto f3 = reference_forces(slab_scene("ldc", 3000), st);
  for (size_t i = 0; i < f1.size(); ++i) EXPECT_LT(glm::length(f3[i] - 3.0 * f1[i]), 1e-9 * (1 + glm::length(f3[i])));
}

TEST(LdcForce, ZeroForPbf) {
  ParticleState st = two_density_slab(slab_scene("pbf", 2000));
  for (auto& fi : reference_forces(slab_scene("pbf", 2000), st)) EXPECT_EQ(glm::length(fi), 0.0);
}

// A compressed column (density rising linearly with depth) is held up by the force. With
// the walls as mirrors a particle next to a side wall, or in a corner, gets the same force
// as one in the middle at its height; without its ghost neighbours it got about half,
// sank, and drove a jet down every wall of a tank at rest.
TEST(LdcForce, AWallParticleFeelsTheInteriorsForce) {
  Scene scene = slab_scene("ldc", 2000);
  Derived d = derive(scene);
  auto x = lattice_particles(scene);
  ReferenceSolver ref(d, x);
  ref.build_grid(ref.state.x);
  ref.density();  // lists the neighbours; the densities are then set by hand
  for (size_t i = 0; i < x.size(); ++i) ref.state.rho[i] = d.rho0 * (1.0 + 0.2 * (0.4 - x[i].y));
  const double s = scene.particle_spacing, y = 0.2 + 0.5 * s;  // a layer mid-depth
  auto force_at = [&](double px, double pz) {
    for (size_t i = 0; i < x.size(); ++i)
      if (glm::length(x[i] - glm::dvec3(px, y, pz)) < 1e-9) return ref.correction_force(i);
    ADD_FAILURE() << "no particle at " << px << ", " << pz;
    return glm::dvec3(0.0);
  };
  const glm::dvec3 middle = force_at(0.3 + 0.5 * s, 0.3 + 0.5 * s);
  EXPECT_GT(middle.y, 1.0) << "the column's gradient pushes up";
  for (glm::dvec2 p : {glm::dvec2(0.5 * s, 0.3 + 0.5 * s), glm::dvec2(0.6 - 0.5 * s, 0.3 + 0.5 * s),
                       glm::dvec2(0.5 * s, 0.5 * s), glm::dvec2(0.6 - 1.5 * s, 0.6 - 0.5 * s)}) {
    glm::dvec3 f = force_at(p.x, p.y);
    EXPECT_LT(glm::length(f - middle), 1e-9 * glm::length(middle)) << "at x = " << p.x << ", z = " << p.y << ": " << f.x
                                                                     << ", " << f.y << ", " << f.z;
  }
}

class LdcGpuTest : public test::GpuTest, public ::testing::WithParamInterface<bool> {};

TEST_P(LdcGpuTest, GpuForceMatchesReference) {
  const bool clamp = GetParam();
  Scene scene = slab_scene("ldc", 2000, clamp);
  ParticleState st = two_density_slab(scene);
  Derived d = derive(scene);
  GpuSolver gpu(test::gpu(), d, st.x);
  gpu.begin();
  gpu.grid_at_positions();
  gpu.density();
  gpu.correction_and_predict();
  gpu.finish();
  ParticleState g = gpu.download();
  for (glm::dvec3& v : g.v) v -= d.gravity * d.dt;  // the pass predicts too: gravity's part out
  std::vector<glm::dvec3> dv_ref;
  for (const auto& f : reference_forces(scene, st)) dv_ref.push_back(f * d.dt);
  test::ErrorReport e =
      test::compare(g.v, dv_ref, std::string("LDC dv on a two-density slab, ") + (clamp ? "clamped" : "unclamped"));
  EXPECT_LE(e.max_abs, 1e-3 * e.scale);
  EXPECT_GT(e.scale, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Variants, LdcGpuTest, ::testing::Bool(),
                         [](const auto& info) { return std::string(info.param ? "clamped" : "unclamped"); });

}  // namespace
}  // namespace pbflow
