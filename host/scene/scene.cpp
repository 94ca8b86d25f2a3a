#include "scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace pbflow {

const std::vector<std::pair<std::string_view, std::string_view>>& builtin_scenes_text();  // generated (cmake/embed.cmake)

namespace {

using nlohmann::json;

// The keys a scene may have; anything else is an error naming its path.
const json& schema() {
  static const json s = json::parse(R"({
    "description": "", "domain": {"min": 0, "max": 0}, "particle_spacing": 0,
    "fluid_blocks": [], "fluid_spheres": [], "obstacles": [], "gravity": 0, "settle": 0, "fps": 0, "frames": 0,
    "solver": {"method": 0, "iterations": 0, "max_iterations": 0, "target_compression": 0, "substeps": 0, "kernel_ratio": 0, "rest_density": 0,
               "relaxation": 0, "jacobi_gain": 0, "lambda_smoothing": 0, "scorr_k": 0, "scorr_n": 0, "scorr_dq": 0, "xsph": 0,
               "vorticity": 0, "damping": 0, "ldc_strength": 0, "ldc_k": 0, "ldc_clamp": 0,
               "ldc_mean_reference": 0},
    "camera": {"eye": 0, "target": 0, "fov": 0}
  })");
  return s;
}

void reject_unknown(const json& j, const json& allowed, const std::string& path) {
  if (!j.is_object()) throw InputError("scene key '" + path + "' must be an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    std::string key = path.empty() ? it.key() : path + "." + it.key();
    if (!allowed.contains(it.key())) throw InputError("unknown scene key '" + key + "'");
    if (allowed[it.key()].is_object()) reject_unknown(it.value(), allowed[it.key()], key);
  }
}

// Lengths and coordinates, m: a scene beyond a thousand kilometres is a mistake, and past it
// the arithmetic of particle counts and time steps would overflow.
constexpr double kMaxCoordinate = 1e6;

double number(const json& j, const std::string& key, double fallback) {
  if (!j.contains(key)) return fallback;
  if (!j[key].is_number()) throw InputError("scene key '" + key + "' must be a number");
  return j[key].get<double>();
}

glm::dvec3 vec3(const json& j, const std::string& key, const std::string& path, glm::dvec3 fallback) {
  if (!j.contains(key)) return fallback;
  const json& a = j[key];
  if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
    throw InputError("scene key '" + path + "' must be an array of three numbers");
  glm::dvec3 v(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
  if (glm::any(glm::greaterThan(glm::abs(v), glm::dvec3(kMaxCoordinate))))
    throw InputError("scene key '" + path + "' must lie within 1e6 of the origin");
  return v;
}

Box box(const json& j, const std::string& path) {
  if (!j.is_object()) throw InputError("scene key '" + path + "' must be an object with min and max");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "min" && it.key() != "max") throw InputError("unknown scene key '" + path + "." + it.key() + "'");
  if (!j.contains("min") || !j.contains("max")) throw InputError("scene key '" + path + "' needs min and max");
  Box b{vec3(j, "min", path + ".min", {}), vec3(j, "max", path + ".max", {})};
  if (!(b.max.x > b.min.x && b.max.y > b.min.y && b.max.z > b.min.z))
    throw InputError("scene key '" + path + "': max must exceed min on every axis");
  return b;
}

Ball ball(const json& j, const std::string& path) {
  if (!j.is_object()) throw InputError("scene key '" + path + "' must be an object with centre and radius");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "centre" && it.key() != "radius")
      throw InputError("unknown scene key '" + path + "." + it.key() + "'");
  if (!j.contains("centre") || !j.contains("radius")) throw InputError("scene key '" + path + "' needs centre and radius");
  Ball b{vec3(j, "centre", path + ".centre", {}), number(j, "radius", 0)};
  if (!(b.radius > 0)) throw InputError("scene key '" + path + ".radius' must be positive");
  return b;
}

void require(bool ok, const std::string& message) {
  if (!ok) throw InputError(message);
}

