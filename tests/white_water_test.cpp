// White water (shaders/white_water.h): the GPU's births and moves against the reference's, the
// fluid untouched by them, none in a still tank, the cap held, the files written per frame, and
// the dam break's frame at 1 s white where it foams.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>

#include "capture/particle_export.hpp"
#include "capture/png.hpp"
#include "gpu/gpu_solver.hpp"
#include "sim/reference_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

namespace fs = std::filesystem;

// The dam break at 0.03 m (4 700 particles) at 0.4 s, its front reaching the far wall, with
// many times the default emission so that a frame's births are many. In id order.
struct Splash {
  Scene scene;
  Derived d;
  ParticleState state;
  double frame_time;
};
const Splash& splash() {
  static const Splash s = [] {
    Splash s;
    s.scene = load_scene("dam_break", {"particle_spacing=0.03", "white_water.emission=1000"});
    s.d = derive(s.scene);
    GpuSolver g(test::gpu(), s.d, initial_particles(s.scene));
    for (int frame = 0; frame < 24; ++frame) g.advance(s.scene.solver.substeps);
    s.state = g.download();
    s.frame_time = s.scene.solver.substeps * s.d.dt;
    return s;
  }();
  return s;
}

// Solvers at the splash, white water on (none alive yet).
std::unique_ptr<GpuSolver> gpu_at(const Splash& s) {
  auto g = std::make_unique<GpuSolver>(test::gpu(), s.d, initial_particles(s.scene));
  g->set_outputs({.white_water = true});
  g->upload(s.state);
  return g;
}
std::unique_ptr<ReferenceSolver> reference_at(const Splash& s) {
  auto r = std::make_unique<ReferenceSolver>(s.d, initial_particles(s.scene));
  r->set_outputs({.white_water = true});
  r->upload(s.state);
  return r;
}

std::map<uint32_t, WhiteParticle> by_birth(const std::vector<WhiteParticle>& w) {  // the tag without its kind
  std::map<uint32_t, WhiteParticle> m;
  for (const WhiteParticle& p : w) m[p.tag >> WHITE_KIND_BITS] = p;
  return m;
}

// Where the GPU and the reference made or moved the same particles: how many of the
// reference's the GPU has, of the same kind, and the largest differences among those.
struct Agreement {
  size_t matched = 0, same_kind = 0;
  double x = 0, v = 0, life = 0;
};
Agreement agree(const std::vector<WhiteParticle>& gpu, const std::vector<WhiteParticle>& ref) {
  const auto g = by_birth(gpu);
  Agreement a;
  for (const WhiteParticle& r : ref) {
    auto it = g.find(r.tag >> WHITE_KIND_BITS);
    if (it == g.end()) continue;
    ++a.matched;
    if (it->second.kind() != r.kind()) continue;
    ++a.same_kind;
    a.x = std::max(a.x, glm::length(it->second.x - r.x));
    a.v = std::max(a.v, glm::length(it->second.v - r.v));
    a.life = std::max(a.life, std::abs(it->second.life - r.life));
  }
  std::printf("[ white    ] gpu %zu, reference %zu, matched %zu, same kind %zu; max |dx| %.3g m, |dv| %.3g m/s, "
              "|dlife| %.3g s\n",
              gpu.size(), ref.size(), a.matched, a.same_kind, a.x, a.v, a.life);
  return a;
}

class WhiteWater : public test::GpuTest {};

// A frame's births from the splash in both solvers, the GPU's and the reference's white water.
struct Births {
  std::vector<WhiteParticle> gpu, ref;
};
Births births_at(const Splash& s) {
  auto g = gpu_at(s);
  g->begin();
  g->grid_at_positions();
  g->white_water_emit(s.frame_time, 7);
  g->finish();
  auto r = reference_at(s);
  r->build_grid(r->state.x);
  r->white_water_emit(s.frame_time, 7);
  return {g->white_water(), r->white};
}
// The same particles (a float's rounding may tip a birth count at its threshold: 1 % leeway),
// placed, launched and aged alike.
void expect_same_births(const Births& b) {
  ASSERT_GT(b.ref.size(), 100u) << "the splash should make white water";
  const Agreement a = agree(b.gpu, b.ref);
  EXPECT_GE(double(a.same_kind), 0.99 * double(b.ref.size()));
  EXPECT_LE(double(b.gpu.size()), 1.01 * double(b.ref.size()) + 2);
  EXPECT_LT(a.x, 1e-5);
  EXPECT_LT(a.v, 1e-5);
  EXPECT_LT(a.life, 1e-5);
}

