#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>

namespace pbflow::capture {

namespace {

// A temporary beside `path` that this call creates (O_EXCL), never a file that was there: a
// name left by another process, or planted, is not opened, truncated or later removed.
std::FILE* create_temporary(const std::filesystem::path& path, std::filesystem::path& tmp) {
  static std::mt19937_64 random{std::random_device{}()};
  for (int attempt = 0; attempt < 16; ++attempt) {
    tmp = path;
    tmp += ".tmp" + std::to_string(getpid()) + std::to_string(random() % 1000000000);
    const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0) return fdopen(fd, "wb");
    if (errno != EEXIST) break;
  }
  throw std::runtime_error("cannot write " + tmp.string() + ": " + std::strerror(errno));
}

}  // namespace

void write_atomically(const std::filesystem::path& path, const std::function<void(std::FILE*)>& write) {
  std::filesystem::path tmp;
  std::FILE* f = create_temporary(path, tmp);
  try {
    write(f);
    if (std::fflush(f) != 0 || std::ferror(f)) throw std::runtime_error(std::strerror(errno));
  } catch (const std::exception& e) {
    std::fclose(f);
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot write " + path.string() + ": " + e.what());
  }
  if (std::fclose(f) != 0 || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::string why = std::strerror(errno);
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot write " + path.string() + ": " + why);
  }
}

}  // namespace pbflow::capture
