// The command line as scripts use it: stats.csv, exit statuses, GPU and CPU agreeing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Result {
  int status;
  std::string output;
};

Result pbflow(const std::string& args) {
  fs::path log = fs::temp_directory_path() / ("pbflow_cli_" + std::to_string(::getpid()) + ".log");
  std::string cmd = std::string(PBFLOW_BINARY) + " " + args + " > " + log.string() + " 2>&1";
  int raw = std::system(cmd.c_str());
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  fs::remove(log);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text.str()};
}

std::vector<std::vector<double>> read_csv(const fs::path& path, std::string* header) {
  std::ifstream in(path);
  std::getline(in, *header);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

fs::path fresh_dir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("pbflow_test_" + name);
  fs::remove_all(dir);
  return dir;
}

TEST(Cli, GpuAndCpuWriteMatchingStats) {
  const std::string common = " run dam_break --no-render --frames 4 --param particle_spacing=0.04 --quiet --out ";
  fs::path gpu = fresh_dir("gpu"), cpu = fresh_dir("cpu");
  Result g = pbflow(common + gpu.string() + " --validate");
  ASSERT_EQ(g.status, 0) << g.output;
  Result c = pbflow(common + cpu.string() + " --device cpu");
  ASSERT_EQ(c.status, 0) << c.output;

  std::string header_g, header_c;
  auto rows_g = read_csv(gpu / "stats.csv", &header_g), rows_c = read_csv(cpu / "stats.csv", &header_c);
  EXPECT_EQ(header_g, "frame,time,mean_compression,max_compression,kinetic_energy,max_speed,step_ms");
  EXPECT_EQ(header_c, header_g);
  ASSERT_EQ(rows_g.size(), 4u);
  ASSERT_EQ(rows_c.size(), 4u);
  for (size_t f = 0; f < 4; ++f) {
    EXPECT_EQ(rows_g[f][0], double(f));
    EXPECT_NEAR(rows_g[f][1], f / 60.0, 1e-6);
    EXPECT_NEAR(rows_g[f][2], rows_c[f][2], 1e-4 + 0.02 * rows_c[f][2]) << "mean compression, frame " << f;
    EXPECT_NEAR(rows_g[f][4], rows_c[f][4], 1e-3 * rows_c[f][4] + 1e-9) << "kinetic energy, frame " << f;
    EXPECT_NEAR(rows_g[f][5], rows_c[f][5], 1e-3 * rows_c[f][5] + 1e-9) << "max speed, frame " << f;
    if (f > 0) {
      EXPECT_GT(rows_g[f][6], 0.0) << "step_ms";
    }
  }
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
    Result r = pbflow(c.args + " --no-render --frames 2 --out " + (dir / "out").string());
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir / "out" / "stats.csv")) << c.args << " wrote output despite bad input";
  }
}

}  // namespace
