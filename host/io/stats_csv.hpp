#pragma once
// DIR/stats.csv as docs/design.md defines it: one complete, flushed row per frame.
#include <filesystem>

#include "io/csv_file.hpp"
#include "sim/solver.hpp"

namespace pbflow {

class StatsCsv {
 public:
  explicit StatsCsv(const std::filesystem::path& path);
  // Throws std::runtime_error naming the file and the cause when the row cannot be written.
  void write(int frame, double time, const FrameStats& s);

 private:
  CsvFile file_;
};

// DIR/solids.csv, where the scene's solids move: per frame a row for the tank and one for each
// obstacle (scene order), its pose in the world as a position and a unit quaternion
// (w, x, y, z), so that a renderer elsewhere can place them beside the exported particles.
class SolidsCsv {
 public:
  explicit SolidsCsv(const std::filesystem::path& path);
  void write(int frame, double time, const Pose& tank, const std::vector<Pose>& obstacles);

 private:
  void row(int frame, double time, const std::string& solid, const Pose& pose);
  CsvFile file_;
};

// DIR/bodies.csv, where the scene has rigid bodies: per frame a row for each (scene order), its
// centre of mass and turn in the world (a unit quaternion w, x, y, z), its velocity (m/s) and
// angular velocity (rad/s).
class BodiesCsv {
 public:
  explicit BodiesCsv(const std::filesystem::path& path);
  void write(int frame, double time, const std::vector<Body>& bodies, const std::vector<Pose>& obstacles);

 private:
  CsvFile file_;
};

}  // namespace pbflow
