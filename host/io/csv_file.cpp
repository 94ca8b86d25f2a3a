#include "io/csv_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pbflow {

namespace {
// A new file: the previous run's was set aside, and a file that appeared since (or a link under
// its name) is not opened through, let alone truncated.
std::FILE* create_new(const std::filesystem::path& path) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  return fd < 0 ? nullptr : fdopen(fd, "w");
}
}  // namespace

CsvFile::CsvFile(const std::filesystem::path& path, const char* header) : path_(path), file_(create_new(path)) {
  if (!file_) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  append(header);
}

CsvFile::~CsvFile() { std::fclose(file_); }

void CsvFile::append(const char* row) {
  // A row the disk took only in part (no space, quota, file size limit) is cut off again
  // before the error.
  long whole = std::ftell(file_);
  if (std::fputs(row, file_) < 0 || std::fflush(file_) != 0) {
    std::string why = std::strerror(errno);
    std::clearerr(file_);
    if (whole >= 0 && ftruncate(fileno(file_), whole) == 0) std::fseek(file_, whole, SEEK_SET);
    throw std::runtime_error("cannot write " + path_.string() + ": " + why);
  }
}

}  // namespace pbflow
