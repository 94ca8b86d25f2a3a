#include "scene/framing.hpp"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace pbflow {

namespace {
constexpr double kAspect = 16.0 / 9.0;
constexpr double kElevation = glm::radians(30.0);
constexpr double kMargin = 0.95;  // the corners stay this far inside the image's edges

// The poses the scene's motion takes the tank through: at its keys, or 16 along a period or turn.
std::vector<Pose> tank_poses(const Motion& m) {
  std::vector<double> times{0.0};
  if (m.type == Motion::Type::Keyframes)
    for (const Motion::Key& k : m.keys) times.push_back(k.t);
  const double span = m.type == Motion::Type::Oscillate ? m.period : m.type == Motion::Type::Rotate ? 360 / std::abs(m.rate) : 0;
  for (int k = 1; span > 0 && k < 16; ++k) times.push_back(span * k / 16);
  std::vector<Pose> poses;
  for (double t : times) poses.push_back(m.at(t));
  return poses;
}

// The poses turned by +-degrees about x and about z through `pivot`, and as they are.
std::vector<Pose> tilted(const std::vector<Pose>& poses, double degrees, const glm::dvec3& pivot) {
  std::vector<Pose> all = poses;
  for (const glm::dvec3 axis : {glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1)})
    for (const double sign : {-1.0, 1.0}) {
      const Pose turn = turn_about(glm::angleAxis(sign * glm::radians(degrees), axis), pivot);
      for (const Pose& p : poses) all.push_back(compose(turn, p));
    }
  return all;
}
}  // namespace

Camera framing_camera(const Scene& scene, double tilt_degrees) {
  const Box box{scene.domain.min, scene.domain.max};
  Camera c = scene.camera;
  c.target = 0.5 * (box.min + box.max);
  const glm::dvec3 towards_eye(0, std::sin(kElevation), std::cos(kElevation));
  const glm::dvec3 right(1, 0, 0), up = glm::cross(right, -towards_eye);
  const double tan_v = kMargin * std::tan(glm::radians(scene.camera.fov_degrees) / 2), tan_h = kAspect * tan_v;
  // A corner at offset o from the target lies at depth d - o.towards_eye; it fits where
  // |o.right| <= depth tan_h and |o.up| <= depth tan_v.
  double distance = 0;
  std::vector<Pose> poses = tank_poses(scene.tank_motion);
  if (tilt_degrees > 0) poses = tilted(poses, tilt_degrees, scene.domain.floor_centre());
  for (const Pose& pose : poses)
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 o = pose.world(box.corner(k)) - c.target;
      const double along = glm::dot(o, towards_eye);
      distance = std::max({distance, std::abs(glm::dot(o, right)) / tan_h + along, std::abs(glm::dot(o, up)) / tan_v + along});
    }
  c.eye = c.target + distance * towards_eye;
  return c;
}

}  // namespace pbflow
