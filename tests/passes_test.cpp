// Every GPU pass against the reference on the same input, then whole steps.
// Tolerances: the GPU computes in float (relative precision 6e-8); sums of ~30
// neighbour terms and the cancellation in differences like x_pred - x cost a few
// hundred ulps at most, so a pass agrees to a relative 1e-4 of the field's scale.
#include <optional>
#include <random>

#include "gpu/gpu_solver.hpp"
#include "sim/reference_solver.hpp"
#include "sim/settle.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

constexpr double kPassTolerance = 1e-4;  // max error / max |reference value|

void expect_close(const test::ErrorReport& e, double tolerance = kPassTolerance) {
  EXPECT_GT(e.scale, 0.0) << "the compared field is all zeros: the test compares nothing";
  EXPECT_LE(e.max_abs, tolerance * e.scale);
}

// The passes read neighbour lists (shaders/neighbours.glsl); a particle whose list is full
// walks its cells instead. Each test runs with the scene's capacity (no list full), with
// 24 entries (the jittered lattice's ~30 neighbours fill some lists), with 1 (all full)
// and with none (no lists: what a run too large for the device's buffers gets). Beside the
// mesh, 24 entries hold some particles' neighbours but not their images too (50 of its ~300):
// those lists overflow in the lists pass's near variant, not in its walk (neighbour_lists.comp);
// without lists that variant runs over every particle, for the mesh's creases alone.
// The obstacles stand inside the column, so that particles meet them from the first step.
constexpr const char* kObstaclesInTheColumn =
    R"([{"type": "box", "min": [0.25, 0, 0.1], "max": [0.45, 0.2, 0.3]},
        {"type": "sphere", "centre": [0.2, 0.5, 0.2], "radius": 0.1}])";
// The same solids moving: the box turning about its upright axis, the ball swinging along x.
constexpr const char* kMovingInTheColumn =
    R"([{"type": "box", "min": [0.25, 0, 0.1], "max": [0.45, 0.2, 0.3],
         "motion": {"type": "rotate", "axis": [0, 1, 0], "rate": 300}},
        {"type": "sphere", "centre": [0.2, 0.5, 0.2], "radius": 0.1,
         "motion": {"type": "oscillate", "axis": [1, 0, 0], "amplitude": 0.05, "period": 0.5}}])";
// The same solids, the fluid sticking to them ("slip": false): pulled along their surfaces in
// the viscosity pass, and stopped where it meets them rather than along their normals.
constexpr const char* kStickyInTheColumn =
    R"([{"type": "box", "min": [0.25, 0, 0.1], "max": [0.45, 0.2, 0.3], "slip": false,
         "motion": {"type": "rotate", "axis": [0, 1, 0], "rate": 300}},
        {"type": "sphere", "centre": [0.2, 0.5, 0.2], "radius": 0.1, "slip": false,
         "motion": {"type": "oscillate", "axis": [1, 0, 0], "amplitude": 0.05, "period": 0.5}}])";
// The dam break's tank shaken sideways and up at once (keyframes, a kick at each key).
constexpr const char* kShakenTank =
    R"({"min": [0, 0, 0], "max": [1.6, 1.0, 0.4], "motion": {"type": "keyframes", "keys": [
        {"t": 0, "position": [0, 0, 0]}, {"t": 0.02, "position": [0.01, 0.004, 0]}, {"t": 0.05, "position": [0, 0, 0]}]}})";
// The tank turning about z as it shakes: the rotating frame's terms in every particle's kick.
constexpr const char* kTurningTank =
    R"({"min": [0, 0, 0], "max": [1.6, 1.0, 0.4], "motion": {"type": "keyframes", "centre": [0, 0, 0.2], "keys": [
        {"t": 0, "position": [0, 0, 0]}, {"t": 0.02, "position": [0.01, 0.004, 0], "rotation": [0, 0, 1]},
        {"t": 0.05, "position": [0, 0, 0], "rotation": [0, 0, 2]}]}})";
