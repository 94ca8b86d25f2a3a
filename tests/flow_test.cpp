// Emitters and drains (sim/flow.hpp): the count balances, both solvers agree, a jet leaves its
// inlet at the rest density, the capacity holds, and the flow's energy is accounted for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "gpu/gpu_solver.hpp"
#include "gpu/memory_estimate.hpp"
#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "sim/reference_solver.hpp"
#include "sim/settle.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

class FlowTest : public test::GpuTest {};

// The fountain at 0.04 m, its jet a 3 x 3 square (the disc would be one particle at this
// spacing) and fast enough for a layer most frames.
Scene coarse_fountain(std::vector<std::string> keys = {}) {
  // The drains' tops off the lattice's layers (at 0.02 and 0.06 m): a particle on a drain's
  // face is inside in one solver's rounding and outside in the other's.
  keys.insert(keys.begin(), {"particle_spacing=0.04",
                             R"(emitters=[{"centre": [0.3, 0.12, 0.4], "normal": [0.25, 1, 0], "size": [0.1, 0.1], "speed": 2.5}])",
                             R"(drains=[{"min": [-1, -1, -1], "max": [0.1, 0.035, 1]}, {"min": [0.7, -1, -1], "max": [1, 0.035, 1]}])"});
  return load_scene("fountain", keys);
}

// Counts, ids and positions agree frame by frame while the drains take the pool's edge and the
// jet rises (drains: the GPU's particles come down and go back whole), and with the jet alone
// (only the new particles go up): the flow is the same host function in both.
// (LDC reads rho at x from the last step's lists: both build them anew after the flow.)
struct FlowCase {
  const char* name;
  bool drains;
  const char* method;
};
void PrintTo(const FlowCase& c, std::ostream* os) { *os << c.name; }
class FlowAgreeTest : public test::GpuTest, public ::testing::WithParamInterface<FlowCase> {};

TEST_P(FlowAgreeTest, GpuAndReferenceAgreeAsWaterEntersAndLeaves) {
  const FlowCase& c = GetParam();
  std::vector<std::string> keys{std::string("solver.method=\"") + c.method + "\""};
  if (!c.drains) keys.push_back("drains=[]");
  const Scene scene = coarse_fountain(keys);
  const Derived d = derive(scene);
  const auto x0 = initial_particles(scene);
  GpuSolver gpu(test::gpu(), d, x0);
  ReferenceSolver ref(d, x0);
  EXPECT_EQ(gpu.capacity(), ref.capacity());
  uint32_t emitted = 0, drained = 0;
  for (int frame = 0; frame < 4; ++frame) {
    const FrameStats g = gpu.advance(2), r = ref.advance(2);
    EXPECT_EQ(g.count, r.count) << "frame " << frame;
    EXPECT_EQ(g.emitted, r.emitted) << "frame " << frame;
    EXPECT_EQ(g.drained, r.drained) << "frame " << frame;
    EXPECT_NEAR(g.flow_energy, r.flow_energy, 1e-5 + 1e-4 * std::abs(r.flow_energy));  // J
    EXPECT_NEAR(g.kinetic_energy, r.kinetic_energy, 1e-3 * r.kinetic_energy);
    emitted += r.emitted, drained += r.drained;
  }
  EXPECT_GT(emitted, 0u) << "the jet emitted nothing";
  if (c.drains) {
    EXPECT_GT(drained, 0u) << "the drains took nothing";
  }
  const ParticleState g = gpu.download();
  ASSERT_EQ(g.id, ref.state.id);
  const test::ErrorReport e = test::compare(g.x, ref.state.x, "positions after 8 steps with flow");
  EXPECT_LT(e.max_abs, 1e-5);  // metres
}

INSTANTIATE_TEST_SUITE_P(Flow, FlowAgreeTest,
                         ::testing::Values(FlowCase{"drained", true, "pbf"}, FlowCase{"emitted_alone", false, "pbf"},
                                           FlowCase{"ldc_drained", true, "ldc"}),
                         [](const auto& info) { return std::string(info.param.name); });

