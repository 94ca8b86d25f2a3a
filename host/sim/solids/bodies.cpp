#include "sim/solids/bodies.hpp"

#include <btBulletDynamicsCommon.h>
#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <numbers>

namespace pbflow {

namespace {
btVector3 bt(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
glm::dvec3 from_bt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// Where Bullet's frame of a solid lies in its body frame: a body's at its centre of mass on its
// principal axes, another solid's at its middle.
struct Frame {
  glm::dvec3 origin{0.0};
  glm::dmat3 axes{1.0};
};
Frame frame_of(const Body& b) { return {b.centre, b.axes}; }
Frame frame_of(const Obstacle& o) { return {o.middle(), glm::dmat3(1.0)}; }

btTransform transform(const Pose& p, const Frame& f) {
  const glm::dmat3 r = p.rotation * f.axes;  // glm is column-major: r[column][row]
  btMatrix3x3 basis(r[0][0], r[1][0], r[2][0], r[0][1], r[1][1], r[2][1], r[0][2], r[1][2], r[2][2]);
  return btTransform(basis, bt(p.world(f.origin)));
}

Pose pose_of(const btTransform& t, const Frame& f) {
  const btMatrix3x3& b = t.getBasis();
  glm::dmat3 r;
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column) r[column][row] = b[row][column];
  Pose p;
  p.rotation = r * glm::transpose(f.axes);
  p.translation = from_bt(t.getOrigin()) - p.rotation * f.origin;
  return p;
}

// A solid's shape for Bullet in its frame f: a mesh body as its convex hull, a standing mesh as its
// triangles, grown by its margin (its triangles are its own surface).
std::unique_ptr<btCollisionShape> shape_of(const Obstacle& o, const Frame& f, std::unique_ptr<btTriangleMesh>& triangles) {
  if (o.kind == Obstacle::Kind::Sphere) return std::make_unique<btSphereShape>(o.radius);
  if (o.kind == Obstacle::Kind::Box) return std::make_unique<btBoxShape>(bt(0.5 * (o.max - o.min)));
  auto local = [&](const glm::vec3& c) { return bt(glm::transpose(f.axes) * (glm::dvec3(c) - f.origin)); };
  const std::vector<glm::vec3>& c = *o.corners;
  if (o.body >= 0) {
    auto hull = std::make_unique<btConvexHullShape>();
    for (const glm::vec3& corner : c) hull->addPoint(local(corner), false);
    hull->recalcLocalAabb();
    hull->setMargin(o.margin);
    return hull;
  }
  triangles = std::make_unique<btTriangleMesh>();
  for (size_t k = 0; k + 2 < c.size(); k += 3) triangles->addTriangle(local(c[k]), local(c[k + 1]), local(c[k + 2]));
  auto mesh = std::make_unique<btBvhTriangleMeshShape>(triangles.get(), true);
  mesh->setMargin(o.margin);
  return mesh;
}
}  // namespace

double Body::energy(const Pose& p, const glm::dvec3& g, const glm::dvec3& floor) const {
  return 0.5 * mass * glm::dot(velocity, velocity) + 0.5 * glm::dot(angular_velocity, spin_momentum(p, angular_velocity)) -
         mass * glm::dot(g, world_centre(p) - floor);
}

namespace {
// Cell centres of a lattice half a spacing fine over the shape's box, those inside it kept (in
// its body frame: the shape as the scene places it, unturned).
std::vector<glm::dvec3> volume_samples(const Obstacle& shape, double spacing, double& cell_volume) {
  Obstacle own = shape;
  own.pose = own.previous = Pose{};
  const glm::dvec3 size = own.high() - own.low();
  const glm::ivec3 n = glm::max(glm::ivec3(glm::ceil(size / (0.5 * spacing))), glm::ivec3(2));
  cell_volume = size.x * size.y * size.z / (double(n.x) * n.y * n.z);
  std::vector<glm::dvec3> samples;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const glm::dvec3 p = own.low() + (glm::dvec3(x, y, z) + 0.5) / glm::dvec3(n) * size;
        glm::dvec3 normal;
        if (own.surface(p, normal) < 0) samples.push_back(p);
      }
  return samples;
}

// A mesh's centre, principal axes and moments from its samples, each a small cube of its share of
// the mass (Bullet's Jacobi diagonalisation).
void mesh_mass_properties(Body& b, double cell_volume) {
  const double each = b.mass / double(b.samples.size()), side2 = std::cbrt(cell_volume) * std::cbrt(cell_volume);
  b.centre = glm::dvec3(0.0);
  for (const glm::dvec3& p : b.samples) b.centre += p / double(b.samples.size());
  btMatrix3x3 tensor(0, 0, 0, 0, 0, 0, 0, 0, 0);
  for (const glm::dvec3& p : b.samples) {
    const glm::dvec3 r = p - b.centre;
    const double rr = glm::dot(r, r) + side2 / 6.0;  // the cube's own: m s^2 / 6 on each axis
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) tensor[i][j] += each * ((i == j ? rr : 0.0) - r[i] * r[j]);
  }
  btMatrix3x3 rotation;
  rotation.setIdentity();
  tensor.diagonalize(rotation, 1e-12, 32);  // tensor = rotation diag rotation^T
  for (int i = 0; i < 3; ++i) {
    b.inertia[i] = tensor[i][i];
    for (int j = 0; j < 3; ++j) b.axes[i][j] = rotation[j][i];  // column i: principal axis i
  }
  if (glm::determinant(b.axes) < 0) b.axes[2] = -b.axes[2];  // a rotation, not a reflection
}
}  // namespace

