#pragma once
// Reading a file a user hands in (a scene, a run directory's run.json): a regular file of
// bounded size, or an InputError naming it. Opened without blocking, so that a FIFO is refused
// rather than waited on, and checked on the open file itself, so that it cannot be swapped for
// a device between the check and the read.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "common/input_error.hpp"

namespace pbflow {

struct ReadLimits {
  long long max_bytes;
  bool follow_links = true;  // false: a symbolic link is refused (a file pbflow would replace)
};

// The whole of `path`; `what` names it in messages ("scene 'x.json'", "DIR/run.json").
inline std::string read_user_file(const std::string& path, const std::string& what, ReadLimits limits) {
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | (limits.follow_links ? 0 : O_NOFOLLOW));
  if (fd < 0) {
    const int error = errno;
    if (error == ELOOP) throw InputError(what + " is a symbolic link, not a file pbflow wrote");
    throw InputError("cannot read " + what + ": " + std::strerror(error));
  }
  struct stat st {};
  std::string text, problem;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = what + " is not a regular file (a directory, FIFO or device)";
  } else if (st.st_size > limits.max_bytes) {
    problem = what + " is larger than " + std::to_string(limits.max_bytes >> 20) + " MiB, too large to be read";
  } else {
    text.resize(size_t(st.st_size));
    size_t done = 0;
    while (done < text.size()) {  // short reads; a file that grew past its size is cut at it
      const ssize_t n = read(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += size_t(n);
    }
    text.resize(done);
  }
  close(fd);
  if (!problem.empty()) throw InputError(problem);
  return text;
}

}  // namespace pbflow