// A frame's births from the dam break's front agree.
TEST_F(WhiteWater, BirthsAgreeWithTheReference) { expect_same_births(births_at(splash())); }

// Births are seeded by each fluid particle's id, not its place: with ids as emitters and drains
// leave them (ascending, with gaps) both solvers still bear the same white water.
TEST_F(WhiteWater, BirthsAgreeWithTheReferenceWhateverTheIds) {
  Splash s = splash();
  s.state.id.resize(s.state.x.size());
  for (size_t k = 0; k < s.state.id.size(); ++k) s.state.id[k] = uint32_t(1000 + 3 * k);
  expect_same_births(births_at(s));
}

// A frame's moves: each particle typed by the fluid around it (some of each kind), moved as
// its kind moves, stopped at the walls, aged; those whose life ends are gone in both.
TEST_F(WhiteWater, MovesAgreeWithTheReference) {
  const Splash& s = splash();
  auto reference = reference_at(s);
  ReferenceSolver& r = *reference;
  r.build_grid(r.state.x);
  r.white_water_emit(s.frame_time, 7);
  std::vector<WhiteParticle> start = r.white;
  ASSERT_GT(start.size(), 100u);
  for (size_t k = 0; k < start.size(); k += 10) start[k].life = 0.5 * s.frame_time;  // these die this frame
  for (size_t k = 1; k < start.size(); k += 10) start[k].x.y += 0.3;                 // these fly as spray

  auto gpu_solver = gpu_at(s);
  GpuSolver& g = *gpu_solver;
  g.upload_white_water(start);
  g.begin();
  g.grid_at_positions();
  g.white_water_advect(s.frame_time);
  g.finish();
  r.upload_white_water(start);
  r.build_grid(r.state.x);
  r.white_water_advect(s.frame_time);

  size_t kinds[3] = {0, 0, 0};
  for (const WhiteParticle& p : r.white) ++kinds[p.kind()];
  std::printf("[ white    ] after the move: %zu spray, %zu foam, %zu bubbles of %zu\n", kinds[0], kinds[1], kinds[2],
              start.size());
  EXPECT_GT(kinds[WHITE_SPRAY], 0u);
  EXPECT_GT(kinds[WHITE_FOAM], 0u);
  EXPECT_GT(kinds[WHITE_BUBBLE], 0u);
  EXPECT_EQ(r.white.size(), start.size() - (start.size() + 9) / 10);
  const std::vector<WhiteParticle> moved = g.white_water();
  EXPECT_EQ(moved.size(), r.white.size());
  const Agreement a = agree(moved, r.white);
  EXPECT_GE(double(a.same_kind), 0.99 * double(r.white.size()));
  EXPECT_LT(a.x, 1e-5);
  EXPECT_LT(a.v, 1e-4);
  EXPECT_LT(a.life, 1e-5);
}

// Spray thrown down at the box of dam_obstacle lands on its top, as the reference's: its fall
// stops there and its slide along the top goes on (the box slips); no particle ends inside it
// (grown by half a spacing, as for the fluid; 10 um of float's rounding).
TEST_F(WhiteWater, SprayStopsAtAnObstacleAsTheReferences) {
  const Scene scene = load_scene("dam_obstacle", {"particle_spacing=0.03"});
  const Derived d = derive(scene);
  const double frame_time = scene.solver.substeps * d.dt;
  std::vector<WhiteParticle> thrown;
  for (int i = 0; i < 10; ++i)
    for (int k = 0; k < 10; ++k)  // above the box's top (0.9-1.0 x 0.1-0.3 m, 0.3 m high), falling at 5 m/s
      thrown.push_back({glm::dvec3(0.86 + 0.018 * i, 0.36, 0.06 + 0.028 * k), glm::dvec3(0.5, -5, 0), 1.0,
                        uint32_t(i * 10 + k) << WHITE_KIND_BITS | WHITE_SPRAY});
  GpuSolver g(test::gpu(), d, initial_particles(scene));
  g.set_outputs({.white_water = true});
  g.upload_white_water(thrown);
  g.begin();
  g.grid_at_positions();
  g.white_water_advect(frame_time);
  g.finish();
  ReferenceSolver r(d, initial_particles(scene));
  r.set_outputs({.white_water = true});
  r.upload_white_water(thrown);
  r.build_grid(r.state.x);
  r.white_water_advect(frame_time);
  const std::vector<WhiteParticle> moved = g.white_water();
  ASSERT_EQ(moved.size(), thrown.size());
  size_t landed = 0, sliding = 0;
  const Obstacle inner = d.obstacles[0].grown(-1e-5);  // on its surface in float is not inside
  for (const WhiteParticle& p : moved) {
    EXPECT_FALSE(inner.contains(p.x)) << p.x.x << " " << p.x.y << " " << p.x.z;
    landed += p.v.y == 0.0;
    sliding += p.v.y == 0.0 && p.v.x == 0.5;
  }
  EXPECT_GT(landed, 20u) << "some land on the box";
  EXPECT_GT(sliding, 20u) << "and slide along its top";
  const Agreement a = agree(moved, r.white);
  EXPECT_EQ(a.same_kind, thrown.size());
  EXPECT_LT(a.x, 1e-5);
  EXPECT_LT(a.v, 1e-4);
}