// Every frame's count is the last one's plus what entered less what left; past the capacity the
// emitters wait (and say so) and the count never passes it.
TEST_F(FlowTest, TheCountBalancesAndTheCapacityHolds) {
  const Scene probe = coarse_fountain();
  const size_t start = initial_particles(probe).size();
  // Room for two of the jet's layers, and no drain to make more.
  const Scene scene = coarse_fountain({"capacity=" + std::to_string(start + 20), "drains=[]"});
  GpuSolver gpu(test::gpu(), derive(scene), initial_particles(scene));
  ASSERT_EQ(gpu.capacity(), start + 20);
  uint32_t count = uint32_t(start);
  bool paused = false;
  for (int frame = 0; frame < 30; ++frame) {
    const FrameStats s = gpu.advance(2);
    EXPECT_EQ(s.count, count + s.emitted - s.drained) << "frame " << frame;
    EXPECT_LE(s.count, gpu.capacity()) << "frame " << frame;
    EXPECT_EQ(s.count, gpu.particle_count());
    count = s.count;
    paused = paused || s.paused;
  }
  EXPECT_TRUE(paused) << "the emitters never reached the capacity";
  ParticleState past = gpu.download();  // a state past the buffers' room is refused, not cut
  past.x.resize(gpu.capacity() + 1, past.x.back());
  past.v.resize(past.x.size()), past.x_pred = past.x, past.id.clear();
  EXPECT_THROW(gpu.upload(past), std::invalid_argument);
}

// A jet in weightless air: its layers leave the inlet a spacing apart at the inlet's speed, so
// its inside reads the rest density (the lattice's, 1e-3 at most off) from the first layer on.
TEST_F(FlowTest, AJetLeavesItsInletAtTheRestDensity) {
  const Scene scene = load_scene(
      "fountain", {"gravity=[0, 0, 0]", "drains=[]", R"(fluid_blocks=[{"min": [0.7, 0, 0.7], "max": [0.8, 0.04, 0.8]}])",
                   R"(emitters=[{"centre": [0.1, 0.25, 0.4], "normal": [1, 0, 0], "size": [0.16, 0.16], "speed": 1.2}])"});
  const Derived d = derive(scene);
  GpuSolver gpu(test::gpu(), d, initial_particles(scene));
  for (int frame = 0; frame < 15; ++frame) gpu.advance(scene.solver.substeps);
  const ParticleFrame f = gpu.read_frame();
  double front = 0;
  for (const glm::vec4& x : f.x) front = x.y > 0.1 ? std::max(front, double(x.x)) : front;
  ASSERT_GT(front, 0.1 + 8 * d.spacing) << "the jet has not left its inlet";
  int inside = 0;
  double worst = 0;
  for (size_t i = 0; i < f.x.size(); ++i) {
    const glm::dvec3 x(f.x[i]);
    const bool deep = std::abs(x.y - 0.25) <= d.spacing + 1e-6 && std::abs(x.z - 0.4) <= d.spacing + 1e-6 &&
                      x.x > 0.1 + d.h + 1e-6 && x.x < front - d.h - 1e-6;
    if (!deep) continue;
    ++inside;
    worst = std::max(worst, std::abs(f.rho[i] / d.rho0 - 1.0));
  }
  std::printf("  %d particles inside the jet, the furthest from rho0 %.2e\n", inside, worst);
  EXPECT_GT(inside, 9);
  EXPECT_LT(worst, 1e-3);
}

// The fountain for 2 s: the fluid gains no energy beyond what the jet brings and the gutters
// take (EnergyGain's bar, docs/design.md), and the pool holds its count within a tenth.
TEST_F(FlowTest, TheFountainGainsNothingBeyondItsFlowSlow) {
  const Scene scene = load_scene("fountain");
  const Derived d = derive(scene);
  const size_t start = initial_particles(scene).size();
  GpuSolver gpu(test::gpu(), d, initial_particles(scene));
  relax_start(gpu);
  ASSERT_TRUE(settle(gpu, d).converged);
  EnergyGain energy;
  energy.add(gpu.advance(0));
  uint32_t emitted = 0, drained = 0;
  for (int frame = 1; frame <= 120; ++frame) {
    const FrameStats s = gpu.advance(scene.solver.substeps);
    ASSERT_FALSE(s.divergence.any()) << "frame " << frame;
    energy.add(s);
    emitted += s.emitted, drained += s.drained;
  }
  std::printf("  2 s: %u emitted, %u drained, %zu particles, largest gain %.4f\n", emitted, drained, gpu.particle_count(),
              energy.largest());
  EXPECT_GT(emitted, 1000u);
  EXPECT_GT(drained, 0u);
  EXPECT_NEAR(double(gpu.particle_count()), double(start), 0.1 * double(start));
  EXPECT_LE(energy.largest(), 0.01);
}

