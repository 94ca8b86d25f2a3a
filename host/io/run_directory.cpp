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
#include <iostream>
#include <map>
#include <sstream>

#include "common/input_error.hpp"
#include "common/json_input.hpp"
#include "common/pause_point.hpp"
#include "common/read_file.hpp"
#include "io/atomic_file.hpp"
#include "io/frame_files.hpp"

namespace pbflow {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const char* kManifest = "run.json";
const char* kSubdirs[] = {"frames", "particles", "white_water"};
// The manifest records the scene it ran: room for the largest scene file (kMaxSceneBytes, 64 MiB).
constexpr long long kMaxManifestBytes = 128LL << 20;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Every name pbflow writes under DIR, with '*' for a frame number (io/frame_files.hpp). A
// manifest may list these and nothing else: it is a file a user can edit, and pbflow removes
// what it lists.
const char* kOwnPatterns[] = {"stats.csv", "solids.csv", "bodies.csv", "frames/frame_*.png",    "particles/frame_*.ply",
                              "particles/frame_*.vtp", "white_water/frame_*.ply", "white_water/frame_*.vtp"};

size_t skip_digits(std::string_view text, size_t at) {
  while (at < text.size() && std::isdigit(static_cast<unsigned char>(text[at]))) ++at;
  return at;
}

// Where `pattern` ('*': one or more digits) ends as a prefix of `name`; npos where it is not one.
size_t pattern_end(std::string_view pattern, std::string_view name) {
  const size_t star = pattern.find('*');
  if (star == std::string_view::npos) return name.starts_with(pattern) ? pattern.size() : std::string_view::npos;
  const std::string_view before = pattern.substr(0, star), after = pattern.substr(star + 1);
  if (!name.starts_with(before)) return std::string_view::npos;
  const size_t digits_end = skip_digits(name, before.size());
  if (digits_end == before.size() || name.substr(digits_end, after.size()) != after) return std::string_view::npos;
  return digits_end + after.size();
}

// Whether `name` is `pattern`'s, or a temporary of one (NAME.tmpDIGITS, io/atomic_file.hpp).
bool matches(std::string_view pattern, std::string_view name) { return pattern_end(pattern, name) == name.size(); }
bool temporary_of(std::string_view pattern, std::string_view name) {
  const size_t at = pattern_end(pattern, name);
  const std::string_view tmp = ".tmp";
  return at != std::string_view::npos && name.substr(at, tmp.size()) == tmp && at + tmp.size() < name.size() &&
         skip_digits(name, at + tmp.size()) == name.size();
}

// The files a manifest lists (run.json always), checked against pbflow's own names.
class Listed {
 public:
  Listed(const json& manifest, const fs::path& path) {
    patterns_.push_back(kManifest);
    if (!manifest.contains("files")) return;
    if (!manifest["files"].is_array()) throw not_ours(path, "a 'files' entry that is not a list");
    for (const json& f : manifest["files"]) {
      const std::string* name = f.get_ptr<const std::string*>();
      if (!name || std::find(std::begin(kOwnPatterns), std::end(kOwnPatterns), *name) == std::end(kOwnPatterns))
        throw not_ours(path, "'" + (name ? *name : f.dump()) + "' among its files, which pbflow never writes");
      patterns_.push_back(*name);
    }
  }
  bool lists(std::string_view relative) const {
    return std::any_of(patterns_.begin(), patterns_.end(), [&](const std::string& p) { return matches(p, relative); });
  }
  bool temporary(std::string_view relative) const {
    return std::any_of(patterns_.begin(), patterns_.end(), [&](const std::string& p) { return temporary_of(p, relative); });
  }
  // Whether a run made the folder `sub`: it listed files in it.
  bool made(std::string_view sub) const {
    return std::any_of(patterns_.begin(), patterns_.end(),
                       [&](const std::string& p) { return p.size() > sub.size() && p.starts_with(sub) && p[sub.size()] == '/'; });
  }

