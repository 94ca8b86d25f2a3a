#include "stats_csv.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace pbflow {

StatsCsv::StatsCsv(const std::filesystem::path& path) : file_(std::fopen(path.c_str(), "w")) {
  if (!file_) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  std::fputs("frame,time,mean_compression,max_compression,kinetic_energy,potential_energy,max_speed,iterations,step_ms\n", file_);
  std::fflush(file_);
}

StatsCsv::~StatsCsv() { std::fclose(file_); }

void StatsCsv::write(int frame, double time, const FrameStats& s) {
  // One fprintf per row and a flush: a run stopped at any point leaves whole rows.
  std::fprintf(file_, "%d,%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.4g,%.6f\n", frame, time, s.mean_compression,
               s.max_compression, s.kinetic_energy, s.potential_energy, s.max_speed, s.iterations, s.step_ms);
  std::fflush(file_);
}

}  // namespace pbflow
