#include "video.hpp"

#include <unistd.h>

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "scene.hpp"

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
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out.append("'\\''");  // close the quote, an escaped quote, reopen
    else out.push_back(c);
  }
  return out + "'";
}
}  // namespace

VideoEncoder::VideoEncoder(const std::filesystem::path& file, int width, int height, double fps)
    : file_(file), width_(width), height_(height) {
  std::filesystem::path ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) throw InputError("--video needs ffmpeg, which is not on PATH (apt-get install ffmpeg)");
  if (width % 2 || height % 2) throw InputError("--video needs an even --width and --height (H.264 with 4:2:0)");
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  tmp_ = file;
  tmp_ += ".part" + std::to_string(getpid()) + file.extension().string();
  std::ostringstream cmd;
  cmd << quoted(ffmpeg) << " -y -loglevel error -f rawvideo -pix_fmt rgb24 -s " << width << "x" << height
      << " -framerate " << fps << " -i - -c:v libx264 -pix_fmt yuv420p -crf 20 " << quoted(tmp_.string());
  pipe_ = popen(cmd.str().c_str(), "w");
  if (!pipe_) throw std::runtime_error("cannot start ffmpeg");
}

VideoEncoder::~VideoEncoder() {
  if (!pipe_) return;
  pclose(pipe_);
  std::filesystem::remove(tmp_);
}

void VideoEncoder::add(const Image& frame) {
  if (frame.width != width_ || frame.height != height_) throw std::runtime_error("video frame of the wrong size");
  if (std::fwrite(frame.rgb.data(), 1, frame.rgb.size(), pipe_) != frame.rgb.size())
    throw std::runtime_error("ffmpeg stopped taking frames for " + file_.string());
}

void VideoEncoder::finish() {
  int status = pclose(std::exchange(pipe_, nullptr));
  if (status != 0) {
    std::filesystem::remove(tmp_);
    throw std::runtime_error("ffmpeg failed to encode " + file_.string() + " (status " + std::to_string(status) + ")");
  }
  std::filesystem::rename(tmp_, file_);
}

}  // namespace pbflow::capture
