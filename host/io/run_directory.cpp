#include "io/run_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <fstream>
#include <regex>
#include <sstream>

#include "common/input_error.hpp"
#include "io/atomic_file.hpp"
#include "io/frame_files.hpp"

namespace pbflow {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const char* kManifest = "run.json";
const char* kSubdirs[] = {"frames", "particles"};

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The files a manifest lists, as paths relative to the directory where '*' stands for a
// frame number; a temporary of a listed file (NAME.tmpPID, capture/atomic_file.hpp) counts too.
class Listed {
 public:
  explicit Listed(const json& manifest) {
    std::vector<std::string> names = {kManifest};
    if (manifest.contains("files") && manifest["files"].is_array())
      for (const json& f : manifest["files"])
        if (f.is_string()) names.push_back(f.get<std::string>());
    for (const std::string& name : names) {
      std::string re;
      for (char c : name) {
        if (c == '*') re.append("\\d+");
        else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/' || c == '-') re.push_back(c);
        else re.append({'\\', c});
      }
      patterns_.emplace_back(re + "(\\.tmp\\d+)?");
    }
  }
  bool lists(const std::string& relative) const {
    for (const std::regex& p : patterns_)
      if (std::regex_match(relative, p)) return true;
    return false;
  }

 private:
  std::vector<std::regex> patterns_;
};

// The previous run's manifest, or an empty object where there is none.
json previous_manifest(const fs::path& dir) {
  fs::path path = dir / kManifest;
  if (!fs::exists(path)) return json::object();
  std::ifstream in(path);
  json m = json::parse(in, nullptr, false);
  if (m.is_discarded() || !m.is_object() || !m.contains("pbflow"))
    throw InputError(path.string() + " is not a pbflow manifest; choose another --out");
  return m;
}

InputError foreign(const fs::path& file) {
  return InputError(file.string() + " was not written by pbflow (no run.json lists it); choose another --out");
}

// Every file where a run writes that `previous` (the manifest in `dir`) lists, relative to
// `dir`. Throws InputError for one it does not list.
std::vector<std::string> previous_files(const fs::path& dir, const json& previous) {
  Listed listed(previous);
  std::vector<std::string> owned;
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::string name = entry.path().filename().string();
    bool sub = std::find(std::begin(kSubdirs), std::end(kSubdirs), name) != std::end(kSubdirs);
    if (sub) {
      if (!entry.is_directory()) throw InputError(entry.path().string() + " exists and is not a directory; choose another --out");
      for (const auto& file : fs::directory_iterator(entry.path())) {
        std::string relative = name + "/" + file.path().filename().string();
        if (!file.is_regular_file() || !listed.lists(relative)) throw foreign(file.path());
        owned.push_back(relative);
      }
    } else if (listed.lists(name)) {
      owned.push_back(name);
    } else if (name == "stats.csv") {
      throw foreign(entry.path());
    }
  }
  return owned;
}

// The pid holding a flock on `dir`, from /proc/locks (0 where it cannot be told).
long lock_holder(const fs::path& dir) {
  struct stat st;
  if (stat(dir.c_str(), &st) != 0) return 0;
  std::ifstream locks("/proc/locks");
  std::ostringstream inode;
  inode << ":" << st.st_ino << " ";
  for (std::string line; std::getline(locks, line);) {
    std::istringstream f(line);
    std::string id, kind, mode, access, device;
    long pid = 0;
    f >> id >> kind >> mode >> access >> pid >> device;
    if (kind == "FLOCK" && (device + " ").find(inode.str()) != std::string::npos) return pid;
  }
  return 0;
}

std::string utc_now() {
  std::time_t t = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return text;
}

}  // namespace

void RunDirectory::check(const fs::path& dir) {
  if (dir.empty()) throw InputError("--out is empty: name a directory");
  if (!fs::exists(dir)) return;
  if (!fs::is_directory(dir)) throw InputError("--out " + dir.string() + " exists and is not a directory");
  previous_files(dir, previous_manifest(dir));
}

