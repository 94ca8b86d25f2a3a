#include "output_dir.hpp"

#include <limits>
#include <regex>

#include "scene.hpp"

namespace pbflow {

namespace fs = std::filesystem;

namespace {

const char* kSubdirs[] = {"frames", "particles"};

// frame_NNNNN.png / .ply / .vtp: the number. The temporary of a killed run
// (frame_NNNNN.png.tmpPID): past every frame, so that it counts as stale. -1 for
// anything else.
long frame_number(const fs::path& file) {
  static const std::regex name(R"(frame_(\d{5,12})\.(png|ply|vtp)(\.tmp\d+)?)");
  std::smatch m;
  std::string s = file.filename().string();
  if (!std::regex_match(s, m, name)) return -1;
  return m[3].matched ? std::numeric_limits<long>::max() : std::stol(m[1].str());
}

}  // namespace

void check_output_dir(const fs::path& out) {
  if (!fs::exists(out)) return;
  if (!fs::is_directory(out)) throw InputError("--out " + out.string() + " exists and is not a directory");
  for (const char* sub : kSubdirs) {
    fs::path dir = out / sub;
    if (!fs::exists(dir)) continue;
    if (!fs::is_directory(dir)) throw InputError(dir.string() + " exists and is not a directory; choose another --out");
    for (const auto& entry : fs::directory_iterator(dir))
      if (!entry.is_regular_file() || frame_number(entry.path()) < 0)
        throw InputError(dir.string() + " holds " + entry.path().filename().string() +
                         ", which pbflow did not write; choose another --out");
  }
}

void remove_stale_frames(const fs::path& out, int frames) {
  for (const char* sub : kSubdirs) {
    fs::path dir = out / sub;
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir))
      if (frame_number(entry.path()) >= frames) fs::remove(entry.path());
  }
}

}  // namespace pbflow