// A run with flow exports every frame whole: each PLY holds the frame's count from stats.csv
// (the rows in ascending id order, ids no longer 0 to n - 1 once particles left).
// A live run makes solvers anew (another setting, its substeps too) and carries the state: the
// emitters' clock goes with it, in seconds, so a jet that stopped stays stopped, and the solids'
// clock lands on the nearest step of the new dt.
TEST(FlowCarry, ASolverMadeAnewKeepsTheEmittersAndTheSolidsClocks) {
  Scene scene = coarse_fountain({R"(emitters=[{"centre": [0.3, 0.12, 0.4], "normal": [0, 1, 0], "size": [0.1, 0.1], "speed": 2.5, "stop": 0.05}])",
                                 "drains=[]"});
  ReferenceSolver first(derive(scene), initial_particles(scene));
  uint32_t emitted = 0;
  for (int frame = 0; frame < 5; ++frame) emitted += first.advance(scene.solver.substeps).emitted;
  ASSERT_GT(emitted, 0u) << "the jet never ran";
  const SolidsState solids = first.solids();
  EXPECT_NEAR(solids.flow_time, 5.0 / scene.fps, 1e-12);
  scene.solver.substeps = 3;  // another step: the clock is a time, not a count of steps
  ReferenceSolver next(derive(scene), initial_particles(scene));
  next.upload(first.download());
  next.carry(solids);
  EXPECT_NEAR(next.solids().flow_time, solids.flow_time, 0.5 * derive(scene).dt);
  EXPECT_NEAR(next.solids().time, solids.time, 0.5 * derive(scene).dt);
  for (int frame = 0; frame < 3; ++frame)
    EXPECT_EQ(next.advance(scene.solver.substeps).emitted, 0u) << "the jet stopped at 0.05 s began again, frame " << frame;
}

// A capacity past what the device holds is bad input that names the key to lower, before anything
// is written.
TEST(FlowCli, ACapacityPastTheDeviceIsRefusedNamingIt) {
  const Scene scene = load_scene("fountain", {"capacity=100000000"});
  const vk::DeviceInfo& device = test::gpu().info();
  const MemoryNeed need = memory_need(derive(scene), particle_estimate(scene), &device);
  if (need.device <= device.device_local_bytes && need.largest_array <= device.max_storage_buffer_range)
    GTEST_SKIP() << device.name << " has room for 100 000 000 particles";
  const std::filesystem::path dir = test::fresh_dir("flow_capacity");
  const test::CliResult r = test::run_pbflow("run fountain --no-render --frames 2 --param capacity=100000000 --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("lower capacity (room for 100000000 particles"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir)) << "a refused run wrote " << dir;
}

TEST(FlowCli, ARunWithFlowExportsEachFramesParticles) {
  const std::filesystem::path dir = test::fresh_dir("flow_export");
  // A drain over the floor's first layer by one wall: particles leave at the first frame.
  const test::CliResult r = test::run_pbflow(
      "run fountain --no-render --export ply --frames 5 --quiet --param particle_spacing=0.04 --param "
      "'drains=[{\"min\": [-1, -1, -1], \"max\": [0.1, 0.035, 1]}]' --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream stats(dir / "stats.csv");
  std::string line;
  std::getline(stats, line);
  ASSERT_NE(line.find(",particles,emitted,drained,"), std::string::npos) << line;
  int frames = 0;
  uint32_t drained = 0;
  std::vector<uint32_t> before;  // the last frame's ids
  for (; std::getline(stats, line); ++frames) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    const std::string count = cells.at(9);
    drained += uint32_t(std::stoul(cells.at(11)));
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.ply", frames);
    std::ifstream ply(dir / "particles" / name, std::ios::binary);
    const std::string file((std::istreambuf_iterator<char>(ply)), std::istreambuf_iterator<char>());
    EXPECT_NE(file.find("element vertex " + count + "\n"), std::string::npos) << name << " should hold " << count;
    // Each record seven floats and the id; the ids ascend, and a particle keeps its id: each is
    // one the last frame held, or newer than all of them (an emitter's).
    ASSERT_NE(file.find("property float density\nproperty uint id\nend_header\n"), std::string::npos) << name;
    const size_t body = file.find("end_header\n") + 11, records = (file.size() - body) / 32;
    ASSERT_EQ(records, std::stoul(count)) << name;
    std::vector<uint32_t> ids(records);
    for (size_t k = 0; k < records; ++k) std::memcpy(&ids[k], file.data() + body + 32 * k + 28, 4);
    EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()) && std::adjacent_find(ids.begin(), ids.end()) == ids.end()) << name;
    const uint32_t newest = before.empty() ? 0 : before.back();
    for (uint32_t id : ids)
      EXPECT_TRUE(before.empty() || id > newest || std::binary_search(before.begin(), before.end(), id)) << name << " id " << id;
    if (drained > 0) {
      EXPECT_GE(ids.back(), ids.size()) << name << ": the drained particles' ids left no gap";
    }
    before = ids;
  }
  EXPECT_EQ(frames, 5);
  EXPECT_GT(drained, 0u) << "no particle left: the ids stayed 0 to n - 1";
}

}  // namespace
}  // namespace pbflow