// A mesh in the column (scripts/make_meshes.py's rock): its distance field read by both solvers.
const std::string kMeshInTheColumn =
    std::string(R"([{"type": "mesh", "file": ")") + PBFLOW_TEST_DATA + R"(/../scenes/meshes/rock.obj", "position": [0.25, 0.2, 0.2]}])";

struct ListCase {
  const char* name;
  int capacity;                  // -1: the scene's own (Derived::neighbour_capacity)
  const char* obstacles = "[]";  // JSON: with obstacles, their images take part (sim/solids/mirrors.hpp)
  // The lists pass's layout (GpuLayout: where the near particles' images are listed), or the device's.
  std::optional<GpuLayout> layout = std::nullopt;
};
void PrintTo(const ListCase& c, std::ostream* os) { *os << c.name; }

class PassTest : public test::GpuTest, public ::testing::WithParamInterface<ListCase> {
 protected:
  // Coarse dam break with every optional pass switched on (ldc's correction among them).
  Scene scene = load_scene("dam_break", {"particle_spacing=0.04", "solver.xsph=0.05", "solver.vorticity=0.1",
                                         "solver.method=ldc", std::string("obstacles=") + GetParam().obstacles});
  Derived d = with_capacity(derive(scene), GetParam().capacity);
  ParticleState input = test::jittered_state(scene);
  GpuSolver gpu{test::gpu(), d, input.x, GetParam().layout};
  ReferenceSolver ref{d, input.x};

  void SetUp() override {
    test::GpuTest::SetUp();
    gpu.upload(input);
    ref.state = input;
  }
  template <class Record>
  ParticleState run_gpu(Record&& record) {
    gpu.begin();
    record();
    gpu.finish();
    return gpu.download();
  }
  // One viscosity_vorticity pass at x from `input`, its densities uploaded, on the GPU
  // and on the reference.
  ParticleState gpu_viscosity(GpuSolver& g) {
    g.upload(input);
    g.begin();
    g.grid_at_positions();
    g.viscosity_vorticity();
    g.finish();
    return g.download();
  }
  // Returns rho at x, which the GPU's viscosity pass sums too (for the next step).
  std::vector<double> reference_viscosity(ReferenceSolver& r) {
    r.state = input;
    r.build_grid(r.state.x);
    r.density();  // for its lists at x (the GPU's grid_at_positions builds them); the dashpot
    std::vector<double> at_x = r.state.rho;
    r.state.rho = input.rho;  // reads the uploaded densities, as on the GPU
    r.viscosity_vorticity();
    return at_x;
  }
  // One lambda pass and one apply pass (relaxation 0.5) at x_pred from `input`: how far
  // they moved x_pred, on the GPU and on the reference.
  std::vector<glm::dvec3> gpu_apply_dp(GpuSolver& g) {
    g.upload(input);
    g.begin();
    g.grid_at_predictions();
    g.constraint_lambda();
    g.constraint_apply(0.5);
    g.finish();
    return test::difference(g.download().x_pred, input.x_pred);
  }
  std::vector<glm::dvec3> reference_apply_dp(ReferenceSolver& r) {
    r.state = input;
    r.build_grid(r.state.x_pred);
    r.constraint_lambda();
    r.constraint_apply(0.5);
    return test::difference(r.state.x_pred, input.x_pred);
  }
  static Derived with_capacity(Derived d, int capacity) {
    if (capacity >= 0) d.neighbour_capacity = uint32_t(capacity);
    return d;
  }
};

TEST_P(PassTest, Density) {
  ParticleState g = run_gpu([&] {
    gpu.grid_at_positions();
    gpu.density();
  });
  ref.build_grid(ref.state.x);
  ref.density();
  expect_close(test::compare(g.rho, ref.state.rho, "density rho"));
}

// The positions the fluid's surface is drawn from, at x from the lists at x: how far each
// particle moved towards its neighbourhood's mean (small beside x itself).
TEST_P(PassTest, SmoothedPositions) {
  gpu.set_outputs({.surface = true});
  gpu.begin();
  gpu.grid_at_positions();
  gpu.smoothed_positions();
  gpu.finish();
  const ParticleFrame f = gpu.read_frame();
  ASSERT_EQ(f.x_smooth.size(), input.x.size());
  std::vector<glm::dvec3> g(input.x.size());
  for (size_t k = 0; k < f.id.size(); ++k) g[f.id[k]] = glm::dvec3(glm::vec3(f.x_smooth[k]));
  ref.build_grid(ref.state.x);
  const ReferenceSolver::DrawnParticles drawn = ref.smoothed_positions();
  expect_close(test::compare(test::difference(g, input.x), test::difference(drawn.x, input.x),
                             "smoothed positions x_smooth - x"),
               1e-3);
  // The drawn shapes, compared as the ellipsoids' matrices (an eigenvector's sign and the
  // order of equal axes are arbitrary), each as its three columns.
  ASSERT_EQ(f.shape.size(), 2 * input.x.size());
  std::vector<glm::dvec3> shape_gpu(3 * input.x.size()), shape_ref;
  for (size_t k = 0; k < f.id.size(); ++k) {
    const glm::dmat3 t = decode_shape(f.shape[2 * k], f.shape[2 * k + 1]);
    for (int c = 0; c < 3; ++c) shape_gpu[3 * f.id[k] + c] = t[c];
  }
  for (const glm::dmat3& t : drawn.shape)
    for (int c = 0; c < 3; ++c) shape_ref.push_back(t[c]);
  expect_close(test::compare(shape_gpu, shape_ref, "drawn shapes T (particle radii)"), 1e-3);
}

TEST_P(PassTest, CorrectionForceAndPredict) {
  ParticleState g = run_gpu([&] {
    gpu.grid_at_positions();
    gpu.density();
    gpu.correction_and_predict();
  });
  ref.build_grid(ref.state.x);
  ref.density();
  ref.correction();
  ref.predict();
  // Compare the velocity change (f + g) dt: it is small next to v itself.
  expect_close(test::compare(test::difference(g.v, input.v), test::difference(ref.state.v, input.v),
                             "correction force and gravity dv = (f + g) dt"),
               1e-3);
  expect_close(test::compare(g.x_pred, ref.state.x_pred, "correction and predict x_pred"));
}

TEST_P(PassTest, Predict) {
  ParticleState g = run_gpu([&] { gpu.predict(); });
  ref.predict();
  expect_close(test::compare(g.v, ref.state.v, "predict v"));
  expect_close(test::compare(g.x_pred, ref.state.x_pred, "predict x_pred"));
}

TEST_P(PassTest, ConstraintLambda) {
  ParticleState g = run_gpu([&] {
    gpu.grid_at_predictions();
    gpu.constraint_lambda();
  });
  ref.build_grid(ref.state.x_pred);
  ref.constraint_lambda();
  expect_close(test::compare(g.lambda, ref.state.lambda, "constraint lambda"));
}

TEST_P(PassTest, ConstraintSmooth) {
  ASSERT_GT(d.solver.lambda_smoothing, 0);
  ParticleState g = run_gpu([&] {
    gpu.grid_at_predictions();
    gpu.constraint_lambda();
    gpu.constraint_smooth();
  });
  ref.build_grid(ref.state.x_pred);
  ref.constraint_lambda();
  const std::vector<double> raw = ref.state.lambda;
  ref.constraint_smooth();
  expect_close(test::compare(g.lambda, ref.state.lambda, "smoothed lambda"));
  // The smoothing did something: the smoothed field is not the raw one.
  const test::ErrorReport change = test::compare(ref.state.lambda, raw, "smoothing's change of lambda");
  EXPECT_GT(change.max_abs, 0.1 * change.scale);
}

TEST_P(PassTest, ConstraintApply) {
  expect_close(test::compare(gpu_apply_dp(gpu), reference_apply_dp(ref), "constraint apply dp"), 1e-3);
}

// The coarse correction (paired iterations only), as a step's first iteration runs it: the
// lambda pass (rho at x_pred), the deposit, the solve and the move, then the apply pass (the
// move goes to x_lambda, which the apply pass turns into x_pred), on the GPU and the reference.
void expect_coarse_correction_matches(const Derived& d, const ParticleState& input, const char* what) {
  ASSERT_GT(d.coarse.strength, 0.0);
  GpuSolver g(test::gpu(), d, input.x);
  ReferenceSolver r(d, input.x);
  g.upload(input);
  g.begin();
  g.grid_at_predictions();
  g.constraint_lambda();
  g.coarse_correction();
  g.constraint_apply(0.5);
  g.finish();
  r.state = input;
  r.build_grid(r.state.x_pred);
  r.constraint_lambda();
  const std::vector<glm::dvec3> before = r.state.x_pred;
  r.coarse_correction();
  const test::ErrorReport moved = test::compare(r.state.x_pred, before, "the coarse move alone");
  EXPECT_GT(moved.max_abs, 0.0) << "the jittered column's compression moves it";
  r.constraint_apply(0.5);
  expect_close(test::compare(test::difference(g.download().x_pred, input.x_pred),
                             test::difference(r.state.x_pred, input.x_pred), what),
               1e-3);
}

TEST_P(PassTest, CoarseCorrection) {
  Scene paired = scene;
  paired.solver.iterations = 2;
  expect_coarse_correction_matches(with_capacity(derive(paired), GetParam().capacity), input,
                                   "coarse correction and apply");
}

// A grid whose phi outgrows a workgroup's shared memory sweeps in a dispatch per half sweep
// (GpuSolver's coarse_sweep_group): the same column in a tank wide enough for 50 x 19 x 19 nodes.
using CoarseTest = test::GpuTest;
TEST_F(CoarseTest, SweepsADispatchAHalfSweepOnALargeGrid) {
  Scene wide = load_scene("dam_break", {"particle_spacing=0.04", "solver.iterations=2"});
  wide.domain.max = {8.0, 3.0, 3.0};
  const Derived d = derive(wide);
  ASSERT_GT(d.coarse.count() * sizeof(float), test::gpu().limits().maxComputeSharedMemorySize);
  expect_coarse_correction_matches(d, test::jittered_state(wide), "coarse correction on a large grid");
}

// A closed tank full to its lid has no node of air: both solvers take the mean excess off every
// node's source (contract.h, COARSE_TOTALS), the GPU from its fixed-point totals.
TEST_F(CoarseTest, AFullClosedTanksSourceLosesItsMean) {
  Scene full = load_scene("dam_break", {"particle_spacing=0.04", "solver.iterations=2", "domain.max=[0.4,0.4,0.4]",
                                        R"(fluid_blocks=[{"min":[0,0,0],"max":[0.4,0.4,0.4]}])"});
  expect_coarse_correction_matches(derive(full), test::jittered_state(full), "coarse correction in a full tank");
}

// A later iteration reads the lists the first built, at positions that have moved since.
TEST_P(PassTest, SecondIterationReadsTheFirstOnesLists) {
  ParticleState g = run_gpu([&] {
    gpu.grid_at_predictions();
    for (int k = 0; k < 2; ++k) {
      gpu.constraint_lambda();
      gpu.constraint_apply(0.5);
    }
  });
  ref.build_grid(ref.state.x_pred);
  for (int k = 0; k < 2; ++k) {
    ref.constraint_lambda();
    ref.constraint_apply(0.5);
  }
  expect_close(test::compare(g.lambda, ref.state.lambda, "second constraint lambda"), 1e-3);
  expect_close(test::compare(test::difference(g.x_pred, input.x_pred),
                             test::difference(ref.state.x_pred, input.x_pred), "two constraint iterations dp"),
               1e-3);
}

TEST_P(PassTest, VelocityUpdate) {
  ParticleState g = run_gpu([&] { gpu.velocity_update(); });
  ref.velocity_update();
  expect_close(test::compare(g.v, ref.state.v, "velocity update v"), 1e-3);
  expect_close(test::compare(g.x, ref.state.x, "velocity update x = x_pred"));
}

// The dashpot reads the last lambda pass's densities (squeezed pairs are damped less),
// on the GPU from v's w, which the upload fills from rho: densities from 0.9 to 2.1 rho0
// put some pairs past the cap (DAMPING_LIMIT rho0 / max(rho_i, rho_j) < DAMPING from
// ~1.5 rho0 on) and leave others under it.
TEST_P(PassTest, ViscosityAndVorticity) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> squeeze(0.9, 2.1);
  for (double& r : input.rho) r = d.rho0 * squeeze(rng);
  ASSERT_LT(d.damping_limit / 2.1, d.solver.damping) << "no pair reaches the cap";
  ParticleState g = gpu_viscosity(gpu);
  std::vector<double> rho_at_x = reference_viscosity(ref);
  expect_close(test::compare(test::difference(g.v, input.v), test::difference(ref.state.v, input.v), "XSPH and damping dv"));
  expect_close(test::compare(g.curl, ref.state.curl, "vorticity curl"));
  expect_close(test::compare(g.rho, rho_at_x, "rho at x, summed by the viscosity pass"));
}

