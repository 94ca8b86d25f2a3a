// `pbflow bench`: the quick study finishes every run with the promised columns and
// charts; the chart script draws its PNGs from a small CSV fixture; the scaling bench
// measures each count with its pass split and fit. No timing asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "bench/scaling.hpp"
#include "bench/study.hpp"
#include "support.hpp"
#include "capture/png.hpp"
#include "sim/solver.hpp"

namespace pbflow {
namespace {

namespace fs = std::filesystem;

// Splits one CSV line, honouring quoted cells.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (c == '"' && quoted && i + 1 < line.size() && line[i + 1] == '"') out.back() += c, ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

std::vector<std::vector<std::string>> read_csv(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(cells(line));
  return rows;
}

const char* kCharts[] = {"accuracy_vs_cost.png", "time_per_step.png", "compression_over_time.png",
                         "kinetic_energy.png"};

void expect_charts(const fs::path& dir) {
  for (const char* chart : kCharts) {
    capture::Image image = capture::read_png(dir / chart);  // throws unless a complete PNG
    EXPECT_GT(image.width, 300) << chart;
    EXPECT_GT(image.height, 200) << chart;
  }
}

TEST(BenchSlow, QuickStudyFinishesEveryRunWithItsColumnsAndCharts) {
  PBFLOW_NEEDS_PYTHON("matplotlib", "scripts/setup.sh installs python3-matplotlib");
  fs::path dir = fs::temp_directory_path() / "pbflow_test_bench";
  fs::remove_all(dir);
  std::string cmd = std::string(PBFLOW_BINARY) + " bench --quick --out " + dir.string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  auto runs = read_csv(dir / "runs.csv");
  ASSERT_FALSE(runs.empty());
  EXPECT_EQ(runs[0], bench::run_columns());
  EXPECT_EQ(runs.size(), 1u + 2 * 2 * 3) << "2 scenes x 2 methods x 3 iteration counts";
  auto column = [&](const std::string& name) {
    return size_t(std::find(runs[0].begin(), runs[0].end(), name) - runs[0].begin());
  };
  for (size_t r = 1; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].size(), runs[0].size()) << "row " << r;
    // Cost columns are finite numbers; accuracy columns are numbers (pbf@1 may blow up: that is data).
    for (size_t c = 3; c < runs[r].size(); ++c) {
      if (c == column("method")) continue;
      if (c == column("class")) {
        EXPECT_TRUE(runs[r][c] == "stable" || runs[r][c] == "compressed" || runs[r][c] == "gains energy" ||
                    runs[r][c] == "diverged")
            << runs[r][c];
        EXPECT_EQ(runs[r][c] == "gains energy", runs[r][column("diverged")] == "0" &&
                                                    std::stod(runs[r][column("energy_gain")]) > 0.01)
            << "row " << r;
        EXPECT_EQ(runs[r][c] == "diverged", runs[r][column("diverged")] == "1") << "row " << r;
        continue;
      }
      double v = std::stod(runs[r][c]);
      if (c <= column("particle_steps_per_s")) {
        EXPECT_TRUE(std::isfinite(v)) << runs[0][c] << ", row " << r;
      }
    }
    EXPECT_GT(std::stod(runs[r][column("step_ms_mean")]), 0.0);
    EXPECT_GT(std::stod(runs[r][column("constraints_ms")]), 0.0) << "per-pass timestamps missing";
    EXPECT_EQ(std::stod(runs[r][column("correction_ms")]) > 0, runs[r][column("method")] == "ldc")
        << "only ldc runs the correction pass";
  }
  auto series = read_csv(dir / "series.csv");
  EXPECT_EQ(series[0], (std::vector<std::string>{"run", "frame", "time", "mean_compression", "max_compression",
                                                 "kinetic_energy", "potential_energy"}));
  // 61 frames (1 s at 60 fps, frame 0 included) per run; a run stopped as diverged has
  // the frames up to its stop, as its simulated_s says.
  std::map<std::string, int> frames;
  for (size_t k = 1; k < series.size(); ++k) frames[series[k][0]]++;
  for (size_t r = 1; r < runs.size(); ++r) {
    int expected = int(std::lround(std::stod(runs[r][column("simulated_s")]) * 60)) + 1;
    EXPECT_EQ(frames[runs[r][0]], expected) << "run " << runs[r][0];
    if (runs[r][column("diverged")] == "0") {
      EXPECT_EQ(expected, 61) << "run " << runs[r][0];
    }
  }
  expect_charts(dir);
  EXPECT_GT(capture::read_png(dir / "accuracy_vs_cost.png").height, 800) << "the energy gain's row of panels";
  // cheapest.md: a row for each scene, count and target (5, 2, 1, 0.5 %), each naming a
  // setting of the study or none.
  std::ifstream cheapest(dir / "cheapest.md");
  int rows = 0;
  for (std::string line; std::getline(cheapest, line);)
    if (line.rfind("| dam_break |", 0) == 0 || line.rfind("| hydrostatic |", 0) == 0) {
      ++rows;
      EXPECT_TRUE(line.find("@") != std::string::npos || line.find("none of the runs") != std::string::npos) << line;
    }
  EXPECT_EQ(rows, 2 * 4) << "2 scenes x 1 count x 4 targets";
}