RunDirectory::RunDirectory(const fs::path& dir, const RunFiles& files) : dir_(dir), files_(files) {
  if (dir.empty()) throw InputError("--out is empty: name a directory");
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw InputError("cannot create --out " + dir.string() + ": " + error.message());
  lock_fd_ = open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_fd_ < 0) throw InputError("cannot open --out " + dir.string() + ": " + std::strerror(errno));
  if (flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    close(lock_fd_);
    long pid = lock_holder(dir);
    throw InputError("--out " + dir.string() + " is in use by another pbflow run" +
                     (pid > 0 ? " (pid " + std::to_string(pid) + ")" : "") + "; wait for it or choose another --out");
  }
  check(dir);  // under the lock, so that no other run changes it after
}

RunDirectory::~RunDirectory() {
  try {
    if (manifest_.value("status", "") == "running") end("failed", "stopped without a final status", 0);
  } catch (...) {  // a destructor must not throw; the manifest then says "running", and its pid is gone
  }
  close(lock_fd_);
}

std::array<std::pair<const char*, std::string>, 2> RunDirectory::frame_folders() const {
  return {{{kSubdirs[0], files_.images ? "png" : ""}, {kSubdirs[1], files_.particle_extension}}};
}

fs::path RunDirectory::frame_path(int frame) const {
  const auto [sub, extension] = frame_folders()[0];  // a copy: the array is a temporary
  return capture::frame_file(dir_ / sub, frame, files_.frame_count, extension);
}

fs::path RunDirectory::particle_path(int frame) const {
  const auto [sub, extension] = frame_folders()[1];
  return capture::frame_file(dir_ / sub, frame, files_.frame_count, extension);
}

void RunDirectory::begin(json about) {
  const json previous = previous_manifest(dir_);
  for (const std::string& file : previous_files(dir_, previous)) fs::remove(dir_ / file);
  // The video of an interrupted encoder: NAME.partPID.EXT beside NAME (capture/video.hpp).
  if (previous.contains("video") && previous["video"].is_string() && !previous["video"].get<std::string>().empty()) {
    fs::path video = previous["video"].get<std::string>();
    fs::path folder = video.has_parent_path() ? video.parent_path() : fs::path(".");
    std::string prefix = video.filename().string() + ".part";
    std::error_code ignored;
    for (const auto& entry : fs::directory_iterator(folder, ignored))
      if (entry.path().filename().string().rfind(prefix, 0) == 0) fs::remove(entry.path(), ignored);
  }
  std::vector<std::string> listed = {"stats.csv"};
  for (const auto& [sub, extension] : frame_folders()) {
    if (!extension.empty()) {
      fs::create_directories(dir_ / sub);
      listed.push_back(std::string(sub) + "/frame_*." + extension);
    } else if (fs::is_directory(dir_ / sub) && fs::is_empty(dir_ / sub)) {
      fs::remove(dir_ / sub);
    }
  }
  manifest_ = std::move(about);
  manifest_["pbflow"] = PBFLOW_VERSION;
  manifest_["pid"] = long(getpid());
  manifest_["started"] = utc_now();
  manifest_["status"] = "running";
  manifest_["files"] = listed;
  manifest_["frames"] = {{"planned", files_.frame_count}, {"completed", 0}};
  write_manifest();
}

void RunDirectory::frames_done(int completed) {
  manifest_["frames"]["completed"] = completed;
  if (now_seconds() - last_write_ >= 1.0) write_manifest();
}

void RunDirectory::end(const std::string& status, const std::string& message, double wall_seconds) {
  manifest_["status"] = status;
  if (!message.empty()) manifest_["message"] = message;
  manifest_["wall_seconds"] = wall_seconds;
  manifest_["finished"] = utc_now();
  write_manifest();
}

void RunDirectory::write_manifest() {
  std::string text = manifest_.dump(2) + "\n";
  capture::write_atomically(dir_ / kManifest, [&](std::FILE* f) {
    if (std::fwrite(text.data(), 1, text.size(), f) != text.size()) throw std::runtime_error(std::strerror(errno));
  });
  last_write_ = now_seconds();
}

}  // namespace pbflow