// Without vorticity the pass skips the curl (a specialisation constant) and keeps no
// curl: the velocity change must still be the reference's.
TEST_P(PassTest, ViscosityWithoutVorticity) {
  Derived plain = d;
  plain.solver.vorticity = 0.0;
  GpuSolver gpu_plain{test::gpu(), plain, input.x};
  ReferenceSolver ref_plain{plain, input.x};
  ParticleState g = gpu_viscosity(gpu_plain);
  std::vector<double> rho_at_x = reference_viscosity(ref_plain);
  expect_close(test::compare(test::difference(g.v, input.v), test::difference(ref_plain.state.v, input.v),
                             "XSPH and damping dv, no vorticity"));
  expect_close(test::compare(g.rho, rho_at_x, "rho at x, summed by the viscosity pass, no vorticity"));
  EXPECT_TRUE(g.curl.empty()) << "no vorticity storage without vorticity";
}

TEST_P(PassTest, VorticityForce) {
  ParticleState before = run_gpu([&] {
    gpu.grid_at_positions();
    gpu.density();
    gpu.viscosity_vorticity();
  });
  ParticleState g = run_gpu([&] { gpu.vorticity_force(); });
  ref.build_grid(ref.state.x);
  ref.density();
  ref.viscosity_vorticity();
  std::vector<glm::dvec3> ref_before = ref.state.v;
  ref.vorticity_force();
  expect_close(test::compare(test::difference(g.v, before.v), test::difference(ref.state.v, ref_before),
                             "vorticity force dv"),
               1e-3);
}