// The passes read the fluid and write nothing of it: its state after them is the same, bit for
// bit, as before them.
TEST_F(WhiteWater, ThePassesLeaveTheFluidAsItWas) {
  const Splash& s = splash();
  auto gpu_solver = gpu_at(s);
  GpuSolver& g = *gpu_solver;
  g.begin();
  g.grid_at_positions();
  g.density();
  g.finish();
  const ParticleState before = g.download();
  g.begin();
  g.white_water_advect(s.frame_time);
  g.white_water_emit(s.frame_time, 3);
  g.white_water_advect(s.frame_time);
  g.white_water_emit(s.frame_time, 4);
  g.finish();
  const ParticleState after = g.download();
  EXPECT_GT(g.white_water().size(), 100u);
  EXPECT_EQ(after.x, before.x);
  EXPECT_EQ(after.v, before.v);
  EXPECT_EQ(after.x_pred, before.x_pred);
  EXPECT_EQ(after.rho, before.rho);
}

// A run's measures are the same with white water as without (the reference, whose arithmetic
// repeats bit for bit; the GPU's sums vary in their last bits from run to run).
TEST(WhiteWaterReference, TheStatsAreTheSameWithAndWithout) {
  const Scene scene = load_scene("dam_break", {"particle_spacing=0.05"});
  const Derived d = derive(scene);
  ReferenceSolver with(d, initial_particles(scene)), without(d, initial_particles(scene));
  with.set_outputs({.white_water = true});
  for (int frame = 0; frame < 24; ++frame) {
    const FrameStats a = with.advance(scene.solver.substeps), b = without.advance(scene.solver.substeps);
    ASSERT_EQ(a.mean_compression, b.mean_compression) << "frame " << frame;
    ASSERT_EQ(a.max_compression, b.max_compression) << "frame " << frame;
    ASSERT_EQ(a.kinetic_energy, b.kinetic_energy) << "frame " << frame;
    ASSERT_EQ(a.potential_energy, b.potential_energy) << "frame " << frame;
    ASSERT_EQ(a.max_speed, b.max_speed) << "frame " << frame;
  }
  EXPECT_GT(with.white.size(), 0u) << "the run should have made white water";
  EXPECT_TRUE(without.white.empty());
}

// A PLY file's vertex count and properties.
std::pair<size_t, std::string> ply_header(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, props;
  size_t count = 0;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string word, type, name;
    words >> word;
    if (word == "element") words >> type >> count;
    if (word == "property") words >> type >> name, props += (props.empty() ? "" : " ") + name;
  }
  return {count, props};
}

std::vector<size_t> white_counts(const fs::path& dir, int frames) {
  std::vector<size_t> counts;
  for (int f = 0; f < frames; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.ply", f);
    const auto [count, props] = ply_header(dir / "white_water" / name);
    EXPECT_EQ(props, "x y z vx vy vz life kind") << name;
    counts.push_back(count);
  }
  return counts;
}

