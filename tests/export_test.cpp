// Particle files parse back (with readers written here, from the formats' specs) to
// the particles that were written, in id order.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "capture/particle_export.hpp"
#include "io/frame_files.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "scene/seeding.hpp"
#include "sim/reference_solver.hpp"
#include "sim/settle.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

namespace fs = std::filesystem;

// Rows of x y z vx vy vz density.
using Rows = std::vector<std::array<float, 7>>;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Rows read_ply(const fs::path& path) {
  std::string data = slurp(path);
  size_t end = data.find("end_header\n");
  if (end == std::string::npos) throw std::runtime_error("no PLY header");
  std::stringstream header(data.substr(0, end));
  std::string line, expect_props = "x y z vx vy vz density", props;
  size_t count = 0;
  std::getline(header, line);
  EXPECT_EQ(line, "ply");
  while (std::getline(header, line)) {
    std::stringstream words(line);
    std::string word, a, b;
    words >> word;
    if (word == "format") {
      words >> a;
      EXPECT_EQ(a, "binary_little_endian");
    } else if (word == "element") {
      words >> a >> count;
      EXPECT_EQ(a, "vertex");
    } else if (word == "property") {
      words >> a >> b;
      EXPECT_EQ(a, "float");
      props += (props.empty() ? "" : " ") + b;
    }
  }
  EXPECT_EQ(props, expect_props);
  const char* body = data.data() + end + std::strlen("end_header\n");
  EXPECT_EQ(data.size() - size_t(body - data.data()), count * 7 * sizeof(float)) << "PLY body size";
  Rows rows(count);
  std::memcpy(rows.data(), body, std::min(data.size() - size_t(body - data.data()), count * 7 * sizeof(float)));
  return rows;
}

// Reads the value of attribute `name` in the first element starting with `tag` after `from`.
std::string attribute(const std::string& xml, const std::string& tag, const std::string& name, size_t from = 0) {
  size_t at = xml.find(tag, from);
  size_t end = xml.find('>', at);
  size_t key = xml.find(" " + name + "=\"", at);
  if (at == std::string::npos || key == std::string::npos || key > end) return "";
  key += name.size() + 3;
  return xml.substr(key, xml.find('"', key) - key);
}

Rows read_vtp(const fs::path& path) {
  std::string data = slurp(path);
  EXPECT_EQ(attribute(data, "<VTKFile", "byte_order"), "LittleEndian");
  EXPECT_EQ(attribute(data, "<VTKFile", "header_type"), "UInt32");
  size_t n = std::stoul(attribute(data, "<Piece", "NumberOfPoints"));
  size_t appended = data.find('_', data.find("<AppendedData encoding=\"raw\">")) + 1;
  auto array = [&](const std::string& start_tag, size_t components) {
    size_t offset = std::stoul(attribute(data, start_tag, "offset"));
    uint32_t bytes = 0;
    std::memcpy(&bytes, data.data() + appended + offset, 4);
    EXPECT_EQ(bytes, n * components * sizeof(float)) << start_tag;
    std::vector<float> values(n * components);
    std::memcpy(values.data(), data.data() + appended + offset + 4, values.size() * sizeof(float));
    return values;
  };
  auto points = array("<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"", 3);
  auto velocity = array("<DataArray type=\"Float32\" Name=\"velocity\"", 3);
  auto density = array("<DataArray type=\"Float32\" Name=\"density\"", 1);
  Rows rows(n);
  for (size_t i = 0; i < n; ++i)
    rows[i] = {points[3 * i], points[3 * i + 1], points[3 * i + 2], velocity[3 * i], velocity[3 * i + 1],
               velocity[3 * i + 2], density[i]};
  return rows;
}

// A frame in a shuffled order (as the GPU keeps it); its rows in id order.
ParticleFrame shuffled_frame(size_t n, Rows& by_id) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2, 2);
  by_id.resize(n);
  for (auto& r : by_id)
    for (float& v : r) v = u(rng);
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), rng);
  ParticleFrame f;
  for (uint32_t id : order) {
    const auto& r = by_id[id];
    f.x.emplace_back(r[0], r[1], r[2], 0.0f);
    f.v.emplace_back(r[3], r[4], r[5], 0.0f);
    f.rho.push_back(r[6]);
    f.id.push_back(id);
  }
  return f;
}

TEST(Export, PlyAndVtpReadBackToTheParticlesWritten) {
  fs::path dir = test::fresh_dir("export");
  fs::create_directories(dir);
  Rows expected;
  ParticleFrame f = shuffled_frame(777, expected);
  capture::write_particles(dir / "a.ply", capture::ExportFormat::Ply, f);
  capture::write_particles(dir / "a.vtp", capture::ExportFormat::Vtk, f);
  EXPECT_EQ(read_ply(dir / "a.ply"), expected);
  EXPECT_EQ(read_vtp(dir / "a.vtp"), expected);
  size_t files = std::distance(fs::directory_iterator(dir), fs::directory_iterator());
  EXPECT_EQ(files, 2u) << "temporary files left behind";
}