TEST_P(PassTest, Measures) {
  FrameStats g = gpu.advance(0), r = ref.advance(0);
  EXPECT_NEAR(g.mean_compression, r.mean_compression, 1e-5);
  EXPECT_NEAR(g.max_compression, r.max_compression, 1e-5);
  EXPECT_NEAR(g.kinetic_energy, r.kinetic_energy, 1e-5 * r.kinetic_energy);
  EXPECT_NEAR(g.max_speed, r.max_speed, 1e-5 * r.max_speed);
  EXPECT_GT(r.max_compression, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Lists, PassTest,
                         ::testing::Values(ListCase{"listed", -1}, ListCase{"some_full", 24}, ListCase{"all_full", 1},
                                           ListCase{"no_lists", 0}, ListCase{"obstacles", -1, kObstaclesInTheColumn},
                                           ListCase{"obstacles_all_full", 1, kObstaclesInTheColumn},
                                           ListCase{"sticky", -1, kStickyInTheColumn},
                                           ListCase{"mesh", -1, kMeshInTheColumn.c_str()},
                                           ListCase{"mesh_some_full", 24, kMeshInTheColumn.c_str()},
                                           ListCase{"mesh_no_lists", 0, kMeshInTheColumn.c_str()},
                                           ListCase{"mesh_walked", -1, kMeshInTheColumn.c_str(), GpuLayout{true}},
                                           ListCase{"mesh_walked_some_full", 24, kMeshInTheColumn.c_str(), GpuLayout{true}}),
                         [](const auto& info) { return std::string(info.param.name); });

constexpr const char* kDamBreakDomain = R"({"min": [0, 0, 0], "max": [1.6, 1.0, 0.4]})";
// The column standing in the mixer's bowl as the domain's mesh: the fluid inside it, the walls no mirror.
constexpr const char* kBowlDomain =
    R"({"min": [0, 0, 0], "max": [1.6, 1.0, 0.4], "mesh": {"file": "meshes/bowl.obj", "position": [0.2, 0, 0.2]}})";
// The tank as a box-shaped mesh: its edges and corners are concave creases, each face a plane
// mirror there (Mirrors::creases).
const std::string kBoxTankDomain = R"({"min": [0, 0, 0], "max": [1.6, 1.0, 0.4], "mesh": {"file": ")" +
                                   test::box_mesh({0, 0, 0}, {1.6, 1.0, 0.4}) + R"("}})";

