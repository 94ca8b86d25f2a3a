#include "io/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pbflow::capture {

void write_atomically(const std::filesystem::path& path, const std::function<void(std::FILE*)>& write) {
  std::filesystem::path tmp = path;
  tmp += ".tmp" + std::to_string(getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + tmp.string() + ": " + std::strerror(errno));
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
