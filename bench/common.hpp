#pragma once
// Shared by the benches (study, scaling): CSV cells, the spacing for a particle count, charts.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace pbflow::vk {
class Context;
}

namespace pbflow::bench {

std::string number(double v);                             // 6 significant digits
std::string join(const std::vector<std::string>& cells);  // one CSV line, RFC 4180 quoting

// The particle spacing at which `scene` holds about `particles` fluid particles.
double spacing_for(const Scene& scene, int particles);

// Throws InputError where `scene` would not fit the device's memory (ctx) or the host's
// (ctx null: the reference solver), from its estimated particle count: before any particle is made.
void check_fits(const Scene& scene, const vk::Context* ctx);

// A file the bench writes: every write flushed and checked, a failure a runtime_error naming it.
class OutputFile {
 public:
  explicit OutputFile(const std::filesystem::path& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  void write(const std::string& text);
  void close();  // reports a failed close; the destructor cannot

 private:
  std::filesystem::path path_;
  std::FILE* file_;
};

// Runs the embedded bench/charts.py on `out` (Debian's python3 with matplotlib), leaving
// the script beside its charts. A chart it cannot draw is a warning on stderr, not a failure.
void draw_charts(const std::string& out);

}  // namespace pbflow::bench
