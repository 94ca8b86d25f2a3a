// Scenes: every built-in one runs, fluid shapes fill what they should, obstacles keep
// the fluid out even when it is thrown at them.
#include <cmath>

#include "app/live_run.hpp"
#include "gpu/gpu_solver.hpp"
#include "gpu/make_solver.hpp"
#include "scene/framing.hpp"
#include "sim/solids/obstacles.hpp"
#include "sim/reference_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

bool finite(const glm::dvec3& x) { return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z); }

class SceneTest : public test::GpuTest {};

// Each scene at twice its spacing (an eighth of its particles), 10 frames on the GPU.
TEST_F(SceneTest, EveryBuiltinSceneRunsAFewFramesInsideItsDomain) {
  ASSERT_GE(builtin_scenes().size(), 5u);
  for (const BuiltinScene& b : builtin_scenes()) {
    Scene full = load_scene(b.name);
    Scene scene = load_scene(b.name, {"particle_spacing=" + std::to_string(2 * full.particle_spacing)});
    auto x0 = initial_particles(scene);
    double ratio = double(initial_particles(full).size()) / double(x0.size());
    // A curved tank (the domain's mesh) loses a half-spacing shell of its fluid to the keep-out at
    // either spacing, a larger share at the coarse one: the mixer's bowl keeps 1/9.8.
    const bool curved = std::any_of(full.obstacles.begin(), full.obstacles.end(), [](const Obstacle& o) { return o.container; });
    EXPECT_NEAR(ratio, curved ? 9.0 : 8.0, 1.6) << b.name << ": doubling the spacing should leave about an eighth";
    // Bodies run on the reference (the GPU solver refuses them).
    const std::unique_ptr<Solver> solver = make_solver(scene.bodies.empty() ? &test::gpu() : nullptr, derive(scene), x0);
    FrameStats s;
    for (int frame = 0; frame < 10; ++frame) s = solver->advance(scene.solver.substeps);
    EXPECT_TRUE(std::isfinite(s.kinetic_energy)) << b.name;
    ParticleState state = solver->download();
    ASSERT_EQ(state.x.size(), s.count);
    if (scene.emitters.empty() && scene.drains.empty()) {
      ASSERT_EQ(state.x.size(), x0.size()) << b.name;
    }
    for (const glm::dvec3& x : state.x) {
      ASSERT_TRUE(finite(x)) << b.name;
      ASSERT_TRUE(glm::all(glm::greaterThanEqual(x, scene.domain.min)) &&
                  glm::all(glm::lessThanEqual(x, scene.domain.max)))
          << b.name << ": a particle left the domain";
    }
  }
}

TEST(SceneShapes, FluidSphereHoldsItsVolumeAndObstaclesHoldNoParticle) {
  Scene scene = load_scene("drop", {"fluid_blocks=[]"});
  const Ball& ball = scene.fluid_spheres.at(0);
  double expected = 4.0 / 3.0 * M_PI * std::pow(ball.radius / scene.particle_spacing, 3);
  EXPECT_NEAR(double(initial_particles(scene).size()), expected, 0.03 * expected);

  Scene blocked = load_scene("dam_break", {R"(obstacles=[{"type": "sphere", "centre": [0.2, 0.4, 0.2], "radius": 0.1},
                                                         {"type": "box", "min": [0, 0, 0], "max": [0.1, 0.1, 0.4]}])"});
  Derived d = derive(blocked);
  size_t full = initial_particles(load_scene("dam_break")).size();
  auto x0 = initial_particles(blocked);
  EXPECT_LT(x0.size(), full);
  for (const glm::dvec3& x : x0)
    for (const Obstacle& o : d.obstacles) ASSERT_FALSE(o.contains(x)) << "a particle was created inside an obstacle";
}

TEST(SceneShapes, ProjectionLeavesAnObstacleByItsNearestFreeSide) {
  glm::dvec3 wall_min(0.0), wall_max(1.0);
  Obstacle box;
  box.min = glm::dvec3(0.2, -0.01, 0.2);  // a slab on the floor (grown past it)
  box.max = glm::dvec3(0.8, 0.05, 0.8);
  // Nearest face is the bottom, but it lies outside the walls: the particle goes up.
  glm::dvec3 p = project_out(box, glm::dvec3(0.5, 0.003, 0.5), wall_min, wall_max);
  EXPECT_FALSE(box.contains(p));
  EXPECT_EQ(p, glm::dvec3(0.5, 0.05, 0.5));
  EXPECT_EQ(project_out(box, glm::dvec3(0.21, 0.03, 0.5), wall_min, wall_max), glm::dvec3(0.2, 0.03, 0.5));
  Obstacle ball;
  ball.kind = Obstacle::Kind::Sphere;
  ball.centre = glm::dvec3(0.5);
  ball.radius = 0.1;
  glm::dvec3 q = project_out(ball, glm::dvec3(0.5, 0.55, 0.5), wall_min, wall_max);
  EXPECT_NEAR(q.y, 0.6, 1e-12);
  EXPECT_EQ(project_out(ball, glm::dvec3(0.8), wall_min, wall_max), glm::dvec3(0.8));  // outside: untouched
}

