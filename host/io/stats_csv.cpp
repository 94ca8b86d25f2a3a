#include "io/stats_csv.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace pbflow {

namespace {
// A new file: the previous run's was set aside, and a stats.csv that appeared since (or a link
// under its name) is not opened through, let alone truncated.
std::FILE* create_new(const std::filesystem::path& path) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  return fd < 0 ? nullptr : fdopen(fd, "w");
}
}  // namespace

StatsCsv::StatsCsv(const std::filesystem::path& path) : path_(path), file_(create_new(path)) {
  if (!file_) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  append("frame,time,mean_compression,max_compression,kinetic_energy,potential_energy,solid_work,max_speed,iterations,step_ms\n");
}

StatsCsv::~StatsCsv() { std::fclose(file_); }

void StatsCsv::write(int frame, double time, const FrameStats& s) {
  char row[512];
  std::snprintf(row, sizeof row, "%d,%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.4g,%.6f\n", frame, time, s.mean_compression,
                s.max_compression, s.kinetic_energy, s.potential_energy, s.solid_work, s.max_speed, s.iterations,
                s.step_ms);
  append(row);
}

void StatsCsv::append(const char* text) {
  // Written and flushed whole: a run stopped at any point leaves whole rows. A row the disk
  // took only in part (no space, quota, file size limit) is cut off again before the error.
  long whole = std::ftell(file_);
  if (std::fputs(text, file_) < 0 || std::fflush(file_) != 0) {
    std::string why = std::strerror(errno);
    std::clearerr(file_);
    if (whole >= 0 && ftruncate(fileno(file_), whole) == 0) std::fseek(file_, whole, SEEK_SET);
    throw std::runtime_error("cannot write " + path_.string() + ": " + why);
  }
}

}  // namespace pbflow
