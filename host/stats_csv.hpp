#pragma once
// DIR/stats.csv as DESIGN.md defines it: one complete, flushed row per frame.
#include <cstdio>
#include <filesystem>

#include "solver.hpp"

namespace pbflow {

class StatsCsv {
 public:
  explicit StatsCsv(const std::filesystem::path& path);
  ~StatsCsv();
  StatsCsv(const StatsCsv&) = delete;
  StatsCsv& operator=(const StatsCsv&) = delete;
  void write(int frame, double time, const FrameStats& s);

 private:
  std::FILE* file_;
};

}  // namespace pbflow