// Whole steps of both methods from the lattice: positions drift apart only by float
// rounding, a few micrometres over 4 steps (spacing 40 mm).
struct StepCase {
  const char* name;
  const char* method;
  const char* obstacles;  // JSON for the scene's obstacles
  const char* domain = kDamBreakDomain;  // or shaken
  bool steered = false;  // a viewer's hand (Derived::steerable): the box dragged, the tank shaken
  std::optional<GpuLayout> layout = std::nullopt;  // as ListCase's
};
void PrintTo(const StepCase& c, std::ostream* os) { *os << c.name; }

class StepTest : public test::GpuTest, public ::testing::WithParamInterface<StepCase> {};

TEST_P(StepTest, SeveralStepsAgree) {
  const StepCase& c = GetParam();
  Scene scene = load_scene("dam_break", {"particle_spacing=0.04", std::string("solver.method=\"") + c.method + "\"",
                                         "solver.iterations=2", "solver.vorticity=0.1",
                                         std::string("obstacles=") + c.obstacles, std::string("domain=") + c.domain});
  Derived d = derive(scene);
  if (c.steered) d.make_steerable();
  auto x0 = initial_particles(scene);
  GpuSolver gpu(test::gpu(), d, x0, c.layout);
  ReferenceSolver ref(d, x0);
  Motion shake;
  shake.type = Motion::Type::Oscillate, shake.axis = {0, 0, 1}, shake.amplitude = 0.01, shake.period = 0.1;
  for (Solver* solver : std::initializer_list<Solver*>{&gpu, &ref})
    if (c.steered)
      solver->drag(0, {-0.1, 0.05, 0}), solver->shake(shake), solver->tilt(glm::angleAxis(glm::radians(10.0), glm::dvec3(1, 0, 0)));
  for (int frame = 0; frame < 2; ++frame) {
    FrameStats g = gpu.advance(2), r = ref.advance(2);
    EXPECT_NEAR(g.mean_compression, r.mean_compression, 1e-4 + 1e-2 * r.mean_compression);
    EXPECT_NEAR(g.kinetic_energy, r.kinetic_energy, 1e-3 * r.kinetic_energy);
    EXPECT_NEAR(g.solid_work, r.solid_work, 1e-6 + 1e-2 * std::abs(r.solid_work));  // J
    if (d.moving()) {
      EXPECT_GT(std::abs(r.solid_work), 1e-4) << "the moving solids did no work";
    }
  }
  ParticleState g = gpu.download();
  test::ErrorReport e = test::compare(g.x, ref.state.x, std::string(c.name) + " positions after 4 steps");
  test::ErrorReport ev = test::compare(g.v, ref.state.v, std::string(c.name) + " velocities after 4 steps");
  EXPECT_LT(e.max_abs, 1e-5);                 // metres
  EXPECT_LT(ev.max_abs, 1e-3 * ev.scale);
}