void apply_override(json& j, const std::string& assignment) {
  auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--param '" + assignment + "' must be key=value");
  std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  // Walk the schema so that a typo is caught here, naming the key.
  const json* allowed = &schema();
  json* target = &j;
  std::stringstream parts(key);
  std::string part, done;
  while (std::getline(parts, part, '.')) {
    done += (done.empty() ? "" : ".") + part;
    if (!allowed->is_object() || !allowed->contains(part)) throw InputError("--param: unknown scene key '" + done + "'");
    allowed = &(*allowed)[part];
    target = &(*target)[part];
  }
  json value = json::parse(text, nullptr, false);
  *target = value.is_discarded() ? json(text) : value;
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& origin, const std::vector<std::string>& overrides) {
  json j;
  try {
    j = json::parse(json_text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers past double's range
    throw InputError(origin + ": JSON syntax error: " + e.what());
  }
  if (!j.is_object()) throw InputError(origin + ": a scene must be a JSON object ({...})");
  for (const std::string& o : overrides) apply_override(j, o);
  reject_unknown(j, schema(), "");

  Scene s;
  s.name = origin;
  s.resolved = j.dump();
  require(!j.contains("description") || j["description"].is_string(), "scene key 'description' must be a string");
  s.description = j.value("description", "");
  require(j.contains("domain"), "scene needs a 'domain'");
  s.domain = box(j["domain"], "domain");
  require(j.contains("particle_spacing"), "scene needs a 'particle_spacing'");
  s.particle_spacing = number(j, "particle_spacing", 0);
  require(s.particle_spacing > 0, "particle_spacing must be positive");
  require(s.particle_spacing >= 1e-6 && s.particle_spacing <= kMaxCoordinate, "particle_spacing must be in [1e-6, 1e6] m");
  auto inside_domain = [&](glm::dvec3 lo, glm::dvec3 hi) {
    return glm::all(glm::greaterThanEqual(lo, s.domain.min)) && glm::all(glm::lessThanEqual(hi, s.domain.max));
  };
  for (const char* key : {"fluid_blocks", "fluid_spheres", "obstacles"})
    require(!j.contains(key) || j[key].is_array(), std::string("scene key '") + key + "' must be an array");
  static const json none = json::array();
  auto array = [&](const char* key) -> const json& { return j.contains(key) ? j[key] : none; };
  for (size_t i = 0; i < array("fluid_blocks").size(); ++i) {
    std::string path = "fluid_blocks[" + std::to_string(i) + "]";
    Box b = box(array("fluid_blocks")[i], path);
    require(inside_domain(b.min, b.max), path + " must lie inside the domain");
    s.fluid_blocks.push_back(b);
  }
  for (size_t i = 0; i < array("fluid_spheres").size(); ++i) {
    std::string path = "fluid_spheres[" + std::to_string(i) + "]";
    Ball b = ball(array("fluid_spheres")[i], path);
    require(inside_domain(b.centre - b.radius, b.centre + b.radius), path + " must lie inside the domain");
    s.fluid_spheres.push_back(b);
  }
  require(!s.fluid_blocks.empty() || !s.fluid_spheres.empty(),
          "scene needs fluid: a non-empty 'fluid_blocks' or 'fluid_spheres'");
  // Checked before any particle is made, so that a tiny spacing fails here, not in an allocation.
  double estimate = particle_estimate(s);
  if (!(estimate <= kMaxParticles)) {
    std::ostringstream m;
    m.precision(3);
    m << "the fluid would hold about " << estimate << " particles, more than pbflow's limit of " << kMaxParticles
      << " (raise particle_spacing)";
    throw InputError(m.str());
  }
  for (size_t i = 0; i < array("obstacles").size(); ++i) {
    std::string path = "obstacles[" + std::to_string(i) + "]";
    const json& o = array("obstacles")[i];
    require(o.is_object() && o.contains("type") && o["type"].is_string(),
            path + " needs a \"type\": \"box\" or \"sphere\"");
    json shape = o;
    shape.erase("type");
    Obstacle ob;
    if (o["type"] == "box") {
      Box b = box(shape, path);
      ob.min = b.min, ob.max = b.max;
    } else if (o["type"] == "sphere") {
      Ball b = ball(shape, path);
      ob.kind = Obstacle::Kind::Sphere, ob.centre = b.centre, ob.radius = b.radius;
    } else {
      throw InputError(path + ".type must be \"box\" or \"sphere\"");
    }
    glm::dvec3 lo = ob.kind == Obstacle::Kind::Box ? ob.min : ob.centre - ob.radius;
    glm::dvec3 hi = ob.kind == Obstacle::Kind::Box ? ob.max : ob.centre + ob.radius;
    require(glm::all(glm::lessThan(lo, s.domain.max)) && glm::all(glm::greaterThan(hi, s.domain.min)),
            path + " lies wholly outside the domain");
    s.obstacles.push_back(ob);
  }
  s.gravity = vec3(j, "gravity", "gravity", {0, -9.81, 0});
  require(glm::length(s.gravity) <= 1e4, "gravity must not exceed 1e4 m/s^2 (a thousand g)");
  if (j.contains("settle")) {
    require(j["settle"].is_boolean(), "settle must be true or false");
    s.settle = j["settle"].get<bool>();
  }
  s.fps = number(j, "fps", 60);
  require(s.fps >= 1e-3 && s.fps <= 1e5, "fps must be in [0.001, 100000]");
  double frames = number(j, "frames", 240);
  require(frames >= 1 && frames <= kMaxFrames && frames == std::floor(frames),
          "frames must be a whole number from 1 to " + std::to_string(kMaxFrames));
  s.frames = int(frames);

  s.solver = SolverParams::defaults();
  const json solver = j.value("solver", json::object());
  SolverParams& p = s.solver;
  if (solver.contains("method")) {
    require(solver["method"].is_string(), "solver.method must be \"pbf\" or \"ldc\"");
    try {
      p.method = parse_method(solver["method"].get<std::string>());
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("solver.") + e.what());
    }
  }
  auto whole = [&](const char* key, int fallback, int lo, int hi) {
    double v = number(solver, key, fallback);
    require(v == std::floor(v) && v >= lo && v <= hi,
            std::string("solver.") + key + " must be a whole number from " + std::to_string(lo) + " to " +
                std::to_string(hi));
    return int(v);
  };
  p.iterations = whole("iterations", p.iterations, 1, 1000);
  p.max_iterations = whole("max_iterations", std::max(p.max_iterations, p.iterations), 1, 1000);
  require(p.max_iterations >= p.iterations, "solver.max_iterations must be at least solver.iterations");
  p.target_compression = number(solver, "target_compression", p.target_compression);
  require(p.target_compression >= 0 && p.target_compression < 1,
          "solver.target_compression must be in [0, 1) (0: a fixed number of iterations)");
  p.substeps = whole("substeps", p.substeps, 1, 1000);
  p.kernel_ratio = number(solver, "kernel_ratio", p.kernel_ratio);
  require(p.kernel_ratio > 1 && p.kernel_ratio <= 4, "solver.kernel_ratio (h / spacing) must be in (1, 4]");
  p.rest_density = number(solver, "rest_density", p.rest_density);
  require(p.rest_density > 0 && p.rest_density <= 1e6, "solver.rest_density must be in (0, 1e6] kg/m^3");
  p.relaxation = number(solver, "relaxation", p.relaxation);
  require(p.relaxation > 0 && p.relaxation <= 1e6, "solver.relaxation must be in (0, 1e6]");
  p.jacobi_gain = number(solver, "jacobi_gain", p.jacobi_gain);
  require(p.jacobi_gain > 0 && p.jacobi_gain <= 1,
          "solver.jacobi_gain must be in (0, 1]: a constraint pass that moves a mode past its error makes energy");
  if (solver.contains("lambda_smoothing")) p.lambda_smoothing = whole("lambda_smoothing", 0, 0, 4);
  require(p.lambda_smoothing == SolverParams::kChosenSmoothing || p.lambda_smoothing % 2 == 0,
          "solver.lambda_smoothing must be 0, 2 or 4: a single average turns some density modes' correction around");
  p.scorr_k = number(solver, "scorr_k", p.scorr_k);
  require(p.scorr_k >= 0 && p.scorr_k <= 1e3, "solver.scorr_k must be in [0, 1000]");
  p.scorr_n = number(solver, "scorr_n", p.scorr_n);
  require(p.scorr_n >= 1 && p.scorr_n <= 16, "solver.scorr_n must be in [1, 16]");
  p.scorr_dq = number(solver, "scorr_dq", p.scorr_dq);
  require(p.scorr_dq > 0 && p.scorr_dq < 1, "solver.scorr_dq (a fraction of h) must be in (0, 1)");
  p.xsph = number(solver, "xsph", p.xsph);
  require(p.xsph >= 0 && p.xsph <= 1, "solver.xsph must be in [0, 1]");
  p.vorticity = number(solver, "vorticity", p.vorticity);
  require(p.vorticity >= 0 && p.vorticity <= 1e6, "solver.vorticity must be in [0, 1e6]");
  p.damping = number(solver, "damping", p.damping);
  require(p.damping >= 0 && p.damping <= 0.3,
          "solver.damping must be in [0, 0.3]: past that the explicit dashpot reverses the fastest modes");
  p.ldc_strength = number(solver, "ldc_strength", p.ldc_strength);
  require(p.ldc_strength >= 0 && p.ldc_strength < 1,
          "solver.ldc_strength (a fraction of the stiffness the step carries) must be in [0, 1)");
  if (solver.contains("ldc_k")) {
    p.ldc_k = number(solver, "ldc_k", 0);
    require(p.ldc_k >= 0, "solver.ldc_k must not be negative");
  }
  if (solver.contains("ldc_clamp")) {
    require(solver["ldc_clamp"].is_boolean(), "solver.ldc_clamp must be true or false");
    p.ldc_clamp = solver["ldc_clamp"].get<bool>();
  }
  if (solver.contains("ldc_mean_reference")) {
    require(solver["ldc_mean_reference"].is_boolean(), "solver.ldc_mean_reference must be true or false");
    p.ldc_mean_reference = solver["ldc_mean_reference"].get<bool>();
  }

  glm::dvec3 centre = 0.5 * (s.domain.min + s.domain.max), size = s.domain.max - s.domain.min;
  const json camera = j.value("camera", json::object());
  s.camera.target = vec3(camera, "target", "camera.target", centre);
  s.camera.eye = vec3(camera, "eye", "camera.eye", centre + glm::dvec3(0, 0.4 * size.y, 1.6 * glm::length(size)));
  s.camera.fov_degrees = number(camera, "fov", 45);
  require(s.camera.fov_degrees > 1 && s.camera.fov_degrees < 179, "camera.fov must be in (1, 179) degrees");
  require(glm::length(s.camera.eye - s.camera.target) > 0, "camera.eye and camera.target must differ");
  return s;
}