// The dam break thrown at a box and a sphere for 1.5 s: no particle centre ends inside
// either obstacle or outside the domain.
TEST_F(SceneTest, ThrownFluidStaysOutOfObstacles) {
  Scene scene = load_scene("dam_obstacle", {"particle_spacing=0.04", R"(obstacles=[
      {"type": "box", "min": [0.9, 0, 0.1], "max": [1.0, 0.3, 0.3]},
      {"type": "sphere", "centre": [0.6, 0.1, 0.2], "radius": 0.08}])"});
  auto x0 = initial_particles(scene);
  GpuSolver solver(test::gpu(), derive(scene), x0);
  double fastest = 0;
  for (int frame = 0; frame < 90; ++frame) fastest = std::max(fastest, solver.advance(scene.solver.substeps).max_speed);
  EXPECT_GT(fastest, 2.0) << "the fluid never moved fast: the test throws nothing";
  size_t inside = 0, outside_domain = 0;
  for (const glm::dvec3& x : solver.download().x) {
    for (const Obstacle& o : scene.obstacles) inside += o.contains(x);
    outside_domain += !(glm::all(glm::greaterThanEqual(x, scene.domain.min)) &&
                        glm::all(glm::lessThanEqual(x, scene.domain.max)));
  }
  EXPECT_EQ(inside, 0u) << "particles inside an obstacle";
  EXPECT_EQ(outside_domain, 0u) << "particles outside the domain";
}

// A particle shot at 30 m/s (25 cm per step) at a plate 1 cm thick: it must stop on the
// near side, on the GPU as in the reference, instead of tunnelling through.
TEST_F(SceneTest, FastParticlesDoNotTunnelThroughAThinPlate) {
  Scene scene = load_scene("hydrostatic", {"particle_spacing=0.05", "gravity=[0, 0, 0]", "solver.method=\"pbf\"",
                                           R"(obstacles=[{"type": "box", "min": [0.45, 0, 0], "max": [0.46, 0.6, 0.6]},
                                                         {"type": "sphere", "centre": [0.3, 0.5, 0.45], "radius": 0.03}])"});
  Derived d = derive(scene);
  std::vector<glm::dvec3> x0 = {{0.3, 0.3, 0.3}, {0.3, 0.5, 0.2}};
  ParticleState st;
  st.x = st.x_pred = x0;
  st.v = {{30, 0, 0}, {0, 0, 30}};  // one towards the plate, one towards the ball
  GpuSolver gpu(test::gpu(), d, x0);
  gpu.upload(st);
  ReferenceSolver ref(d, x0);
  ref.state = st;
  gpu.advance(1);
  ref.advance(1);
  ParticleState g = gpu.download();
  for (const auto* x : {&g.x, &ref.state.x}) {
    EXPECT_LT((*x)[0].x, 0.45) << "tunnelled through the plate: x = " << (*x)[0].x;
    EXPECT_LT((*x)[1].z, 0.42) << "tunnelled through the ball: z = " << (*x)[1].z;
  }
  test::compare(g.x, ref.state.x, "positions after a step into obstacles");
  EXPECT_NEAR(g.x[0].x, ref.state.x[0].x, 1e-5);
  EXPECT_NEAR(g.x[1].z, ref.state.x[1].z, 1e-5);
}

// A view left to framing keeps the tank's corners in the picture at every tilt a viewer of
// pbflow serve may ask; the view framed for the upright tank loses one of some built-in tank.
TEST(Framing, AViewLeftToFramingHoldsTheTankAtEveryLiveTilt) {
  auto in_view = [](const Scene& s, const Camera& c, const Pose& pose) {
    const glm::dvec3 back = glm::normalize(c.eye - c.target), right = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), back));
    const glm::dvec3 up = glm::cross(back, right);
    const double tan_v = std::tan(glm::radians(c.fov_degrees) / 2), tan_h = 16.0 / 9.0 * tan_v;  // 1280x720
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 o = pose.world(Box{s.domain.min, s.domain.max}.corner(k)) - c.eye;
      const double depth = -glm::dot(o, back);
      if (std::abs(glm::dot(o, right)) > depth * tan_h || std::abs(glm::dot(o, up)) > depth * tan_v) return false;
    }
    return true;
  };
  bool upright_view_loses_one = false;
  for (const BuiltinScene& b : builtin_scenes()) {
    const Scene scene = load_scene(b.name);
    if (!scene.camera_framed) continue;
    const Camera live = framing_camera(scene, kMaxTiltDegrees);
    for (const glm::dvec3 axis : {glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1)})
      for (double degrees = -kMaxTiltDegrees; degrees <= kMaxTiltDegrees; degrees += 5) {
        const Pose tilt = turn_about(glm::angleAxis(glm::radians(degrees), axis), scene.domain.floor_centre());
        EXPECT_TRUE(in_view(scene, live, tilt)) << b.name << " tilted " << degrees << " degrees";
        upright_view_loses_one |= !in_view(scene, scene.camera, tilt);
      }
  }
  EXPECT_TRUE(upright_view_loses_one) << "no tilt takes a corner out of the upright view: this test shows nothing";
}

}  // namespace
}  // namespace pbflow
