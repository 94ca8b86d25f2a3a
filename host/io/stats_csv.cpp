#include "io/stats_csv.hpp"

#include <glm/gtc/quaternion.hpp>

#include <string>

namespace pbflow {

namespace {
// A turn as the unit quaternion with w >= 0 (of the two that turn alike).
glm::dquat unit_turn(const glm::dmat3& rotation) {
  const glm::dquat q = glm::normalize(glm::quat_cast(rotation));
  return q.w < 0 ? -q : q;
}
}  // namespace

StatsCsv::StatsCsv(const std::filesystem::path& path)
    : file_(path,
            "frame,time,mean_compression,max_compression,kinetic_energy,potential_energy,solid_work,max_speed,"
            "iterations,particles,emitted,drained,flow_energy,body_energy,step_ms\n") {}

void StatsCsv::write(int frame, double time, const FrameStats& s) {
  char row[512];
  std::snprintf(row, sizeof row, "%d,%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.4g,%u,%u,%u,%.9g,%.9g,%.6f\n", frame, time,
                s.mean_compression, s.max_compression, s.kinetic_energy, s.potential_energy, s.solid_work, s.max_speed,
                s.iterations, s.count, s.emitted, s.drained, s.flow_energy, s.body_energy, s.step_ms);
  file_.append(row);
}

SolidsCsv::SolidsCsv(const std::filesystem::path& path) : file_(path, "frame,time,solid,x,y,z,qw,qx,qy,qz\n") {}

void SolidsCsv::write(int frame, double time, const Pose& tank, const std::vector<Pose>& obstacles) {
  row(frame, time, "tank", tank);
  for (size_t k = 0; k < obstacles.size(); ++k) row(frame, time, std::to_string(k), compose(tank, obstacles[k]));
}

void SolidsCsv::row(int frame, double time, const std::string& solid, const Pose& pose) {
  const glm::dquat q = unit_turn(pose.rotation);
  char text[512];
  std::snprintf(text, sizeof text, "%d,%.6f,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", frame, time, solid.c_str(),
                pose.translation.x, pose.translation.y, pose.translation.z, q.w, q.x, q.y, q.z);
  file_.append(text);
}

BodiesCsv::BodiesCsv(const std::filesystem::path& path)
    : file_(path, "frame,time,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n") {}

void BodiesCsv::write(int frame, double time, const std::vector<Body>& bodies, const std::vector<Pose>& obstacles) {
  for (size_t k = 0; k < bodies.size(); ++k) {
    const Body& b = bodies[k];
    const Pose& pose = obstacles[b.obstacle];
    const glm::dquat q = unit_turn(pose.rotation);
    const glm::dvec3 c = b.world_centre(pose), v = b.velocity, w = b.angular_velocity;
    char text[512];
    std::snprintf(text, sizeof text, "%d,%.6f,%zu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", frame,
                  time, k, c.x, c.y, c.z, q.w, q.x, q.y, q.z, v.x, v.y, v.z, w.x, w.y, w.z);
    file_.append(text);
  }
}

}  // namespace pbflow
