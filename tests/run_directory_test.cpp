// A run owns its --out directory (docs/design.md, "What a run guarantees about its directory"):
// one run at a time, no foreign file touched, never two runs mixed, every write checked,
// interrupts leave whole files and a manifest that says why the run stopped.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <glm/glm.hpp>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "capture/png.hpp"
#include "gpu/memory_estimate.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "support.hpp"
#include "vk/context.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using Result = pbflow::test::CliResult;
using pbflow::test::run_pbflow;

// A run's directory for this test: pbflow_test_dir_NAME, empty.
fs::path fresh_dir(const std::string& name) { return pbflow::test::fresh_dir("dir_" + name); }

json manifest(const fs::path& dir) {
  std::ifstream in(dir / "run.json");
  return json::parse(in, nullptr, false);
}

std::vector<std::string> rows(const fs::path& stats) {
  std::ifstream in(stats);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

size_t files_in(const fs::path& dir) {
  return fs::is_directory(dir) ? std::distance(fs::directory_iterator(dir), fs::directory_iterator()) : 0;
}

bool any_temporary(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp") != std::string::npos) return true;
  return false;
}

const std::string kSmall = " --param particle_spacing=0.04 --style particles --width 64 --height 32 --quiet ";

// A long run in the background, as a child process with its own pid.
class Background {
 public:
  explicit Background(const std::string& args) {
    std::vector<std::string> a = {PBFLOW_BINARY};
    std::istringstream words(args);
    for (std::string w; words >> w;) a.push_back(w);
    std::vector<char*> argv;
    for (auto& s : a) argv.push_back(s.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    EXPECT_EQ(posix_spawn(&pid_, PBFLOW_BINARY, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Background() {
    if (pid_ > 0) stop(SIGKILL);
  }
  pid_t pid() const { return pid_; }
  int stop(int signal) {  // the exit status
    kill(pid_, signal);
    int status = 0;
    waitpid(std::exchange(pid_, -1), &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
};

// Waits (up to a minute) until the manifest in `dir` says that the run `pid` has completed `frames` frames.
bool wait_for_frames(const fs::path& dir, pid_t pid, int frames) {
  for (int i = 0; i < 600; ++i) {
    json m = manifest(dir);
    if (!m.is_discarded() && m.value("pid", 0L) == long(pid) && m["frames"]["completed"].get<int>() >= frames)
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

TEST(RunDirectory, ASecondRunIsRefusedAndAnInterruptedRunLeavesOnlyItsOwnWholeFiles) {
  fs::path dir = fresh_dir("interrupt");
  // An earlier, longer run with particle files: none of its files may survive the next run.
  ASSERT_EQ(run_pbflow("run" + kSmall + "--frames 12 --export ply --out " + dir.string()).status, 0);
  ASSERT_EQ(files_in(dir / "frames"), 12u);

  Background run("run --param particle_spacing=0.015 --style particles --width 64 --height 32 --quiet "
                 "--frames 2000 --out " + dir.string());
  ASSERT_TRUE(wait_for_frames(dir, run.pid(), 2)) << "the background run did not get going";
  Result second = run_pbflow("run" + kSmall + "--frames 2 --out " + dir.string());
  EXPECT_EQ(second.status, 2) << second.output;
  EXPECT_NE(second.output.find("in use by another pbflow run (pid " + std::to_string(run.pid()) + ")"),
            std::string::npos) << second.output;

  EXPECT_EQ(run.stop(SIGTERM), 143);
  json m = manifest(dir);
  ASSERT_FALSE(m.is_discarded());
  EXPECT_EQ(m["status"], "interrupted");
  const int done = m["frames"]["completed"].get<int>();
  EXPECT_GE(done, 2);
  EXPECT_LT(done, 2000);
  EXPECT_EQ(files_in(dir / "frames"), size_t(done)) << "frames 0..k of this run, nothing of the earlier one";
  EXPECT_FALSE(fs::exists(dir / "particles")) << "the earlier run's particle files survived";
  EXPECT_EQ(rows(dir / "stats.csv").size(), size_t(done) + 1) << "a header and a row per frame written";
  for (int f = 0; f < done; ++f)  // every frame whole (this throws on a truncated PNG)
    EXPECT_EQ(pbflow::capture::read_png(dir / "frames" / ("frame_" + std::string(5 - std::to_string(f).size(), '0') +
                                                          std::to_string(f) + ".png")).width, 64);
  EXPECT_FALSE(any_temporary(dir));
}

TEST(RunDirectory, FilesPbflowDidNotWriteAreRefusedAndKept) {
  fs::path dir = fresh_dir("foreign");
  fs::create_directories(dir);
  std::ofstream(dir / "stats.csv") << "my spreadsheet\n";
  Result r = run_pbflow("run" + kSmall + "--frames 2 --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("stats.csv was not written by pbflow"), std::string::npos) << r.output;
  EXPECT_EQ(rows(dir / "stats.csv"), std::vector<std::string>{"my spreadsheet"});
  EXPECT_FALSE(fs::exists(dir / "run.json"));

  fs::remove(dir / "stats.csv");
  std::ofstream(dir / "run.json") << "{\"not\": \"ours\"}";
  r = run_pbflow("run" + kSmall + "--frames 2 --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("not a pbflow manifest"), std::string::npos) << r.output;
}

// run.json is a file a user can edit, and pbflow removes what it lists: a manifest that
// lists anything but pbflow's own names (outside --out, a pattern of its own making) is
// refused before anything changes, and a pattern cannot make the matching slow.
TEST(RunDirectory, AManifestListingWhatPbflowNeverWritesIsRefusedAndNothingChanges) {
  fs::path dir = fresh_dir("edited");
  ASSERT_EQ(run_pbflow("run" + kSmall + "--frames 3 --out " + dir.string()).status, 0);
  const fs::path victim = dir.parent_path() / "pbflow_test_victim.txt";
  std::ofstream(victim) << "mine\n";
  std::ofstream(dir / "notes.txt") << "mine\n";
  const json original = manifest(dir);
  for (const std::string& listed : {std::string("../pbflow_test_victim.txt"), std::string("notes.txt"), std::string("*"),
                                    std::string("frames/") + std::string(40, '*') + "a", std::string("frames/*.png")}) {
    json edited = original;
    edited["files"].push_back(listed);
    std::ofstream(dir / "run.json") << edited.dump();
    const auto start = std::chrono::steady_clock::now();
    Result r = run_pbflow("run" + kSmall + "--frames 2 --out " + dir.string());
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60)) << listed;
    EXPECT_EQ(r.status, 2) << listed << ": " << r.output;
    EXPECT_NE(r.output.find("pbflow removes only its own files"), std::string::npos) << listed << ": " << r.output;
    EXPECT_EQ(files_in(dir / "frames"), 3u) << listed;
    EXPECT_TRUE(fs::exists(victim) && fs::exists(dir / "notes.txt")) << listed;
    EXPECT_EQ(manifest(dir), edited) << listed << ": the manifest changed";
  }
  fs::remove(victim);
}

// The previous run is replaced as a whole: where one of its files cannot be removed (an
// immutable frame), nothing is, and its manifest still tells the truth.
TEST(RunDirectory, AFileThatCannotBeRemovedLeavesThePreviousRunWhole) {
  fs::path dir = fresh_dir("immutable");
  ASSERT_EQ(run_pbflow("run" + kSmall + "--frames 3 --export ply --out " + dir.string()).status, 0);
  const fs::path stuck = dir / "frames" / "frame_00001.png";
  if (std::system(("chattr +i " + stuck.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "chattr +i is not available here (needs root and a filesystem with attributes)";
  Result r = run_pbflow("run" + kSmall + "--frames 2 --out " + dir.string());
  std::system(("chattr -i " + stuck.string()).c_str());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(stuck.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("nothing was removed"), std::string::npos) << r.output;
  EXPECT_EQ(files_in(dir / "frames"), 3u);
  EXPECT_EQ(files_in(dir / "particles"), 3u);
  EXPECT_EQ(rows(dir / "stats.csv").size(), 4u);
  json m = manifest(dir);
  EXPECT_EQ(m["status"], "complete");
  EXPECT_EQ(m["frames"]["completed"], 3);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".pbflow-replaced"), std::string::npos) << e.path();
}

// A full disk fails the run naming the file that did not fit and its cause, and the
// manifest says so, even when the disk cannot take a new file any more.
TEST(RunDirectory, AFullDiskFailsTheRunNamingTheFileAndTheManifestSaysSo) {
  fs::path disk = fresh_dir("full_disk");
  fs::create_directories(disk);
  if (std::system(("mount -t tmpfs -o size=16k tmpfs " + disk.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a small tmpfs here (needs root outside a restricted container)";
  Result r = run_pbflow("run --param particle_spacing=0.04 --style particles --width 160 --height 96 --quiet "
                        "--frames 20 --out " + (disk / "run").string());
  json m = manifest(disk / "run");
  std::system(("umount " + disk.string()).c_str());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("frame_"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  EXPECT_EQ(m["status"], "failed");
  EXPECT_NE(m["message"].get<std::string>().find("No space left on device"), std::string::npos) << m.dump();
}

TEST(RunDirectory, AnAbsurdFrameCountChangesNothing) {
  fs::path dir = fresh_dir("absurd");
  ASSERT_EQ(run_pbflow("run" + kSmall + "--frames 3 --out " + dir.string()).status, 0);
  for (const char* bad : {"--param frames=3000000000", "--param frames=1e10", "--frames 3000000000"}) {
    Result r = run_pbflow("run" + kSmall + bad + " --out " + dir.string());
    EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    EXPECT_EQ(files_in(dir / "frames"), 3u) << bad << " touched the earlier run";
    EXPECT_EQ(manifest(dir)["status"], "complete") << bad;
  }
}

// The manifest names what pbflow chose where the scene was silent: the lambda averages
// (four from three iterations on at this step, two below), and a stated count stands.
TEST(RunDirectory, TheManifestRecordsTheChosenLambdaAverages) {
  fs::path dir = fresh_dir("chosen");
  for (auto [options, averages] : {std::pair{"--iterations 3", 4}, {"--iterations 2", 2},
                                   {"--iterations 4 --param solver.lambda_smoothing=0", 0}}) {
    Result r = run_pbflow("run --no-render --param particle_spacing=0.04 --quiet --frames 2 " + std::string(options) +
                          " --out " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    json m = manifest(dir);
    EXPECT_EQ(m["chosen"]["solver.lambda_smoothing"], averages) << options;
  }
}

// And the camera it framed where the scene names none (host/scene/framing.cpp): the domain's
// centre, the eye in front of it (+z) and above; and the substeps it chose (chosen_substeps:
// 2 here), method and iterations. A stated eye, count or setting stands and is not listed.
TEST(RunDirectory, TheManifestRecordsTheChosenCameraAndSubsteps) {
  fs::path dir = fresh_dir("chosen_camera");
  Result r = run_pbflow("run --no-render --param particle_spacing=0.04 --frames 1 --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("2 substeps per frame (chosen)"), std::string::npos) << r.output;  // the first line
  json m = manifest(dir);
  ASSERT_TRUE(m["chosen"].contains("camera.eye")) << m.dump();
  const json eye = m["chosen"]["camera.eye"], target = m["chosen"]["camera.target"];
  EXPECT_EQ(target, json::array({0.8, 0.5, 0.2}));  // the dam break's domain: [0, 1.6] x [0, 1] x [0, 0.4]
  EXPECT_EQ(eye[0], 0.8);
  EXPECT_GT(eye[1].get<double>(), 0.5);
  EXPECT_GT(eye[2].get<double>(), 0.4);
  EXPECT_EQ(m["chosen"]["solver.substeps"], 2);
  // The built-in scenes leave the setting out too: the front's pbf@2 (keys.cpp).
  EXPECT_NE(r.output.find("pbf with 2 iteration(s) (chosen)"), std::string::npos) << r.output;
  EXPECT_EQ(m["chosen"]["solver.method"], "pbf");
  EXPECT_EQ(m["chosen"]["solver.iterations"], 2);
  r = run_pbflow("run --no-render --param particle_spacing=0.04 --frames 1 --param camera.eye=[3,2,4]"
                 " --param solver.substeps=3 --method ldc --iterations 1 --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("ldc with 1 iteration(s), 3 substeps per frame, on"), std::string::npos) << r.output;
  m = manifest(dir);
  EXPECT_FALSE(m["chosen"].contains("camera.eye")) << m.dump();
  EXPECT_FALSE(m["chosen"].contains("solver.substeps")) << m.dump();
  EXPECT_FALSE(m["chosen"].contains("solver.method")) << m.dump();
  EXPECT_FALSE(m["chosen"].contains("solver.iterations")) << m.dump();
  EXPECT_TRUE(m["chosen"].contains("camera.target")) << m.dump();
}

TEST(RunDirectory, AFailedWriteIsAnErrorNamingTheFileAndLeavesWholeRows) {
  fs::path dir = fresh_dir("efbig");
  // ulimit -f: past 8 KiB a write fails with EFBIG (pbflow ignores SIGXFSZ), ~80 rows in.
  Result r = run_pbflow("run --no-render --param particle_spacing=0.04 --quiet --frames 400 --out " + dir.string(),
                    "ulimit -f 8;");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("stats.csv: File too large"), std::string::npos) << r.output;
  std::vector<std::string> lines = rows(dir / "stats.csv");
  ASSERT_GT(lines.size(), 10u);
  EXPECT_LT(lines.size(), 400u);
  for (const std::string& line : lines) EXPECT_EQ(std::count(line.begin(), line.end(), ','), 14) << line;  // 15 columns
  std::ifstream raw(dir / "stats.csv", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(raw)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.back(), '\n') << "a row cut in the middle";
  json m = manifest(dir);
  EXPECT_EQ(m["status"], "failed");
  EXPECT_EQ(m["frames"]["completed"].get<size_t>(), lines.size() - 1);
}

TEST(RunDirectory, BadOptionsAndScenesAreRefusedBeforeTheDirectoryIsTouched) {
  fs::path dir = fresh_dir("options");
  struct Case {
    std::string args, expect;
  } cases[] = {
      {"run --no-render --out \"\"", "--out is empty"},
      {"run --no-render --video " + (dir / "v.mp4").string() + " --out " + dir.string(), "--video needs frames"},
      {"run " + fs::temp_directory_path().string() + " --no-render --out " + dir.string(), "not a regular file"},
      {"run /dev/zero --no-render --out " + dir.string(), "not a regular file"},
      {"bench --seconds -1 --out " + dir.string(), "--seconds"},
      {"bench --seconds nan --out " + dir.string(), "--seconds"},
      {"bench --seconds inf --out " + dir.string(), "--seconds"},
      {"bench --ldc-strength 0.5,nan --out " + dir.string(), "--ldc-strength"},
      {"bench --targets -inf --out " + dir.string(), "--targets"},
      {"bench --scaling --budget-minutes nan --out " + dir.string(), "--budget-minutes"},
      {"run --no-render --param particle_spacing=nan --out " + dir.string(), "particle_spacing"},
      {"run --no-render --param solver.ldc_strength=inf --out " + dir.string(), "ldc_strength"},
  };
  for (const Case& c : cases) {
    Result r = run_pbflow(c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << c.args << ": not one line: " << r.output;
    EXPECT_FALSE(fs::exists(dir)) << c.args << " wrote output despite bad input";
  }
}

TEST(RunDirectory, ARunTooLargeForTheMemoryIsRefusedWithTheNumbers) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "under AddressSanitizer: its shadow memory cannot be mapped inside the address-space limit this test sets";
#endif
  fs::path dir = fresh_dir("memory");
  // About 30 million particles for the reference solver under a 3 GB address space.
  Result r = run_pbflow("run --device cpu --no-render --param particle_spacing=0.002 --out " + dir.string(),
                    "ulimit -v 3000000;");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("the run needs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("GiB available"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir));
}

// Neighbour lists past the device's storage buffer range are left out, not refused: the
// passes then walk their cells. llvmpipe's range is 128 MiB, one list of 72 entries for
// ~460k particles.
TEST(RunDirectorySlow, ListsPastTheBufferRangeAreLeftOutAndTheRunFits) {
  const pbflow::Derived d = pbflow::derive(pbflow::load_scene("dam_break"));
  pbflow::vk::DeviceInfo device;
  device.max_storage_buffer_range = 128ull << 20;
  EXPECT_EQ(pbflow::neighbour_capacity_on(d, 400000, device), d.neighbour_capacity);
  EXPECT_EQ(pbflow::neighbour_capacity_on(d, 640000, device), 0u);
  const pbflow::MemoryNeed need = pbflow::memory_need(d, 640000, &device);
  EXPECT_LE(need.largest_array, device.max_storage_buffer_range);
  EXPECT_LT(need.device, pbflow::memory_need(d, 400000, &device).device * 640 / 400) << "lists counted";

  // And the run itself on this machine's device (633k particles, validated): the start's 40
  // relaxations and one step, every neighbour pass walking its cells (the scene's 7 substeps
  // cost 38 s more on lavapipe and walk no other pass).
  fs::path dir = fresh_dir("no_lists");
  Result r = run_pbflow("run --no-render --frames 2 --validate --param particle_spacing=0.0058 "
                        "--param solver.substeps=1 --out " + dir.string());
  EXPECT_EQ(r.status, 0) << r.output;
}

// Where solids move, solids.csv gives each frame's pose of the tank and of every obstacle in the
// world (a unit quaternion w, x, y, z), listed in the manifest; a run whose solids stand still
// writes none, and takes the previous run's away.
TEST(RunDirectory, MovingSolidsPosesAreWrittenForARendererElsewhere) {
  const fs::path dir = fresh_dir("solids");
  const std::vector<std::string> base = {"run", "hydrostatic", "--no-render", "--quiet", "--frames", "3", "--param",
                                         "particle_spacing=0.05", "--param", "settle=false", "--out", dir.string()};
  std::vector<std::string> turning = base;
  turning.insert(turning.end(), {"--param", R"(obstacles=[{"type": "box", "min": [0.2, 0, 0.2], "max": [0.4, 0.1, 0.4],
                                                           "motion": {"type": "rotate", "axis": [0, 1, 0], "rate": 90}}])"});
  Result r = run_pbflow(turning);
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<std::string> lines = rows(dir / "solids.csv");
  ASSERT_EQ(lines.size(), 7u) << "a header and the tank and the box each frame";
  EXPECT_EQ(lines[0], "frame,time,solid,x,y,z,qw,qx,qy,qz");
  double frame, time, x, y, z, qw, qx, qy, qz;
  char solid[16];
  ASSERT_EQ(std::sscanf(lines[6].c_str(), "%lf,%lf,%15[^,],%lf,%lf,%lf,%lf,%lf,%lf,%lf", &frame, &time, solid, &x, &y,
                        &z, &qw, &qx, &qy, &qz), 10);
  EXPECT_EQ(std::string(solid), "0");
  const double half = glm::radians(90.0 * 2 / 60) / 2;  // 90 degrees a second, 2 frames at 60 fps
  EXPECT_NEAR(qw, std::cos(half), 1e-6);
  EXPECT_NEAR(qy, std::sin(half), 1e-6);
  EXPECT_EQ(lines[5], "2,0.033333,tank,0,0,0,1,0,0,0") << "the tank stands still";
  EXPECT_NE(manifest(dir)["files"].dump().find("solids.csv"), std::string::npos);

  r = run_pbflow(base);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "solids.csv")) << "the still run left the previous run's poses";
}

TEST(RunDirectory, ACameraLookingStraightDownSeesTheFluid) {
  fs::path dir = fresh_dir("camera");
  Result r = run_pbflow("run" + kSmall + "--frames 1 --param camera.eye=[0.2,3,0.2] --param camera.target=[0.2,0,0.2] --out " +
                    dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  pbflow::capture::Image image = pbflow::capture::read_png(dir / "frames" / "frame_00000.png");
  size_t differs = 0;
  for (size_t p = 0; p < image.rgb.size(); p += 3)
    differs += image.rgb[p] != image.rgb[0] || image.rgb[p + 1] != image.rgb[1] || image.rgb[p + 2] != image.rgb[2];
  EXPECT_GT(differs, image.rgb.size() / 3 / 20) << "a blank frame: fewer than 5 % of the pixels show anything";
}

// Reading a scene is linear in its size: four times the obstacles take about four times as
// long, where the quadratic reader took sixteen (a ratio within one run, not a timing bound).
TEST(RunDirectory, SceneReadingIsLinearInTheObstacles) {
  auto scene_with = [](int n) {
    std::string s = R"({"domain": {"min": [0,0,0], "max": [1,1,1]}, "particle_spacing": 0.1,
      "fluid_blocks": [{"min": [0,0,0], "max": [0.5,0.5,0.5]}], "obstacles": [)";
    for (int i = 0; i < n; ++i)
      s += std::string(i ? "," : "") + R"({"type": "sphere", "centre": [0.8, 0.8, 0.8], "radius": 0.01})";
    return s + "]}";
  };
  auto seconds = [&](int n) {
    std::string text = scene_with(n);
    auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(pbflow::parse_scene(text, "obstacles").obstacles.size(), size_t(n));
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  seconds(1000);  // warm-up
  double small = seconds(20000), large = seconds(80000);
  EXPECT_LT(large / small, 10.0) << small << " s for 20 000 obstacles, " << large << " s for 80 000";
}

}  // namespace
