// The command line as scripts use it: stats.csv, exit statuses, GPU and CPU agreeing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "capture/png.hpp"
#include "capture/video.hpp"
#include "support.hpp"

namespace {

namespace fs = std::filesystem;

using Result = pbflow::test::CliResult;
using pbflow::test::fresh_dir;
using pbflow::test::read_csv;
using pbflow::test::run_pbflow;

TEST(Cli, GpuAndCpuWriteMatchingStats) {
  const std::string common = " run dam_break --no-render --frames 4 --param particle_spacing=0.04 --quiet --out ";
  fs::path gpu = fresh_dir("gpu"), cpu = fresh_dir("cpu");
  Result g = run_pbflow(common + gpu.string() + " --validate");
  ASSERT_EQ(g.status, 0) << g.output;
  Result c = run_pbflow(common + cpu.string() + " --device cpu");
  ASSERT_EQ(c.status, 0) << c.output;

  std::string header_g, header_c;
  auto rows_g = read_csv(gpu / "stats.csv", &header_g), rows_c = read_csv(cpu / "stats.csv", &header_c);
  EXPECT_EQ(header_g,
            "frame,time,mean_compression,max_compression,kinetic_energy,potential_energy,solid_work,max_speed,iterations,"
            "particles,emitted,drained,flow_energy,body_energy,step_ms");
  EXPECT_EQ(header_c, header_g);
  ASSERT_EQ(rows_g.size(), 4u);
  ASSERT_EQ(rows_c.size(), 4u);
  for (size_t f = 0; f < 4; ++f) {
    EXPECT_EQ(rows_g[f][0], double(f));
    EXPECT_NEAR(rows_g[f][1], f / 60.0, 1e-6);
    EXPECT_NEAR(rows_g[f][2], rows_c[f][2], 1e-4 + 0.02 * rows_c[f][2]) << "mean compression, frame " << f;
    EXPECT_NEAR(rows_g[f][4], rows_c[f][4], 1e-3 * rows_c[f][4] + 1e-9) << "kinetic energy, frame " << f;
    EXPECT_NEAR(rows_g[f][5], rows_c[f][5], 1e-5 * rows_c[f][5]) << "potential energy, frame " << f;
    EXPECT_EQ(rows_g[f][6], 0.0) << "solid work, frame " << f;  // nothing moves
    EXPECT_EQ(rows_c[f][6], 0.0) << "solid work, frame " << f;
    EXPECT_NEAR(rows_g[f][7], rows_c[f][7], 1e-3 * rows_c[f][7] + 1e-9) << "max speed, frame " << f;
    EXPECT_EQ(rows_g[f][8], f > 0 ? 2.0 : 0.0) << "iterations, frame " << f;  // the default two
    EXPECT_EQ(rows_c[f][8], rows_g[f][8]) << "iterations, frame " << f;
    if (f > 0) {
      EXPECT_GT(rows_g[f][9], 0.0) << "step_ms";
    }
  }
}

// A file's bytes, for comparing two runs' outputs exactly.
std::string bytes_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The reference solver is deterministic: two runs of one scene and seed write the same
// particles to the last bit and the same stats but for the timing column; another seed starts
// another jitter (docs/design.md, "Reproducibility"). run.json records the seed.
TEST(Cli, CpuRunsAreBitReproducibleAndTheSeedPicksTheStart) {
  const std::string common = " run dam_break --device cpu --no-render --export ply --frames 4 --quiet "
                             "--param particle_spacing=0.06 --out ";
  const fs::path a = fresh_dir("repro_a"), b = fresh_dir("repro_b"), other = fresh_dir("repro_seed");
  for (const auto& [dir, extra] : {std::pair{a, ""}, {b, ""}, {other, " --param seed=7"}}) {
    const Result r = run_pbflow(common + dir.string() + extra);
    ASSERT_EQ(r.status, 0) << r.output;
  }
  auto without_timing = [](const fs::path& csv) {
    std::istringstream in(bytes_of(csv));
    std::string kept;
    for (std::string line; std::getline(in, line);) kept += line.substr(0, line.rfind(',')) + "\n";
    return kept;
  };
  EXPECT_EQ(without_timing(a / "stats.csv"), without_timing(b / "stats.csv"));
  for (int frame = 0; frame < 4; ++frame) {
    const std::string name = "particles/frame_0000" + std::to_string(frame) + ".ply";
    EXPECT_EQ(bytes_of(a / name), bytes_of(b / name)) << name;
    if (frame == 0) {
      EXPECT_NE(bytes_of(a / name), bytes_of(other / name)) << "seed=7 started where the default did";
    }
  }
  EXPECT_NE(bytes_of(a / "run.json").find("\"seed\": 20261126"), std::string::npos);
  EXPECT_NE(bytes_of(other / "run.json").find("\"seed\": 7"), std::string::npos);
}

// GPU runs are bit-reproducible on one device, driver and binary: the grid's sort ranks a
// cell's particles by index, whatever order its atomics took, and white water's lists are
// placed by prefix sums. The same command twice, `pbflow diff` says equal: the dam break's
// stats, particles, white water and drawn frames, again with white water at a cap it reaches
// (which births are dropped is fixed too), and a settled tank's.
TEST(Cli, GpuRunsAreBitReproducible) {
  const std::string dam = " run dam_break --export ply --frames 20 --width 160 --height 96 --param particle_spacing=0.04";
  const std::vector<std::string> runs = {dam, dam + " --param white_water.max_particles=40",
                                         " run hydrostatic --no-render --export ply --frames 4 --param particle_spacing=0.04"};
  for (size_t k = 0; k < runs.size(); ++k) {
    const fs::path a = fresh_dir("gpu_repro_a" + std::to_string(k)), b = fresh_dir("gpu_repro_b" + std::to_string(k));
    for (const fs::path& dir : {a, b}) {
      const Result r = run_pbflow(runs[k] + " --quiet --out " + dir.string());
      ASSERT_EQ(r.status, 0) << r.output;
    }
    const Result same = run_pbflow(" diff " + a.string() + " " + b.string());
    EXPECT_EQ(same.status, 0) << runs[k] << ": " << same.output;
  }
}

// `pbflow diff` names the first difference and by how much: a particle's field, a stats cell,
// a missing frame; and refuses a directory that holds no run.
TEST(Cli, DiffNamesTheFirstDifference) {
  const fs::path a = fresh_dir("diff_a"), b = fresh_dir("diff_b");
  for (const fs::path& dir : {a, b}) {
    const Result r = run_pbflow(" run dam_break --device cpu --no-render --export ply --frames 3 --quiet "
                                "--param particle_spacing=0.06 --out " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  ASSERT_EQ(run_pbflow(" diff " + a.string() + " " + b.string()).status, 0);
  const fs::path ply = b / "particles" / "frame_00002.ply";
  std::string bytes = bytes_of(ply);
  const size_t body = bytes.find("end_header\n") + 11;
  bytes[body + 7 * 4 * 5 + 3] ^= 0x40;  // particle 5's x, its float's top byte
  std::ofstream(ply, std::ios::binary) << bytes;
  Result r = run_pbflow(" diff " + a.string() + " " + b.string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("particles/frame_00002.ply: particle 5"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" x "), std::string::npos) << r.output;
  fs::remove(ply);
  r = run_pbflow(" diff " + a.string() + " " + b.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("frame_00002.ply is in one run only"), std::string::npos) << r.output;
  std::string stats = bytes_of(b / "stats.csv");
  stats[stats.find('\n', stats.find('\n') + 1) + 10] ^= 1;  // a digit of frame 1's row
  std::ofstream(b / "stats.csv", std::ios::binary) << stats;
  r = run_pbflow(" diff " + a.string() + " " + b.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("stats.csv: frame 1"), std::string::npos) << r.output;
  r = run_pbflow(" diff " + a.string() + " " + fresh_dir("diff_none").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("not a run directory"), std::string::npos) << r.output;
}

TEST(Cli, BadInputExitsWithStatus2AndOneLine) {
  fs::path dir = fresh_dir("bad");
  fs::create_directories(dir);
  std::ofstream(dir / "broken.json") << "{\"domain\": {\"min\": [0,0,0], \"max\": [1,1,1]},";
  std::ofstream(dir / "unknown.json")
      << R"({"domain": {"min": [0,0,0], "max": [1,1,1]}, "particle_spacing": 0.1, "fluid_blocks": [{"min": [0,0,0], "max": [0.5,0.5,0.5]}], "solver": {"iterationz": 2}})";
  struct Case {
    std::string args, expect;
  } cases[] = {
      {"run " + (dir / "broken.json").string(), "JSON syntax error"},
      {"run " + (dir / "unknown.json").string(), "solver.iterationz"},
      {"run no_such_scene", "no_such_scene"},
      {"run --param particle_spacing=-1", "particle_spacing"},
      {"run --param solver.bogus=1", "solver.bogus"},
      {"run --method sph", "--method"},
      {"run --device 99", "--device 99"},
      {"run --device banana", "--device"},
  };
  for (const Case& c : cases) {
    Result r = run_pbflow(c.args + " --no-render --frames 2 --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / "out" / "stats.csv")) << c.args << " wrote output despite bad input";
  }
}

TEST(Cli, FramesAreCompletePngsOfTheRequestedSize) {
  fs::path dir = fresh_dir("frames");
  Result r = run_pbflow("run dam_break --frames 3 --width 160 --height 96 --style particles --validate --quiet"
                    " --param particle_spacing=0.04 --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir / "frames")) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"frame_00000.png", "frame_00001.png", "frame_00002.png"}));
  for (const std::string& name : names) {
    pbflow::capture::Image image = pbflow::capture::read_png(dir / "frames" / name);
    EXPECT_EQ(image.width, 160) << name;
    EXPECT_EQ(image.height, 96) << name;
  }
}

TEST(Cli, BadRenderOptionsExitWithStatus2AndWriteNothing) {
  fs::path dir = fresh_dir("bad_render");
  struct Case {
    std::string args, env, expect;
  } cases[] = {
      {"--style watercolour", "", "--style"},
      {"--width 4", "", "--width"},
      {"--video " + (dir / "v.mp4").string(), "PATH=/nonexistent", "ffmpeg"},
      {"--video " + (dir / "v.gif").string(), "", ".mp4, .mkv or .mov"},
      {"--video " + (dir / "folder.mp4").string(), "", "is a directory"},
  };
  fs::create_directories(dir / "folder.mp4");
  for (const Case& c : cases) {
    Result r = run_pbflow("run --frames 2 --param particle_spacing=0.04 --out " + (dir / "out").string() + " " + c.args,
                      c.env);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / "out")) << c.args << " wrote output despite bad input";
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "a temporary was left beside --out";
}

TEST(Cli, VideoHoldsEveryFrame) {
  if (pbflow::capture::find_ffmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed (scripts/setup.sh installs it)";
  fs::path dir = fresh_dir("video");
  Result r = run_pbflow("run --frames 5 --width 160 --height 96 --quiet --param particle_spacing=0.04 --out " +
                    dir.string() + " --video " + (dir / "clip" / "dam.mp4").string());
  ASSERT_EQ(r.status, 0) << r.output;
  Result probe = {0, ""};
  std::string cmd = "ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=width,height,nb_read_frames"
                    " -of csv=p=0 " + (dir / "clip" / "dam.mp4").string();
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char line[256] = {};
  if (std::fgets(line, sizeof line, pipe)) probe.output = line;
  pclose(pipe);
  EXPECT_EQ(probe.output, "160,96,5\n");
  for (const auto& entry : fs::directory_iterator(dir / "clip"))
    EXPECT_EQ(entry.path().filename(), "dam.mp4") << "left behind: " << entry.path();
}

// Files beside the video that merely look like its temporary, and another run's video of
// the same name in progress, are never pbflow's to remove.
TEST(Cli, AVideoRunRemovesNothingBesideItsVideo) {
  if (pbflow::capture::find_ffmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed (scripts/setup.sh installs it)";
  fs::path dir = fresh_dir("video_neighbours");
  fs::create_directories(dir / "clip");
  const std::vector<std::string> mine = {"dam.mp4.part1234.mp4", "dam.mp4.partial-notes.txt", "dam.mp4.part"};
  for (const std::string& name : mine) std::ofstream(dir / "clip" / name) << "mine\n";
  for (const char* out : {"a", "a", "b"}) {
    Result r = run_pbflow("run --frames 3 --width 64 --height 32 --style particles --quiet --param particle_spacing=0.04 "
                          "--out " + (dir / out).string() + " --video " + (dir / "clip" / "dam.mp4").string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  for (const std::string& name : mine) EXPECT_TRUE(fs::exists(dir / "clip" / name)) << name << " was removed";
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "clip"), fs::directory_iterator()), 4) << "a temporary was left";
}

// Nesting past any scene's is refused with one line, from a file and from --param alike:
// 100 000 levels overflowed the stack when the resolved scene was serialised.
TEST(Cli, DeeplyNestedJsonIsRefusedNotACrash) {
  fs::path dir = fresh_dir("nested");
  fs::create_directories(dir);
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  std::ofstream(dir / "deep.json") << R"({"domain": {"min": [0,0,0], "max": [1,1,1]}, "particle_spacing": 0.1,)"
                                   << R"("fluid_blocks": [{"min": [0,0,0], "max": [0.5,0.5,0.5]}], "description": )"
                                   << deep << "}";
  const std::string shallow = std::string(30000, '[') + std::string(30000, ']');  // one argument holds 128 KiB
  for (const std::string& args : {(dir / "deep.json").string(), "dam_break --param description=" + shallow,
                                   "dam_break --param solver.iterations=" + shallow}) {
    Result r = run_pbflow("run " + args + " --no-render --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << r.output.substr(0, 300);
    EXPECT_NE(r.output.find("nested deeper than 64 levels"), std::string::npos) << r.output.substr(0, 300);
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output.substr(0, 300);
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
}

// tests/broken_scenes/: every file exits 2 with one line naming its problem, and
// writes nothing. MESSAGES pairs each file with a piece of the message it must give.
TEST(Cli, EveryBrokenSceneOfTheCorpusIsRefusedByName) {
  const fs::path corpus = fs::path(PBFLOW_TEST_DATA) / "broken_scenes";
  std::ifstream manifest(corpus / "MESSAGES");
  ASSERT_TRUE(manifest) << "no MESSAGES in " << corpus;
  size_t checked = 0;
  for (std::string line; std::getline(manifest, line);) {
    if (line.empty() || line[0] == '#') continue;
    size_t tab = line.find('\t');
    ASSERT_NE(tab, std::string::npos) << line;
    std::string file = line.substr(0, tab), expect = line.substr(tab + 1);
    fs::path out = fresh_dir("broken_" + file);  // no --frames: it would mend fractional_frames.json
    Result r = run_pbflow("run " + (corpus / file).string() + " --no-render --out " + out.string());
    EXPECT_EQ(r.status, 2) << file << ": " << r.output;
    EXPECT_NE(r.output.find(expect), std::string::npos) << file << " should say '" << expect << "': " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << file << ": not one line: " << r.output;
    EXPECT_FALSE(fs::exists(out)) << file << " wrote output despite bad input";
    ++checked;
  }
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(corpus)) files += entry.path().extension() == ".json";
  EXPECT_EQ(checked, files) << "every broken scene needs a line in MESSAGES";
}

TEST(Cli, ParamOverridesReachTheSolver) {
  fs::path dir = fresh_dir("param");
  Result r = run_pbflow("run dam_break --no-render --frames 2 --param particle_spacing=0.04 "
                    "--param solver.iterations=3 --param solver.method=pbf --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("2000 particles, pbf with 3 iteration(s)"), std::string::npos) << r.output;
}

TEST(Cli, OutputDirectoryIsReusedOnlyForPbflowsOwnFiles) {
  fs::path dir = fresh_dir("reuse");
  const std::string run = "run --style particles --width 64 --height 32 --quiet --param particle_spacing=0.04 --out " +
                          dir.string() + " --frames ";
  ASSERT_EQ(run_pbflow(run + "4").status, 0);
  ASSERT_EQ(run_pbflow(run + "2").status, 0);  // a shorter run into the same directory
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_00001.png"));
  EXPECT_FALSE(fs::exists(dir / "frames" / "frame_00002.png")) << "a stale frame of the longer run survived";

  std::ofstream(dir / "frames" / "holiday.jpg") << "not ours";
  Result r = run_pbflow(run + "2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("holiday.jpg"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir / "frames" / "holiday.jpg"));
}

TEST(Cli, ATimeStepTooLargeForTheSpacingIsWarnedAbout) {
  fs::path dir = fresh_dir("cfl");
  Result coarse = run_pbflow("run --no-render --frames 2 --quiet --param solver.substeps=1 --out " + dir.string());
  EXPECT_EQ(coarse.status, 0) << coarse.output;
  EXPECT_NE(coarse.output.find("warning: dt"), std::string::npos) << coarse.output;
  EXPECT_NE(coarse.output.find("solver.substeps=2"), std::string::npos) << coarse.output;
  Result fine = run_pbflow("run --no-render --frames 2 --quiet --out " + dir.string());
  EXPECT_EQ(fine.output.find("warning"), std::string::npos) << "the default scene is within the limit: " << fine.output;
}

}  // namespace