Body make_body(const Obstacle& shape, double density, double mass, double spacing) {
  Body b;
  double cell_volume = 0;
  b.samples = volume_samples(shape, spacing, cell_volume);
  const glm::dvec3 size = shape.high() - shape.low();
  const double volume = shape.kind == Obstacle::Kind::Sphere ? 4.0 / 3.0 * std::numbers::pi * std::pow(shape.radius, 3)
                        : shape.kind == Obstacle::Kind::Box  ? size.x * size.y * size.z
                                                             : cell_volume * double(b.samples.size());
  b.mass = mass > 0 ? mass : density * volume;
  b.sample_volume = b.samples.empty() ? 0.0 : volume / double(b.samples.size());
  b.centre = shape.middle();
  if (shape.kind == Obstacle::Kind::Sphere)
    b.inertia = glm::dvec3(0.4 * b.mass * shape.radius * shape.radius);
  else if (shape.kind == Obstacle::Kind::Box)
    b.inertia = b.mass / 12.0 * glm::dvec3(size.y * size.y + size.z * size.z, size.x * size.x + size.z * size.z,
                                           size.x * size.x + size.y * size.y);
  else if (!b.samples.empty())
    mesh_mass_properties(b, cell_volume);
  return b;
}

void Body::kick(const Pose& p, const BodyPush& push) {
  velocity += push.impulse / mass;
  angular_velocity += turn(p, push.moment);
}

Pose give_way(const Body& b, const Pose& pose, const BodyPush& push) {
  const glm::dvec3 centre = b.world_centre(pose) + push.impulse / b.mass, turn = b.turn(pose, push.moment);
  Pose p = pose;
  if (const double angle = glm::length(turn); angle > 0)
    p.rotation = glm::mat3_cast(glm::angleAxis(angle, turn / angle)) * pose.rotation;
  p.translation = centre - p.rotation * b.centre;
  return p;
}

void finish_bodies(std::vector<Body>& bodies, const std::vector<Obstacle>& obstacles, double dt) {
  for (Body& b : bodies) {
    const Obstacle& o = obstacles[b.obstacle];
    const glm::dquat turned = glm::quat_cast(o.pose.rotation * glm::transpose(o.previous.rotation));
    const double angle = glm::angle(turned);  // in [0, 2 pi): past pi, the other way round
    const glm::dvec3 axis = angle > 1e-12 ? glm::axis(turned) : glm::dvec3(0.0);
    b.velocity = (b.world_centre(o.pose) - b.world_centre(o.previous)) / dt;
    b.angular_velocity = (angle > std::numbers::pi ? angle - 2 * std::numbers::pi : angle) * axis / dt;
  }
}

struct BodyWorld::World {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  std::vector<std::unique_ptr<btTriangleMesh>> triangles;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btCollisionObject>> solids;  // the walls, then each obstacle not a body
  std::vector<std::unique_ptr<btRigidBody>> bodies;        // in Body order, each its index as user index

  // A standing solid of `shape` (kept here) at `at`.
  void add_solid(std::unique_ptr<btCollisionShape> shape, const btTransform& at) {
    shapes.push_back(std::move(shape));
    solids.push_back(std::make_unique<btCollisionObject>());
    solids.back()->setCollisionShape(shapes.back().get());
    solids.back()->setWorldTransform(at);
    solids.back()->setUserIndex(-1);  // not a body (BodyWorld::separate)
    world.addCollisionObject(solids.back().get());
  }
  ~World() {
    for (auto& b : bodies) world.removeRigidBody(b.get());
    for (auto& s : solids) world.removeCollisionObject(s.get());
  }
};

