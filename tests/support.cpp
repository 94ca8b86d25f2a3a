#include "support.hpp"

#include "common/child_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <sstream>
#include <random>

namespace pbflow::test {

vk::Context& gpu() {
  static vk::Context ctx(vk::Context::Options{"auto", true, 0, true});  // its programs kept: every test makes the same
  return ctx;
}

ParticleState jittered_state(const Scene& scene, unsigned seed) {
  std::mt19937 rng(seed);
  const double s = scene.particle_spacing;
  std::uniform_real_distribution<double> jitter(-0.2 * s, 0.2 * s), speed(-0.5, 0.5);
  Derived d = derive(scene);
  ParticleState st;
  for (const glm::dvec3& p : initial_particles(scene)) {
    glm::dvec3 x = glm::clamp(p + glm::dvec3(jitter(rng), jitter(rng), jitter(rng)), d.wall_min, d.wall_max);
    st.x.push_back(x);
    st.v.emplace_back(speed(rng), speed(rng), speed(rng));
    st.x_pred.push_back(glm::clamp(x + glm::dvec3(jitter(rng), jitter(rng), jitter(rng)), d.wall_min, d.wall_max));
  }
  size_t n = st.x.size();
  st.curl.assign(n, glm::dvec3(0.0));
  st.rho.assign(n, 0.0);
  st.lambda.assign(n, 0.0);
  return st;
}

namespace {
ErrorReport report(const std::vector<double>& err, const std::vector<double>& mag, const std::string& what) {
  ErrorReport r;
  for (double m : mag) r.scale = std::max(r.scale, m);
  double floor = std::max(1e-3 * r.scale, 1e-30);
  for (size_t i = 0; i < err.size(); ++i) {
    double rel = err[i] / std::max(mag[i], floor);
    r.max_abs = std::max(r.max_abs, err[i]);
    r.mean_abs += err[i];
    r.max_rel = std::max(r.max_rel, rel);
    r.mean_rel += rel;
  }
  r.mean_abs /= std::max<size_t>(err.size(), 1);
  r.mean_rel /= std::max<size_t>(err.size(), 1);
  std::printf("  %-34s n=%zu  max|ref| %.3e  abs err max %.3e mean %.3e  rel err max %.3e mean %.3e\n",
              what.c_str(), err.size(), r.scale, r.max_abs, r.mean_abs, r.max_rel, r.mean_rel);
  return r;
}
}  // namespace

namespace {
// Error and magnitude of every element, with `norm` giving a scalar per element.
template <class T, class Norm>
ErrorReport compare_with(const std::vector<T>& gpu, const std::vector<T>& ref, const std::string& what, Norm norm) {
  EXPECT_EQ(gpu.size(), ref.size()) << what;
  std::vector<double> err(ref.size()), mag(ref.size());
  for (size_t i = 0; i < ref.size() && i < gpu.size(); ++i) {
    err[i] = norm(gpu[i] - ref[i]);
    mag[i] = norm(ref[i]);
  }
  return report(err, mag, what);
}
}  // namespace

ErrorReport compare(const std::vector<double>& gpu, const std::vector<double>& ref, const std::string& what) {
  return compare_with(gpu, ref, what, [](double v) { return std::abs(v); });
}

ErrorReport compare(const std::vector<glm::dvec3>& gpu, const std::vector<glm::dvec3>& ref, const std::string& what) {
  return compare_with(gpu, ref, what, [](const glm::dvec3& v) { return glm::length(v); });
}

std::vector<glm::dvec3> difference(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  std::vector<glm::dvec3> d(a.size());
  for (size_t i = 0; i < a.size(); ++i) d[i] = a[i] - b[i];
  return d;
}

CliResult run_pbflow(const std::string& args, const std::string& prefix) {
  namespace fs = std::filesystem;
  fs::path log = fs::temp_directory_path() / ("pbflow_cli_" + std::to_string(getpid()) + ".log");
  std::string cmd = prefix + " " + std::string(PBFLOW_BINARY) + " " + args + " > " + log.string() + " 2>&1";
  int raw = std::system(cmd.c_str());
  std::ifstream in(log);
  std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(log);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, output};
}