Scene load_scene(const std::string& name_or_path, const std::vector<std::string>& overrides) {
  for (const auto& [name, text] : builtin_scenes_text())
    if (name == name_or_path) return parse_scene(std::string(text), std::string(name), overrides);
  // A scene is a regular file of modest size: a directory, FIFO or device (/dev/zero) is
  // refused before it is read, and so is a file too large to be a scene.
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(name_or_path, error);
  if (error || !std::filesystem::exists(status))
    throw InputError("no built-in scene or readable file named '" + name_or_path + "' (see 'pbflow scenes')");
  if (!std::filesystem::is_regular_file(status))
    throw InputError("scene '" + name_or_path + "' is not a regular file (a directory, FIFO or device)");
  if (std::filesystem::file_size(name_or_path, error) > kMaxSceneBytes)
    throw InputError("scene '" + name_or_path + "' is larger than " + std::to_string(kMaxSceneBytes >> 20) +
                     " MiB, too large to be a scene");
  std::ifstream file(name_or_path);
  if (!file) throw InputError("cannot read scene '" + name_or_path + "'");
  std::stringstream text;
  text << file.rdbuf();
  return parse_scene(text.str(), name_or_path, overrides);
}

std::vector<BuiltinScene> builtin_scenes() {
  std::vector<BuiltinScene> out;
  for (const auto& [name, text] : builtin_scenes_text())
    out.push_back({std::string(name), json::parse(text).value("description", "")});
  return out;
}

double fluid_volume(const Scene& scene) {
  double v = 0;
  for (const Box& b : scene.fluid_blocks) v += (b.max.x - b.min.x) * (b.max.y - b.min.y) * (b.max.z - b.min.z);
  for (const Ball& b : scene.fluid_spheres) v += 4.0 / 3.0 * M_PI * b.radius * b.radius * b.radius;
  return v;
}

double particle_estimate(const Scene& scene) { return fluid_volume(scene) / std::pow(scene.particle_spacing, 3); }

double fall_speed(const Scene& scene) {
  return std::sqrt(2.0 * glm::length(scene.gravity) * (scene.domain.max.y - scene.domain.min.y));
}

}  // namespace pbflow