 private:
  static InputError not_ours(const fs::path& path, const std::string& what) {
    return InputError(path.string() + " names " + what + "; pbflow removes only its own files: choose another --out");
  }
  std::vector<std::string> patterns_;
};

// The previous run's manifest, or an empty object where there is none: a regular file (not a
// link, FIFO or device) of bounded size, since pbflow removes what it lists.
json previous_manifest(const fs::path& dir) {
  fs::path path = dir / kManifest;
  std::error_code error;
  if (!fs::exists(fs::symlink_status(path, error))) return json::object();
  const std::string text = read_user_file(path.string(), path.string(), {kMaxManifestBytes, false});
  json m;
  try {
    m = parse_user_json(text, path.string());
  } catch (const InputError&) {
    m = nullptr;
  }
  if (!m.is_object() || !m.contains("pbflow"))
    throw InputError(path.string() + " is not a pbflow manifest; choose another --out");
  return m;
}

InputError foreign(const fs::path& file) {
  return InputError(file.string() + " was not written by pbflow (no run.json lists it); choose another --out");
}

// Every file where a run writes that `listed` (the manifest in `dir`) names, relative to `dir`:
// regular files only, never followed through a link. Throws InputError for a file it does not
// list, for a folder or link under a name pbflow writes, and for a frames/ or particles/ that is
// not a real directory. Temporaries (NAME.tmpDIGITS) are left alone: no run can tell whose they are.
std::vector<std::string> previous_files(const fs::path& dir, const Listed& listed) {
  std::vector<std::string> owned;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    const fs::file_status status = entry.symlink_status();
    const bool sub = std::find(std::begin(kSubdirs), std::end(kSubdirs), name) != std::end(kSubdirs);
    if (sub) {
      if (!fs::is_directory(status))
        throw InputError(entry.path().string() + " exists and is not a directory (a file or a link); choose another --out");
      for (const auto& file : fs::directory_iterator(entry.path())) {
        const std::string relative = name + "/" + file.path().filename().string();
        if (listed.temporary(relative)) continue;
        if (!fs::is_regular_file(file.symlink_status()) || !listed.lists(relative)) throw foreign(file.path());
        owned.push_back(relative);
      }
    } else if (listed.lists(name)) {
      if (!fs::is_regular_file(status))
        throw InputError(entry.path().string() + " is not a regular file (a folder or a link), so pbflow did not write it; "
                         "choose another --out");
      owned.push_back(name);
    } else if (name == "stats.csv" || name == "solids.csv" || name == "bodies.csv") {
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

// A directory opened once and worked in by descriptor, never through a link.
class DirectoryFd {
 public:
  DirectoryFd(int parent, const std::string& name)
      : fd_(openat(parent, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC)) {}
  ~DirectoryFd() {
    if (fd_ >= 0) close(fd_);
  }
  DirectoryFd(DirectoryFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  DirectoryFd(const DirectoryFd&) = delete;
  DirectoryFd& operator=(const DirectoryFd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// Moves `files` (relative to `dir`, open as `dir_fd`) into DIR/.pbflow-replaced-PID, then deletes
// them there. A file that cannot be moved (permissions, an immutable file), or a `stop()` once all
// are moved, puts every moved file back: the previous run and its manifest stay whole. Returns
// false for a stop; throws InputError naming a file that could not be moved.
bool replace_previous_run(int dir_fd, const fs::path& dir, const std::vector<std::string>& files,
                          const std::function<bool()>& stop) {
  if (files.empty()) return !stop();
  const std::string aside = ".pbflow-replaced-" + std::to_string(getpid());
  if (mkdirat(dir_fd, aside.c_str(), 0700) != 0)
    throw InputError("cannot set the previous run aside in " + (dir / aside).string() + ": " + std::strerror(errno));
  const DirectoryFd aside_fd(dir_fd, aside);
  // Each folder of the previous run's, as (where its files are, where they go aside).
  std::map<std::string, std::pair<DirectoryFd, DirectoryFd>> folders;
  auto folder = [&](const std::string& sub) -> std::pair<int, int> {
    if (sub.empty()) return {dir_fd, aside_fd.get()};
    auto found = folders.find(sub);
    if (found == folders.end()) {
      mkdirat(aside_fd.get(), sub.c_str(), 0700);
      found = folders.emplace(sub, std::pair{DirectoryFd(dir_fd, sub), DirectoryFd(aside_fd.get(), sub)}).first;
    }
    return {found->second.first.get(), found->second.second.get()};
  };
  auto split = [](const std::string& file) {
    const size_t slash = file.find('/');
    return slash == std::string::npos ? std::pair<std::string, std::string>{"", file}
                                      : std::pair{file.substr(0, slash), file.substr(slash + 1)};
  };
  std::vector<std::string> moved;
  std::string failure;
  for (const std::string& file : files) {
    const auto [sub, name] = split(file);
    const auto [from, to] = folder(sub);
    if (from < 0 || to < 0 || renameat(from, name.c_str(), to, name.c_str()) != 0) {
      failure = (dir / file).string() + ": " + std::strerror(errno);
      break;
    }
    moved.push_back(file);
    if (moved.size() == 1) pause_point("replace");
  }
  const bool undo = !failure.empty() || stop();
  for (auto file = moved.rbegin(); file != moved.rend(); ++file) {
    const auto [sub, name] = split(*file);
    const auto [from, to] = folder(sub);
    if (undo) renameat(to, name.c_str(), from, name.c_str());
    else unlinkat(to, name.c_str(), 0);
  }
  for (const auto& [sub, fds] : folders) unlinkat(aside_fd.get(), sub.c_str(), AT_REMOVEDIR);
  if (unlinkat(dir_fd, aside.c_str(), AT_REMOVEDIR) != 0)
    std::cerr << "pbflow: warning: the previous run's files stay in " << (dir / aside).string() << ": "
              << std::strerror(errno) << "\n";
  if (!failure.empty())
    throw InputError("cannot replace the previous run in " + dir.string() + ": " + failure + "; nothing was removed");
  return !undo;
}

constexpr size_t kManifestRoom = 64 << 10;

// The fallback where a new file cannot be written (no space, quota): the manifest rewritten
// over the old one, into the room write_manifest held for it. Not atomic, so not the rule.
bool overwrite_in_place(const fs::path& path, const std::string& text) {
  const int fd = open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = pwrite(fd, text.data() + done, text.size() - done, off_t(done));
    if (n <= 0) break;
    done += size_t(n);
  }
  const bool whole = done == text.size() && ftruncate(fd, off_t(text.size())) == 0 && fsync(fd) == 0;
  close(fd);
  return whole;
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
  previous_files(dir, Listed(previous_manifest(dir), dir / kManifest));
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

std::array<std::pair<const char*, std::string>, 3> RunDirectory::frame_folders() const {
  return {{{kSubdirs[0], files_.images ? "png" : ""},
           {kSubdirs[1], files_.particle_extension},
           {kSubdirs[2], files_.white_water ? files_.particle_extension : ""}}};
}

fs::path RunDirectory::frame_path(int frame) const {
  const auto [sub, extension] = frame_folders()[0];  // a copy: the array is a temporary
  return capture::frame_file(dir_ / sub, frame, files_.frame_count, extension);
}

fs::path RunDirectory::particle_path(int frame) const {
  const auto [sub, extension] = frame_folders()[1];
  return capture::frame_file(dir_ / sub, frame, files_.frame_count, extension);
}

fs::path RunDirectory::white_water_path(int frame) const {
  const auto [sub, extension] = frame_folders()[2];
  return capture::frame_file(dir_ / sub, frame, files_.frame_count, extension);
}

bool RunDirectory::begin(json about, const std::function<bool()>& stop) {
  const Listed previous(previous_manifest(dir_), dir_ / kManifest);
  if (!replace_previous_run(lock_fd_, dir_, previous_files(dir_, previous), stop)) return false;
  std::vector<std::string> listed = {"stats.csv"};
  if (files_.solids) listed.push_back("solids.csv");
  if (files_.bodies) listed.push_back("bodies.csv");
  for (const auto& [sub, extension] : frame_folders()) {
    if (!extension.empty()) {  // a real directory where one exists (previous_files checked)
      if (mkdirat(lock_fd_, sub, 0755) != 0 && errno != EEXIST)
        throw std::runtime_error("cannot create " + (dir_ / sub).string() + ": " + std::strerror(errno));
      listed.push_back(std::string(sub) + "/frame_*." + extension);
    } else if (previous.made(sub)) {  // the previous run's folder, where it is empty now
      unlinkat(lock_fd_, sub, AT_REMOVEDIR);
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
  return true;
}

void RunDirectory::frames_done(int completed) {
  manifest_["frames"]["completed"] = completed;
  if (now_seconds() - last_write_ >= 1.0) write_manifest();
}

// Frames `first` on are not whole: a failure ended the run while their files were in hand (a
// PNG still being written, particles before their white water). Their files go, by directory
// descriptor, so that the folders hold whole frames only, as the rows do.
void RunDirectory::drop_frames_from(int first) {
  for (const auto& [sub, extension] : frame_folders()) {
    if (extension.empty()) continue;
    const int folder = openat(lock_fd_, sub, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (folder < 0) continue;
    for (int frame = first; frame < files_.frame_count; ++frame)
      unlinkat(folder, capture::frame_file(".", frame, files_.frame_count, extension).filename().c_str(), 0);
    close(folder);
  }
}

void RunDirectory::end(const std::string& status, const std::string& message, double wall_seconds) {
  drop_frames_from(manifest_["frames"]["completed"].get<int>());
  manifest_["status"] = status;
  if (!message.empty()) manifest_["message"] = message;
  manifest_["wall_seconds"] = wall_seconds;
  manifest_["finished"] = utc_now();
  write_manifest();
}

void RunDirectory::write_manifest() {
  const std::string text = manifest_.dump(2) + "\n";
  try {
    capture::write_atomically(dir_ / kManifest, [&](std::FILE* f) {
      if (std::fwrite(text.data(), 1, text.size(), f) != text.size()) throw std::runtime_error(std::strerror(errno));
      // Room for the manifests to come, held past the end of the file (not in its size): when
      // the disk fills up mid-run, the last word (failed, and why) still fits in place.
      fallocate(fileno(f), FALLOC_FL_KEEP_SIZE, 0, off_t(text.size() + kManifestRoom));
    });
  } catch (const std::exception&) {
    if (!overwrite_in_place(dir_ / kManifest, text)) throw;
  }
  last_write_ = now_seconds();
}

}  // namespace pbflow
