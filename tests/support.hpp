#pragma once
// Shared by the tests: the validated Vulkan context, test scenes, and GPU-vs-reference
// error reports (max and mean, absolute and relative, printed for every comparison).
#include <gtest/gtest.h>

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "scene/seeding.hpp"
#include "sim/params.hpp"
#include "sim/solver.hpp"
#include "vk/context.hpp"

namespace pbflow::test {

// One Vulkan context with the validation layer on, shared by all GPU tests.
vk::Context& gpu();

// Every GPU test derives from this: it fails when a validation message appeared.
class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override { messages_before_ = gpu().validation_messages().size(); }
  void TearDown() override {
    auto messages = gpu().validation_messages();
    EXPECT_EQ(messages.size(), messages_before_) << "Vulkan validation: " << messages.back();
  }

 private:
  size_t messages_before_ = 0;
};

// A non-trivial state: lattice positions jittered, random velocities and predictions.
ParticleState jittered_state(const Scene& scene, unsigned seed = 7);

struct ErrorReport {
  double max_abs = 0, mean_abs = 0, max_rel = 0, mean_rel = 0, scale = 0;
};
// Relative errors divide by max(|ref_i|, 1e-3 * scale), scale = max |ref|, so that
// values near zero do not blow the relative error up.
ErrorReport compare(const std::vector<double>& gpu, const std::vector<double>& ref, const std::string& what);
ErrorReport compare(const std::vector<glm::dvec3>& gpu, const std::vector<glm::dvec3>& ref, const std::string& what);

std::vector<glm::dvec3> difference(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b);

// The command line as a user runs it: the binary's exit status and its stdout and stderr.
struct CliResult {
  int status;  // -1 where it did not exit normally
  std::string output;
};
// Runs `pbflow args` through the shell; `prefix` goes before the binary, e.g. an
// environment ("PATH=/x") or a limit ("ulimit -f 8;"), and holds for this run alone.
CliResult run_pbflow(const std::string& args, const std::string& prefix = "");

// The same without a shell: `args` is the argument vector as given (quotes, $(...), newlines
// and all); stdout goes to `stdout_path` where one is named (e.g. /dev/full), else into the output.
CliResult run_pbflow(const std::vector<std::string>& args, const std::string& stdout_path = "");
// Starts pbflow with `args` and `env` (NAME=VALUE) added to its environment, its output into
// `log`; finish_pbflow waits for it and reads the log.
pid_t spawn_pbflow(const std::vector<std::string>& args, const std::filesystem::path& log,
                   const std::vector<std::string>& env = {}, const std::string& stdout_path = "");
CliResult finish_pbflow(pid_t pid, const std::filesystem::path& log);

// A CSV file of numbers: its rows, and its header line in `header`.
std::vector<std::vector<double>> read_csv(const std::filesystem::path& path, std::string* header);

// Whether Debian's python3 imports `module` (matplotlib for the charts, vtk for .vtp files).
bool python_has(const std::string& module);

// An empty path under the temporary directory: pbflow_test_NAME, removed if it exists.
std::filesystem::path fresh_dir(const std::string& name);

// A box's surface from lo to hi as an OBJ file (wound outward), written under the temporary
// directory for this process: a mesh with concave creases and corners where it is a container.
std::string box_mesh(const glm::dvec3& lo, const glm::dvec3& hi);
// A square glass standing on y = 0, centred on x = z = 0, faces along the axes: inside 2 *
// `inside` wide, its walls and floor `wall` thick, `height` tall; the same kind of file.
std::string glass_mesh(double inside, double wall, double height);

}  // namespace pbflow::test

// At a test's start: skips it, with one line saying why, where Debian's python3 cannot import
// `module`; `install` says what installs it.
#define PBFLOW_NEEDS_PYTHON(module, install) \
  if (!pbflow::test::python_has(module)) GTEST_SKIP() << "python3 cannot import " module " (" install ")"