// A white water file holds each particle as written: position, velocity, life and kind (PLY's
// records; the VTK file's arrays by name).
TEST(WhiteWaterExport, FilesHoldEachParticlesPositionVelocityLifeAndKind) {
  const fs::path dir = test::fresh_dir("white_export");
  fs::create_directories(dir);
  ParticleFrame f;
  const std::vector<WhiteParticle> written = {{{0.1, 0.2, 0.3}, {1, -2, 3}, 0.75, 7u << WHITE_KIND_BITS | WHITE_SPRAY},
                                              {{0.4, 0.5, 0.6}, {0, 0, 0}, 1.5, 9u << WHITE_KIND_BITS | WHITE_BUBBLE}};
  add_white_water(f, written);
  capture::write_white_water(dir / "w.ply", capture::ExportFormat::Ply, f);
  capture::write_white_water(dir / "w.vtp", capture::ExportFormat::Vtk, f);
  const auto [count, props] = ply_header(dir / "w.ply");
  EXPECT_EQ(count, written.size());
  EXPECT_EQ(props, "x y z vx vy vz life kind");
  std::ifstream in(dir / "w.ply", std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t body = data.find("end_header\n") + std::strlen("end_header\n");
  ASSERT_EQ(data.size() - body, written.size() * 8 * sizeof(float));
  for (size_t k = 0; k < written.size(); ++k) {
    float r[8];
    std::memcpy(r, data.data() + body + k * sizeof r, sizeof r);
    const WhiteParticle& w = written[k];
    EXPECT_EQ(glm::dvec3(r[0], r[1], r[2]), glm::dvec3(glm::vec3(w.x)));
    EXPECT_EQ(glm::dvec3(r[3], r[4], r[5]), glm::dvec3(glm::vec3(w.v)));
    EXPECT_EQ(r[6], float(w.life));
    EXPECT_EQ(r[7], float(w.kind()));
  }
  std::ifstream vtp_in(dir / "w.vtp", std::ios::binary);
  const std::string vtp((std::istreambuf_iterator<char>(vtp_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(vtp.find("NumberOfPoints=\"2\""), std::string::npos);
  for (const char* name : {"velocity", "life", "kind"})
    EXPECT_NE(vtp.find(std::string("Name=\"") + name + "\""), std::string::npos) << name;
}

// `--export` writes a white water file per frame: none in a tank at rest, some in the dam break.
TEST(WhiteWaterCli, AStillTankMakesNoneAndTheDamBreakSome) {
  const fs::path still = test::fresh_dir("white_still"), dam = test::fresh_dir("white_dam");
  auto run = test::run_pbflow("run hydrostatic --param particle_spacing=0.04 --frames 31 --no-render --export ply --quiet --out " + still.string());
  ASSERT_EQ(run.status, 0) << run.output;
  for (size_t count : white_counts(still, 31)) EXPECT_EQ(count, 0u);
  run = test::run_pbflow("run dam_break --param particle_spacing=0.04 --frames 31 --no-render --export ply --quiet --out " +
                         dam.string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_GT(white_counts(dam, 31).back(), 0u);
  run = test::run_pbflow(
      "run dam_break --param particle_spacing=0.04 --param white_water.enabled=false --frames 3 --no-render --export ply "
      "--quiet --out " + dam.string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_FALSE(fs::exists(dam / "white_water")) << "turned off, none is written (and the last run's are gone)";
}

// At the cap, births stop until some die: never more alive than it, and it is reached.
TEST(WhiteWaterCli, NoMoreThanTheCapLive) {
  const fs::path dir = test::fresh_dir("white_cap");
  auto run = test::run_pbflow(
      "run dam_break --param particle_spacing=0.04 --param white_water.emission=300 --param "
      "white_water.max_particles=50 --frames 31 --no-render --export ply --quiet --out " + dir.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const std::vector<size_t> counts = white_counts(dir, 31);
  EXPECT_EQ(*std::max_element(counts.begin(), counts.end()), 50u);
}

// The share of a frame that reads as white water: nearly white, nearly grey-free (the sky's
// palest channel is 204).
double white_share(const capture::Image& image) {
  size_t white = 0;
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    const int lo = std::min({image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]});
    const int hi = std::max({image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]});
    white += lo >= 225 && hi - lo <= 30;
  }
  return double(white) / double(image.rgb.size() / 3);
}

// The dam break foams at its front and at the far wall: at 1 s at least 0.5 % of a 640x360 frame
// reads as white water; without it, almost none does.
TEST(WhiteWaterSlow, TheDamBreakFoamsAtOneSecond) {
  auto share = [](const std::string& enabled) {
    const fs::path dir = test::fresh_dir("white_dam_" + enabled);
    auto run = test::run_pbflow("run dam_break --frames 61 --width 640 --height 360 --quiet --param white_water.enabled=" +
                                enabled + " --out " + dir.string());
    EXPECT_EQ(run.status, 0) << run.output;
    return white_share(capture::read_png(dir / "frames" / "frame_00060.png"));
  };
  const double with = share("true"), without = share("false");
  std::printf("[ white    ] dam break at 1 s, 640x360: %.3f %% white with white water, %.3f %% without\n", 100 * with,
              100 * without);
  EXPECT_GE(with, 0.005);
  EXPECT_LE(without, 0.001);
}

}  // namespace
}  // namespace pbflow