// The start's relaxation (Solver::relax, sim/settle.hpp): the GPU's relaxations agree with the
// reference's, leave the fluid at rest, and take out the compression the jitter brought.
TEST_P(StepTest, TheStartsRelaxationAgreesAndDecompresses) {
  const StepCase& c = GetParam();
  Scene scene = load_scene("dam_break", {"particle_spacing=0.04", std::string("solver.method=\"") + c.method + "\"",
                                         std::string("obstacles=") + c.obstacles});
  Derived d = derive(scene);
  auto x0 = initial_particles(scene);
  GpuSolver gpu(test::gpu(), d, x0, c.layout);
  ReferenceSolver ref(d, x0);
  const double seeded = ref.advance(0).mean_compression;
  relax_start(gpu);
  relax_start(ref);
  const FrameStats g = gpu.advance(0), r = ref.advance(0);
  std::printf("  %s: mean compression %.5f seeded, %.5f relaxed (reference %.5f)\n", c.name, seeded,
              g.mean_compression, r.mean_compression);
  EXPECT_LT(r.mean_compression, 0.5 * seeded);
  EXPECT_NEAR(g.mean_compression, r.mean_compression, 1e-4 + 1e-2 * r.mean_compression);
  EXPECT_EQ(g.kinetic_energy, 0.0);
  const ParticleState gs = gpu.download();
  test::ErrorReport e = test::compare(test::difference(gs.x, x0), test::difference(ref.state.x, x0),
                                      std::string(c.name) + " the relax's moves");
  EXPECT_LT(e.max_abs, 1e-5);  // metres
  EXPECT_GT(e.scale, 0.0) << "the relax moved nothing";
}