// VTK's own reader (tests/tools/read_vtp.py, Debian's python3-vtk9) sees every particle as a
// vertex cell, so ParaView shows them at its defaults, with each array's range as written.
TEST(Export, VtpOpensInVtksOwnReaderWithAVertexPerParticle) {
  PBFLOW_NEEDS_PYTHON("vtk", "scripts/setup.sh --test installs python3-vtk9");
  fs::path dir = test::fresh_dir("export_vtk");
  fs::create_directories(dir);
  Rows expected;
  ParticleFrame f = shuffled_frame(777, expected);
  capture::write_particles(dir / "a.vtp", capture::ExportFormat::Vtk, f);
  const fs::path json = dir / "seen.json";
  const std::string cmd = std::string("/usr/bin/python3 ") + PBFLOW_TEST_DATA + "/tools/read_vtp.py " +
                          (dir / "a.vtp").string() + " > " + json.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << " (python3-vtk9 is installed by scripts/setup.sh --test)";
  const nlohmann::json seen = nlohmann::json::parse(slurp(json));
  EXPECT_EQ(seen["points"], 777);
  EXPECT_EQ(seen["verts"], 777);
  EXPECT_EQ(seen["cells"], 777);
  auto expect_range = [&](const std::string& name, int column, int component) {
    float low = expected[0][column], high = low;
    for (const auto& r : expected) low = std::min(low, r[column]), high = std::max(high, r[column]);
    const auto& range = seen["arrays"][name]["range"][component];
    EXPECT_EQ(range[0].get<double>(), double(low)) << name << " component " << component;
    EXPECT_EQ(range[1].get<double>(), double(high)) << name << " component " << component;
    EXPECT_EQ(seen["arrays"][name]["tuples"], 777) << name;
  };
  for (int c = 0; c < 3; ++c) expect_range("velocity", 3 + c, c);
  expect_range("density", 6, 0);
  EXPECT_FALSE(seen["arrays"].contains("id")) << "ids only where particles come and go";
  // With the ids (a scene with emitters or drains): gapped ids, as a drain leaves them, read back whole.
  for (uint32_t& id : f.id) id = 3 * id + 16777217u;  // past float's exact integers
  capture::write_particles(dir / "b.vtp", capture::ExportFormat::Vtk, f, true);
  const std::string with_ids = std::string("/usr/bin/python3 ") + PBFLOW_TEST_DATA + "/tools/read_vtp.py " +
                               (dir / "b.vtp").string() + " > " + json.string();
  ASSERT_EQ(std::system(with_ids.c_str()), 0) << with_ids;
  const nlohmann::json ids = nlohmann::json::parse(slurp(json))["arrays"]["id"];
  EXPECT_EQ(ids["tuples"], 777);
  EXPECT_EQ(ids["range"][0][0].get<double>(), 16777217.0);
  EXPECT_EQ(ids["range"][0][1].get<double>(), 16777217.0 + 3 * 776);
}

TEST(Export, FrameNamesSortInFrameOrder) {
  EXPECT_EQ(capture::frame_file("d", 7, 240, "ply"), fs::path("d/frame_00007.ply"));
  EXPECT_EQ(capture::frame_file("d", 7, 200000, "png"), fs::path("d/frame_000007.png"));
  EXPECT_EQ(capture::frame_file("d", 123456, 200000, "png"), fs::path("d/frame_123456.png"));
}

TEST(Export, RunWritesOneFilePerFrameStartingFromTheInitialLattice) {
  fs::path dir = test::fresh_dir("export_run");
  for (const char* format : {"ply", "vtk"}) {  // a directory each: a run replaces the previous run's files
    std::string cmd = std::string(PBFLOW_BINARY) + " run dam_break --no-render --frames 3 --quiet --validate" +
                      " --param particle_spacing=0.04 --export " + format + " --out " + (dir / format).string();
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  Scene scene = load_scene("dam_break", {"particle_spacing=0.04"});
  ReferenceSolver start(derive(scene), initial_particles(scene));  // the start relaxed, as the run starts
  relax_start(start);
  const std::vector<glm::dvec3> x0 = start.download().x;
  for (int frame = 0; frame < 3; ++frame) {
    Rows ply = read_ply(capture::frame_file(dir / "ply" / "particles", frame, 3, "ply"));
    Rows vtp = read_vtp(capture::frame_file(dir / "vtk" / "particles", frame, 3, "vtp"));
    ASSERT_EQ(ply.size(), x0.size());
    // Two runs: GPU atomics order sums differently from run to run, so they agree to rounding.
    ASSERT_EQ(vtp.size(), ply.size());
    for (size_t i = 0; i < ply.size(); ++i)
      for (int c = 0; c < 7; ++c)
        ASSERT_NEAR(ply[i][c], vtp[i][c], 1e-4 * (1 + std::abs(ply[i][c]))) << "frame " << frame << " particle " << i;
    if (frame > 0) continue;
    for (size_t i = 0; i < x0.size(); ++i)
      ASSERT_NEAR(glm::length(glm::dvec3(ply[i][0], ply[i][1], ply[i][2]) - x0[i]), 0.0, 1e-5) << "particle " << i;
  }
}

}  // namespace
}  // namespace pbflow