BodyWorld::BodyWorld(const std::vector<Body>& bodies, const std::vector<Obstacle>& obstacles, const glm::dvec3& wall_min,
                     const glm::dvec3& wall_max, const glm::dvec3& gravity)
    : world_(std::make_unique<World>()) {
  World& w = *world_;
  w.world.setGravity(bt(gravity));
  // Bullet parts overlapping bodies by moving them, not by a velocity to part them: a ball resting
  // on a box rolled off it and the water gained 22 % with the velocity.
  w.world.getSolverInfo().m_splitImpulse = 1;
  w.world.getSolverInfo().m_splitImpulsePenetrationThreshold = 0;
  for (int axis = 0; axis < 3; ++axis)  // the box's walls, facing in
    for (int side = 0; side < 2; ++side) {
      glm::dvec3 normal(0.0);
      normal[axis] = side ? -1.0 : 1.0;
      const double offset = side ? -wall_max[axis] : wall_min[axis];
      w.add_solid(std::make_unique<btStaticPlaneShape>(bt(normal), offset), btTransform::getIdentity());
    }
  for (const Obstacle& o : obstacles) {
    if (o.body >= 0) continue;
    w.triangles.emplace_back();
    w.add_solid(shape_of(o, frame_of(o), w.triangles.back()), transform(o.pose, frame_of(o)));
  }
  for (const Body& b : bodies) {
    const Obstacle& o = obstacles[b.obstacle];
    std::unique_ptr<btTriangleMesh> unused;
    w.shapes.push_back(shape_of(o, frame_of(b), unused));
    btRigidBody::btRigidBodyConstructionInfo info(b.mass, nullptr, w.shapes.back().get(), bt(b.inertia));
    w.bodies.push_back(std::make_unique<btRigidBody>(info));
    w.bodies.back()->setUserIndex(int(w.bodies.size() - 1));
    w.bodies.back()->setActivationState(DISABLE_DEACTIVATION);
    w.world.addRigidBody(w.bodies.back().get());
  }
}

BodyWorld::~BodyWorld() = default;

void BodyWorld::predict(const std::vector<Body>& bodies, std::vector<Obstacle>& obstacles, double dt) {
  World& w = *world_;
  size_t solid = 6;  // after the walls
  for (const Obstacle& o : obstacles)
    if (o.body < 0) w.solids[solid++]->setWorldTransform(transform(o.pose, frame_of(o)));
  for (size_t k = 0; k < bodies.size(); ++k) {
    btRigidBody& rb = *w.bodies[k];
    rb.setWorldTransform(transform(obstacles[bodies[k].obstacle].pose, frame_of(bodies[k])));
    rb.setLinearVelocity(bt(bodies[k].velocity));
    rb.setAngularVelocity(bt(bodies[k].angular_velocity));
  }
  w.world.stepSimulation(dt, 0);
  for (size_t k = 0; k < bodies.size(); ++k)
    obstacles[bodies[k].obstacle].move_to(pose_of(w.bodies[k]->getWorldTransform(), frame_of(bodies[k])));
}

std::vector<BodyWorld::Parting> BodyWorld::separate(const std::vector<Body>& bodies, std::vector<Obstacle>& obstacles) {
  World& w = *world_;
  for (size_t k = 0; k < bodies.size(); ++k)
    w.bodies[k]->setWorldTransform(transform(obstacles[bodies[k].obstacle].pose, frame_of(bodies[k])));
  w.world.performDiscreteCollisionDetection();
  std::vector<glm::dvec3> shift(bodies.size(), glm::dvec3(0.0));
  std::vector<Parting> parted;
  btDispatcher& dispatcher = *w.world.getDispatcher();
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold& contact = *dispatcher.getManifoldByIndexInternal(m);
    const int a = contact.getBody0()->getUserIndex(), b = contact.getBody1()->getUserIndex();  // -1: standing
    auto inverse_mass = [&](int k) {  // a standing solid's and a held body's: none
      return k >= 0 && obstacles[bodies[size_t(k)].obstacle].dynamic() ? 1.0 / bodies[size_t(k)].mass : 0.0;
    };
    const double inv_a = inverse_mass(a), inv_b = inverse_mass(b);
    glm::dvec3 deepest(0.0);  // B's normal times the overlap: A moves along it, B against it
    for (int p = 0; p < contact.getNumContacts(); ++p) {
      const btManifoldPoint& point = contact.getContactPoint(p);
      if (point.getDistance() < -glm::length(deepest)) deepest = -point.getDistance() * from_bt(point.m_normalWorldOnB);
    }
    if (inv_a + inv_b <= 0 || deepest == glm::dvec3(0.0)) continue;
    const Parting p{a, b, deepest, inv_a / (inv_a + inv_b), inv_b / (inv_a + inv_b)};
    if (a >= 0) shift[size_t(a)] += p.share_a * deepest;
    if (b >= 0) shift[size_t(b)] -= p.share_b * deepest;
    parted.push_back(p);
  }
  for (size_t k = 0; k < bodies.size(); ++k) obstacles[bodies[k].obstacle].pose.translation += shift[k];
  return parted;
}

}  // namespace pbflow
