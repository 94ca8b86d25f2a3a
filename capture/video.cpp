#include "capture/video.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>
#include <sstream>
#include <stdexcept>

#include "common/input_error.hpp"

namespace pbflow::capture {

std::filesystem::path find_ffmpeg() {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : dir) / "ffmpeg";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

namespace {
// Checked now, not after the whole run: what is at `file` must be a regular file that the rename
// at the end can replace (an immutable or append-only file cannot be opened for writing).
void check_replaceable(const std::filesystem::path& file) {
  std::error_code exists_error;
  const std::filesystem::file_status there = std::filesystem::symlink_status(file, exists_error);
  if (std::filesystem::is_directory(there)) throw InputError("--video " + file.string() + " is a directory: name a file");
  if (std::filesystem::exists(there) && !std::filesystem::is_regular_file(there) && !std::filesystem::is_symlink(there))
    throw InputError("--video " + file.string() + " exists and is not a regular file (a FIFO, socket or device)");
  if (std::filesystem::is_regular_file(there)) {
    const int existing = open(file.c_str(), O_WRONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (existing < 0)
      throw InputError("--video " + file.string() + " exists and cannot be replaced: " + std::strerror(errno));
    close(existing);
  }
}
}  // namespace

VideoEncoder::VideoEncoder(const std::filesystem::path& file, int width, int height, double fps)
    : file_(file), width_(width), height_(height) {
  const std::string extension = file.extension().string();
  if (extension != ".mp4" && extension != ".mkv" && extension != ".mov")
    throw InputError("--video " + file.string() + " needs the extension .mp4, .mkv or .mov (H.264)");
  check_replaceable(file);
  std::filesystem::path ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) throw InputError("--video needs ffmpeg, which is not on PATH (apt-get install ffmpeg)");
  if (width % 2 || height % 2) throw InputError("--video needs an even --width and --height (H.264 with 4:2:0)");
  // A name no other run can produce (its pid and 64 random bits), created exclusively below:
  // a run removes only its own temporary, never by a prefix or a name from a file.
  std::random_device random;
  std::ostringstream token;
  token << std::hex << getpid() << "-" << ((uint64_t(random()) << 32) | random());
  tmp_ = file;
  tmp_ += ".part" + token.str() + extension;
  // Found now, not after the whole run: the folder must exist (or be made) and take a file.
  std::error_code error;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), error);
  int probe = error ? -1 : open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (probe < 0)
    throw InputError("--video " + file.string() + " cannot be written: " + (error ? error.message() : std::strerror(errno)));
  close(probe);

  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot start ffmpeg: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  std::string size = std::to_string(width) + "x" + std::to_string(height), rate = std::to_string(fps);
  std::vector<std::string> args = {ffmpeg.string(), "-y", "-loglevel", "error", "-nostdin", "-f", "rawvideo", "-pix_fmt",
                                   "rgb24", "-s", size, "-framerate", rate, "-i", "pipe:0", "-c:v", "libx264",
                                   "-pix_fmt", "yuv420p", "-crf", "20",
                                   // As ffmpeg's file protocol names it: a name that starts with '-'
                                   // or holds ':' is still a file, never an option or a protocol.
                                   "file:" + std::filesystem::absolute(tmp_).string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  int spawned = posix_spawn(&pid_, ffmpeg.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  close(fds[0]);
  if (spawned != 0) {
    close(fds[1]);
    std::filesystem::remove(tmp_, error);
    throw std::runtime_error(std::string("cannot start ffmpeg: ") + std::strerror(spawned));
  }
  pipe_ = fdopen(fds[1], "w");
}

VideoEncoder::~VideoEncoder() {
  if (!pipe_) return;
  wait();
  std::error_code ignored;
  std::filesystem::remove(tmp_, ignored);
}

int VideoEncoder::wait() {
  std::fclose(std::exchange(pipe_, nullptr));
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

// ffmpeg's own message goes to stderr; the two causes a user can act on are named here too.
std::string VideoEncoder::cause() const {
  struct statvfs disk {};
  const std::filesystem::path folder = tmp_.has_parent_path() ? tmp_.parent_path() : ".";
  if (statvfs(folder.c_str(), &disk) == 0 && uint64_t(disk.f_bavail) * disk.f_frsize < (64u << 10))
    return ": " + std::string(std::strerror(ENOSPC));
  rlimit limit{};
  std::error_code error;
  const uintmax_t size = std::filesystem::file_size(tmp_, error);
  if (!error && getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && size + (64u << 10) >= limit.rlim_cur)
    return ": " + std::string(std::strerror(EFBIG));
  return "";
}

void VideoEncoder::add(const Image& frame) {
  if (frame.width != width_ || frame.height != height_) throw std::runtime_error("video frame of the wrong size");
  if (std::fwrite(frame.rgb.data(), 1, frame.rgb.size(), pipe_) != frame.rgb.size())
    throw std::runtime_error("ffmpeg stopped taking frames for " + file_.string() + cause());
}

void VideoEncoder::finish() {
  int status = wait();
  // ffmpeg 5.1 exits 0 when it cannot write the trailer of a full disk's file, so a video
  // that ends with the disk (or the file size limit) full is not trusted either.
  const std::string why = cause();
  if (status != 0 || !why.empty()) {
    std::filesystem::remove(tmp_);
    throw std::runtime_error("ffmpeg failed to encode " + file_.string() +
                             (status ? " (status " + std::to_string(status) + ")" : "") + why);
  }
  std::filesystem::rename(tmp_, file_);
}

}  // namespace pbflow::capture