// Copies fixtures/<name>/ to a fresh directory and runs the chart script there.
fs::path charts_from_fixture(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("pbflow_test_charts_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* f : {"runs.csv", "series.csv"})
    fs::copy_file(fs::path(PBFLOW_TEST_DATA) / "fixtures" / name / f, dir / f);
  const fs::path script = fs::path(PBFLOW_TEST_DATA).parent_path() / "bench" / "charts.py";
  std::string cmd = "/usr/bin/python3 " + script.string() + " " + dir.string();
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return dir;
}

TEST(Bench, ChartScriptDrawsFromAFixture) {
  PBFLOW_NEEDS_PYTHON("matplotlib", "scripts/setup.sh installs python3-matplotlib");
  expect_charts(charts_from_fixture("bench"));
}

TEST(Bench, ChartScriptDrawsStabilityMapsFromAFixture) {
  PBFLOW_NEEDS_PYTHON("matplotlib", "scripts/setup.sh installs python3-matplotlib");
  fs::path dir = charts_from_fixture("stability");
  for (const char* map : {"stability_pbf.png", "stability_ldc.png"}) {
    capture::Image image = capture::read_png(dir / map);
    EXPECT_GT(image.width, 300) << map;
  }
  EXPECT_FALSE(fs::exists(dir / "accuracy_vs_cost.png")) << "a stability study draws only its maps";
  EXPECT_FALSE(fs::exists(dir / "pareto.png")) << "a study without the energy gain draws no front";
}

// A study over substeps (the H200's iterations-or-substeps study): the front per scene and
// count with the energy gain below it, the maps, and cheapest.md's rows.
TEST(Bench, ChartScriptDrawsTheFrontOverSubstepsFromAFixture) {
  PBFLOW_NEEDS_PYTHON("matplotlib", "scripts/setup.sh installs python3-matplotlib");
  fs::path dir = charts_from_fixture("pareto");
  capture::Image front = capture::read_png(dir / "pareto.png");
  EXPECT_GT(front.width, 1000) << "a panel per particle count";
  EXPECT_GT(front.height, 800) << "the energy gain's row of panels";
  for (const char* map : {"stability_pbf.png", "stability_ldc.png"}) EXPECT_TRUE(fs::exists(dir / map)) << map;
  std::ifstream cheapest(dir / "cheapest.md");
  int rows = 0;
  for (std::string line; std::getline(cheapest, line);) rows += line.rfind("| dam_break |", 0) == 0;
  EXPECT_EQ(rows, 2 * 4) << "2 counts x 4 targets";
}

// --scaling at three small counts: a row per count with the promised columns, per-pass
// times that make up the step, device memory per particle that does not depend on the
// count, one fit shared by every row, the printed table and the chart. Nothing about speed.
TEST(BenchSlow, ScalingMeasuresEveryCountWithItsSplitAndFit) {
  PBFLOW_NEEDS_PYTHON("matplotlib", "scripts/setup.sh installs python3-matplotlib");
  fs::path dir = fs::temp_directory_path() / "pbflow_test_scaling";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string cmd = std::string(PBFLOW_BINARY) + " bench --scaling --counts 2000,4000,8000 --seconds 0.02 --out " +
                    dir.string() + " > " + (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::stringstream printed;
  printed << std::ifstream(dir / "stdout.txt").rdbuf();
  EXPECT_NE(printed.str().find("fit: "), std::string::npos) << printed.str();

  auto rows = read_csv(dir / "scaling.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], bench::scaling_columns());
  auto at = [&](size_t r, const std::string& name) {
    return std::stod(rows[r][size_t(std::find(rows[0].begin(), rows[0].end(), name) - rows[0].begin())]);
  };
  const double wanted[] = {2000, 4000, 8000};
  for (size_t r = 1; r < rows.size(); ++r) {
    ASSERT_EQ(rows[r].size(), rows[0].size());
    EXPECT_NEAR(at(r, "particles") / wanted[r - 1], 1.0, 0.2) << "row " << r;
    EXPECT_GT(at(r, "step_ms"), 0.0);
    double passes = 0;
    for (const char* p : kPassGroupNames) passes += at(r, std::string(p) + "_ms");
    EXPECT_NEAR(passes / at(r, "step_ms"), 1.0, 0.1) << "the pass groups make up the step, row " << r;
    EXPECT_GT(at(r, "coarse_ms"), 0.0) << "dam_break runs pbf@2, with the coarse correction";
    EXPECT_NEAR(at(r, "particle_steps_per_s"), at(r, "particles") / (at(r, "step_ms") * 1e-3),
                1e-4 * at(r, "particle_steps_per_s"));
    EXPECT_NEAR(at(r, "device_bytes_per_particle") / at(1, "device_bytes_per_particle"), 1.0, 0.25) << "row " << r;
    for (const char* fit : {"fit_intercept_ms", "fit_ms_per_particle", "loglog_slope"}) {
      EXPECT_EQ(at(r, fit), at(1, fit)) << fit;
      EXPECT_TRUE(std::isfinite(at(r, fit))) << fit;
    }
  }
  EXPECT_GT(at(1, "device_bytes_per_particle"), 100.0);
  EXPECT_GT(capture::read_png(dir / "scaling.png").width, 300);
}

TEST(BenchSlow, ScalingRefusesWhatItCannotMeasure) {
  for (const char* args : {"--counts 4000,2000", "--scenes dam_break,drop", "--iterations 1,2", "--stability"}) {
    fs::path dir = fs::temp_directory_path() / "pbflow_test_scaling_bad";
    fs::remove_all(dir);
    std::string cmd = std::string(PBFLOW_BINARY) + " bench --scaling " + args + " --out " + dir.string() + " > /dev/null 2>&1";
    int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << cmd;
    EXPECT_FALSE(fs::exists(dir / "scaling.csv")) << cmd;
  }
}

}  // namespace
}  // namespace pbflow
