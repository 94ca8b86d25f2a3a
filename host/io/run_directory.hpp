#pragma once
// A run owns its --out directory: it locks it for its lifetime (flock, so that a second
// run into it is refused), writes only the files its manifest DIR/run.json lists, and
// replaces the previous run's files as a whole, so that the directory never mixes two runs.
// It removes only regular files inside DIR under pbflow's own names that the previous manifest
// lists, working by directory descriptor and never through a link; a manifest that lists
// anything else, or a folder or link under one of pbflow's names, is refused before anything
// changes (docs/design.md, "What a run guarantees about its directory").
#include <array>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace pbflow {

// What a run writes under its directory besides run.json and stats.csv.
struct RunFiles {
  int frame_count = 0;             // fixes the width of the frame numbers
  bool images = false;             // frames/frame_N.png
  std::string particle_extension;  // particles/frame_N.EXT; empty: none
  bool white_water = false;        // white_water/frame_N.EXT too (the particles' extension)
  bool solids = false;             // solids.csv: the moving solids' poses
  bool bodies = false;             // bodies.csv: the rigid bodies' poses and velocities
};

class RunDirectory {
 public:
  // Read-only: throws InputError when `dir` cannot be this run's (not a directory, a file
  // pbflow's manifest does not list where the run would write). Nothing changes on disk.
  static void check(const std::filesystem::path& dir);

  // Creates and locks `dir`, then checks it again under the lock. Throws InputError naming
  // the directory and the pid of a run that holds it.
  RunDirectory(const std::filesystem::path& dir, const RunFiles& files);
  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  // Replaces the previous run's files (those its manifest lists; regular files only, never
  // through a link; temporaries left alone) as a whole: all are removed, or, where one cannot
  // be, none (InputError naming it). Then writes this run's manifest, status "running".
  // `about` holds what the manifest records of the run (scene, options, device); files and
  // status are added here. Where `stop()` says so once the old files are set aside, they go
  // back, nothing is written, and it returns false.
  bool begin(nlohmann::json about, const std::function<bool()>& stop);
  // Frames 0..completed-1 are whole on disk; the manifest catches up at most once a second.
  void frames_done(int completed);
  // The final manifest: status complete / diverged / interrupted / failed, and why. Files of
  // frames past the last whole one (a failure cut them short) are removed first.
  void end(const std::string& status, const std::string& message, double wall_seconds);

  std::filesystem::path stats_path() const { return dir_ / "stats.csv"; }
  std::filesystem::path solids_path() const { return dir_ / "solids.csv"; }
  std::filesystem::path bodies_path() const { return dir_ / "bodies.csv"; }
  std::filesystem::path frame_path(int frame) const;  // frames/frame_N.png
  std::filesystem::path particle_path(int frame) const;
  std::filesystem::path white_water_path(int frame) const;

 private:
  void write_manifest();
  void drop_frames_from(int first);
  // frames/, particles/ and white_water/ with the extension this run writes there; empty: none.
  std::array<std::pair<const char*, std::string>, 3> frame_folders() const;

  std::filesystem::path dir_;
  RunFiles files_;
  int lock_fd_ = -1;
  nlohmann::json manifest_;
  double last_write_ = 0;  // steady-clock seconds of the last manifest write
};

}  // namespace pbflow
