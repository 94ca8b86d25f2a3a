#pragma once
// DIR/stats.csv as docs/design.md defines it: one complete, flushed row per frame.
#include <cstdio>
#include <filesystem>

#include "sim/solver.hpp"

namespace pbflow {

class StatsCsv {
 public:
  explicit StatsCsv(const std::filesystem::path& path);
  ~StatsCsv();
  StatsCsv(const StatsCsv&) = delete;
  StatsCsv& operator=(const StatsCsv&) = delete;
  // Throws std::runtime_error naming the file and the cause when the row cannot be written.
  void write(int frame, double time, const FrameStats& s);

 private:
  void append(const char* text);

  std::filesystem::path path_;
  std::FILE* file_;
};

}  // namespace pbflow
