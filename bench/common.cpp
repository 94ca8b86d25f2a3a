#include "bench/common.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string_view>
#include <utility>

#include "common/child_process.hpp"
#include "gpu/memory_estimate.hpp"
#include "scene/derive.hpp"
#include "vk/context.hpp"

namespace pbflow {
const std::vector<std::pair<std::string_view, std::string_view>>& bench_scripts_text();  // generated
}

namespace pbflow::bench {

std::string number(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

namespace {
// Debian's python3 with matplotlib (pyenv or venv interpreters on PATH may lack it).
std::string python_with_matplotlib() {
  for (const char* py : {"/usr/bin/python3", "python3"})
    if (run_child({py, "-c", "import matplotlib"}, true) == 0) return py;
  return "";
}

// RFC 4180: a cell with a comma or a quote is quoted (device names have commas).
std::string csv_cell(const std::string& cell) {
  if (cell.find_first_of(",\"\n") == std::string::npos) return cell;
  std::string quoted = "\"";
  for (char c : cell) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}
}  // namespace

std::string join(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += csv_cell(cells[i]);
  }
  return line;
}

double spacing_for(const Scene& scene, int particles) { return std::cbrt(fluid_volume(scene) / particles); }

void check_fits(const Scene& scene, const vk::Context* ctx) {
  const vk::DeviceInfo* device = ctx ? &ctx->info() : nullptr;
  check_memory(memory_need(derive(scene), particle_estimate(scene), device), device, {"lower --counts", ""});
}

OutputFile::OutputFile(const std::filesystem::path& path) : path_(path), file_(std::fopen(path.c_str(), "w")) {
  if (!file_) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
}

OutputFile::~OutputFile() {
  if (file_) std::fclose(file_);
}

void OutputFile::write(const std::string& text) {
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fflush(file_) != 0)
    throw std::runtime_error("cannot write " + path_.string() + ": " + std::strerror(errno));
}

void OutputFile::close() {
  const int closed = std::fclose(std::exchange(file_, nullptr));
  if (closed != 0) throw std::runtime_error("cannot write " + path_.string() + ": " + std::strerror(errno));
}

void draw_charts(const std::string& out) {
  // A chart that cannot be drawn is a warning: the CSVs, minutes of work, are written and stand.
  const std::string python = python_with_matplotlib();
  if (python.empty()) {
    std::cerr << "pbflow: warning: no charts: python3 with matplotlib is missing (apt-get install python3-matplotlib); "
              << "the CSVs in " << out << " are complete\n";
    return;
  }
  // The embedded script goes beside its charts, so that they can be remade from the CSVs.
  const std::filesystem::path script = std::filesystem::path(out) / "charts.py";
  OutputFile file(script);
  for (const auto& [name, text] : bench_scripts_text())
    if (name == "charts") file.write(std::string(text));
  file.close();
  if (run_child({python, script.string(), out}) != 0)
    std::cerr << "pbflow: warning: the chart script failed (the CSVs in " << out << " are complete; run "
              << python << " " << script.string() << " " << out << " to see why)\n";
}

}  // namespace pbflow::bench