INSTANTIATE_TEST_SUITE_P(Methods, StepTest,
                         ::testing::Values(StepCase{"pbf", "pbf", "[]"}, StepCase{"ldc", "ldc", "[]"},
                                           StepCase{"ldc_obstacles", "ldc", kObstaclesInTheColumn},
                                           StepCase{"pbf_mesh", "pbf", kMeshInTheColumn.c_str()},
                                           StepCase{"pbf_moving", "pbf", kMovingInTheColumn},
                                           StepCase{"ldc_moving", "ldc", kMovingInTheColumn},
                                           StepCase{"pbf_sticky", "pbf", kStickyInTheColumn},
                                           StepCase{"pbf_shaken", "pbf", "[]", kShakenTank},
                                           StepCase{"ldc_turning", "ldc", "[]", kTurningTank},
                                           StepCase{"ldc_steered", "ldc", kObstaclesInTheColumn, kDamBreakDomain, true},
                                           StepCase{"pbf_bowl", "pbf", "[]", kBowlDomain},
                                           StepCase{"ldc_box_tank", "ldc", "[]", kBoxTankDomain.c_str()},
                                           StepCase{"pbf_moving_walked", "pbf", kMovingInTheColumn, kDamBreakDomain, false, GpuLayout{true}},
                                           StepCase{"ldc_box_tank_walked", "ldc", "[]", kBoxTankDomain.c_str(), false, GpuLayout{true}}),
                         [](const auto& info) { return std::string(info.param.name); });

class ProfileTest : public test::GpuTest {};

// Profiling marks the end of every pass group of every step (the grid twice per ldc step):
// many steps in one frame must fit the timer, and the groups add up to the step time.
TEST_F(ProfileTest, PassGroupsOfManyStepsAddUpToTheStepTime) {
  Scene scene = load_scene("dam_break", {"particle_spacing=0.05", "solver.xsph=0.05", "solver.method=ldc"});
  GpuSolver gpu(test::gpu(), derive(scene), initial_particles(scene));
  gpu.set_profiling(true);
  gpu.advance(0);
  FrameStats s = gpu.advance(5);
  double sum = 0;
  for (double ms : s.pass_ms) sum += ms;
  EXPECT_GT(s.pass_ms[size_t(PassGroup::Correction)], 0.0);
  EXPECT_GT(s.pass_ms[size_t(PassGroup::Coarse)], 0.0);  // two iterations, the default
  EXPECT_GT(s.pass_ms[size_t(PassGroup::Viscosity)], 0.0);
  EXPECT_NEAR(sum, s.step_ms, 0.05 * s.step_ms + 1e-3) << "the groups should cover the step";
}

}  // namespace
}  // namespace pbflow