pid_t spawn_pbflow(const std::vector<std::string>& args, const std::filesystem::path& log,
                   const std::vector<std::string>& env, const std::string& stdout_path) {
  std::vector<std::string> argv_text = {PBFLOW_BINARY};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv, envp;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text = env;
  for (char** e = environ; *e; ++e) env_text.push_back(*e);
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (stdout_path.empty()) posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
  else posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_path.c_str(), O_WRONLY, 0);
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, PBFLOW_BINARY, &actions, nullptr, argv.data(), envp.data()), 0);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

CliResult finish_pbflow(pid_t pid, const std::filesystem::path& log) {
  int raw = 0;
  while (waitpid(pid, &raw, 0) < 0 && errno == EINTR) {
  }
  std::ifstream in(log);
  std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(log);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, output};
}

CliResult run_pbflow(const std::vector<std::string>& args, const std::string& stdout_path) {
  const std::filesystem::path log =
      std::filesystem::temp_directory_path() / ("pbflow_argv_" + std::to_string(getpid()) + ".log");
  return finish_pbflow(spawn_pbflow(args, log, {}, stdout_path), log);
}

bool python_has(const std::string& module) {
  return run_child({"/usr/bin/python3", "-c", "import " + module}, /*quiet=*/true) == 0;
}

std::filesystem::path fresh_dir(const std::string& name) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("pbflow_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

std::string box_mesh(const glm::dvec3& lo, const glm::dvec3& hi) {
  std::ostringstream name;
  name << "pbflow_box_" << getpid() << "_" << lo.x << "_" << lo.y << "_" << lo.z << "_" << hi.x << "_" << hi.y << "_" << hi.z << ".obj";
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name.str();
  std::ofstream obj(path);
  for (int c = 0; c < 8; ++c)  // corner c: bit 0 x, bit 1 y, bit 2 z at hi
    obj << "v " << (c & 1 ? hi : lo).x << ' ' << (c & 2 ? hi : lo).y << ' ' << (c & 4 ? hi : lo).z << '\n';
  // Each face's corners counter-clockwise seen from outside, two triangles a face.
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces)
    obj << "f " << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << "\nf " << f[0] + 1 << ' ' << f[2] + 1 << ' ' << f[3] + 1 << '\n';
  return path.string();
}

std::string glass_mesh(double inside, double wall, double height) {
  std::ostringstream name;
  name << "pbflow_glass_" << getpid() << "_" << inside << "_" << wall << "_" << height << ".obj";
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name.str();
  std::ofstream obj(path);
  // Turned about y as scripts/make_meshes.py's lathe turns the cup, in four segments whose
  // corners lie on the diagonals: a section (r, y) counter-clockwise, its axis points shared.
  const double corner = std::sqrt(2.0), outside = inside + wall;
  const double section[6][2] = {{0, 0}, {outside, 0}, {outside, height}, {inside, height}, {inside, wall}, {0, wall}};
  int index[4][6], count = 0;
  for (int s = 0; s < 4; ++s)
    for (int k = 0; k < 6; ++k) {
      if (section[k][0] == 0 && s > 0) {
        index[s][k] = index[0][k];
        continue;
      }
      const double turn = std::numbers::pi * (0.25 + 0.5 * s), r = corner * section[k][0];
      obj << "v " << r * std::cos(turn) << ' ' << section[k][1] << ' ' << -r * std::sin(turn) << '\n';
      index[s][k] = ++count;
    }
  for (int s = 0; s < 4; ++s)
    for (int k = 0; k < 6; ++k) {
      const int a = index[s][k], b = index[(s + 1) % 4][k], c = index[(s + 1) % 4][(k + 1) % 6], d = index[s][(k + 1) % 6];
      if (a != b && b != c && a != c) obj << "f " << a << ' ' << b << ' ' << c << '\n';
      if (a != c && c != d && a != d) obj << "f " << a << ' ' << c << ' ' << d << '\n';
    }
  return path.string();
}

std::vector<std::vector<double>> read_csv(const std::filesystem::path& path, std::string* header) {
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


}  // namespace pbflow::test
