#include "scene/parse.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/json_input.hpp"
#include "common/read_file.hpp"
#include "scene/framing.hpp"
#include "scene/keys.hpp"
#include "scene/mesh.hpp"
#include "sim/solids/mirrors.hpp"

namespace pbflow {

const std::vector<std::pair<std::string_view, std::string_view>>& builtin_scenes_text();  // generated (cmake/embed.cmake)
const std::vector<std::pair<std::string_view, std::string_view>>& builtin_meshes_text();  // scenes/meshes, likewise

namespace {

using nlohmann::json;

// The JSON pointer of a dotted key: "solver.iterations" -> /solver/iterations.
json::json_pointer pointer(std::string_view dotted) {
  std::string path = "/";
  for (char c : dotted) path += c == '.' ? '/' : c;
  return json::json_pointer(path);
}

// The keys a scene may have (the key table, nested by its dots); anything else is an error
// naming its path. The lists' own members are checked where they are read.
const json& schema() {
  static const json s = [] {
    json tree = json::object();
    for (const SceneKey& k : scene_keys())
      tree[pointer(k.name)] = k.kind == KeyKind::Box ? json{{"min", 0}, {"max", 0}} : json(0);
    return tree;
  }();
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

// A scalar key's value, type- and range-checked as its row in the key table says; none
// when the scene leaves it out.
std::optional<double> scalar(const json& root, const SceneKey& k) {
  const json::json_pointer at = pointer(k.name);
  if (!root.contains(at)) return std::nullopt;
  const json& v = root[at];
  const std::string name(k.name);
  if (k.kind == KeyKind::Boolean) {
    require(v.is_boolean(), name + " must be true or false");
    return v.get<bool>() ? 1.0 : 0.0;
  }
  require(v.is_number(), "scene key '" + name + "' must be a number");
  const double x = v.get<double>();
  const bool whole = k.kind == KeyKind::Whole;
  if ((whole && x != std::floor(x)) || !k.range->contains(x)) {
    std::ostringstream m;
    m << name << " must be ";
    if (whole) m << "a whole number from " << (long long)k.range->lo << " to " << (long long)k.range->hi;
    else m << "in " << describe_range(*k.range) << (k.unit.empty() ? "" : " ") << k.unit;
    if (!k.why_range.empty()) m << ": " << k.why_range;
    throw InputError(m.str());
  }
  return x;
}

// Every scalar key the scene states (those with a place in the Scene), into that place.
void read_scalars(const json& root, Scene& s) {
  for (const SceneKey& k : scene_keys())
    if (!std::holds_alternative<std::monostate>(k.target))
      if (const std::optional<double> v = scalar(root, k)) assign(k, *v, s);
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
    if (!target->is_object() && !target->is_null())
      throw InputError("--param " + key + ": '" + done + "' is set to a value that is not an object (" +
                       target->dump().substr(0, 40) + ")");
    done += (done.empty() ? "" : ".") + part;
    if (!allowed->is_object() || !allowed->contains(part)) throw InputError("--param: unknown scene key '" + done + "'");
    allowed = &(*allowed)[part];
    target = &(*target)[part];
  }
  // A value that is not JSON is a string (--param camera.style=x); one nested too deep is refused.
  json value;
  try {
    value = parse_user_json(text, "--param " + key);
  } catch (const InputError&) {
    if (json::accept(text)) throw;
    value = text;
  }
  *target = value;
}

}  // namespace

namespace {

// The iteration counts and smoothing: each alone and against the others.
void check_iterations(const json& j, SolverParams& p) {
  if (!j.contains(json::json_pointer("/solver/max_iterations"))) p.max_iterations = std::max(p.max_iterations, p.iterations);
  require(p.max_iterations >= p.iterations, "solver.max_iterations (" + std::to_string(p.max_iterations) +
                                                ") is below solver.iterations (" + std::to_string(p.iterations) + ")");
  require(p.lambda_smoothing == SolverParams::kChosenSmoothing || p.lambda_smoothing % 2 == 0,
          "solver.lambda_smoothing must be 0, 2 or 4: a single average turns some density modes' correction around");
}

// The scene's list `key` (none where it is left out), refused where it is not an array.
const json& list(const json& j, const char* key) {
  static const json none = json::array();
  require(!j.contains(key) || j[key].is_array(), std::string("scene key '") + key + "' must be an array");
  return j.contains(key) ? j[key] : none;
}

bool inside_domain(const Scene& s, glm::dvec3 lo, glm::dvec3 hi) {
  return glm::all(glm::greaterThanEqual(lo, s.domain.min)) && glm::all(glm::lessThanEqual(hi, s.domain.max));
}

// The fluid's blocks and spheres, inside the domain, and a count within pbflow's limit.
void read_fluid(const json& j, Scene& s) {
  const json &blocks = list(j, "fluid_blocks"), &spheres = list(j, "fluid_spheres");
  for (size_t i = 0; i < blocks.size(); ++i) {
    std::string path = "fluid_blocks[" + std::to_string(i) + "]";
    Box b = box(blocks[i], path);
    require(inside_domain(s, b.min, b.max), path + " must lie inside the domain");
    s.fluid_blocks.push_back(b);
  }
  for (size_t i = 0; i < spheres.size(); ++i) {
    std::string path = "fluid_spheres[" + std::to_string(i) + "]";
    Ball b = ball(spheres[i], path);
    require(inside_domain(s, b.centre - b.radius, b.centre + b.radius), path + " must lie inside the domain");
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
}

// Where a scene's files lie: beside it; a built-in scene's `meshes/NAME.obj` are built in
// (scenes/meshes), its other files in the working directory.
struct SceneFiles {
  std::string directory;  // empty: the working directory
  bool builtin = false;
};

// The mesh a scene key names (`file`, `scale`, `position`, `rotation`), read bounded and placed.
TriangleMesh scene_mesh(const json& o, const std::string& path, const SceneFiles& files) {
  require(o.is_object(), "scene key '" + path + "' must be an object {file, scale, position, rotation}");
  reject_unknown(o, json{{"file", 0}, {"scale", 0}, {"position", 0}, {"rotation", 0}}, path);
  require(o.contains("file") && o["file"].is_string(), "scene key '" + path + ".file' must name a mesh file");
  std::filesystem::path file = o["file"].get<std::string>();
  if (file.is_relative() && !files.directory.empty()) file = std::filesystem::path(files.directory) / file;
  Placement place;
  if (o.contains("scale") && o["scale"].is_number())
    place.scale = glm::dvec3(number(o, "scale", 1));
  else
    place.scale = vec3(o, "scale", path + ".scale", place.scale);
  require(glm::all(glm::greaterThan(place.scale, glm::dvec3(0))), "scene key '" + path + ".scale' must be positive");
  place.position = vec3(o, "position", path + ".position", {});
  place.rotation = vec3(o, "rotation", path + ".rotation", {});
  const std::string what = path + "'s mesh '" + file.string() + "'";
  if (files.builtin)
    for (const auto& [name, text] : builtin_meshes_text())
      if (file == std::filesystem::path("meshes") / std::string(name))
        return parse_mesh(std::string(text), "obj", what, place);
  return read_mesh(file.string(), what, place);
}

// A mesh's solid for the solvers: its distance field half a spacing fine, reaching past every
// kernel, with its creases marked (negated first where the solid is outside the mesh), and its
// triangles for drawing.
Obstacle mesh_solid(const TriangleMesh& mesh, const Scene& s, const std::string& what, bool outside = false) {
  Obstacle ob;
  ob.kind = Obstacle::Kind::Mesh;
  ob.min = mesh.lo, ob.max = mesh.hi;
  const double reach = (s.solver.kernel_ratio + 1) * s.particle_spacing;  // h and the keep-out margin, with room
  std::shared_ptr<DistanceField> field = mesh_field(mesh, 0.5 * s.particle_spacing, reach, what);
  if (outside)
    for (float& v : field->values) v = -v;
  mark_creases(*field, s.solver.kernel_ratio * s.particle_spacing, 0.5 * s.particle_spacing);
  ob.field = std::move(field);
  auto corners = std::make_shared<std::vector<glm::vec3>>();
  for (const glm::ivec3& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) corners->push_back(glm::vec3(mesh.vertices[size_t(t[c])]));
  ob.corners = std::move(corners);
  return ob;
}

// The domain's mesh (a glass, a bowl): the fluid inside it and the box, the solid all around
// it: an obstacle whose field is the mesh's negated, over the whole box. Last of the obstacles.
void read_container(const json& domain, Scene& s, const SceneFiles& files) {
  if (!domain.is_object() || !domain.contains("mesh")) return;
  TriangleMesh mesh = scene_mesh(domain["mesh"], "domain.mesh", files);
  require(glm::all(glm::lessThan(mesh.lo, s.domain.max)) && glm::all(glm::greaterThan(mesh.hi, s.domain.min)),
          "domain.mesh lies wholly outside the domain's box");
  mesh.lo = glm::min(mesh.lo, s.domain.min), mesh.hi = glm::max(mesh.hi, s.domain.max);  // the field covers the box
  Obstacle ob = mesh_solid(mesh, s, "domain.mesh", true);
  ob.min = s.domain.min, ob.max = s.domain.max;
  ob.container = true;
  s.obstacles.push_back(std::move(ob));
}

// A number at j[key] within [lo, hi] (a motion's keys), named by its path.
double bounded(const json& j, const char* key, const std::string& path, double lo, double hi) {
  const std::string name = "scene key '" + path + "." + key + "'";
  require(j.contains(key), name + " is missing");
  require(j[key].is_number(), name + " must be a number");
  const double v = j[key].get<double>();
  require(v >= lo && v <= hi, name + " must lie in [" + json(lo).dump() + ", " + json(hi).dump() + "]");
  return v;
}

glm::dvec3 unit_axis(const json& j, const std::string& path) {
  const glm::dvec3 axis = vec3(j, "axis", path + ".axis", {});
  require(glm::length(axis) > 0, "scene key '" + path + ".axis' must be a direction (not zero, not missing)");
  return glm::normalize(axis);
}

// The keyframes' times strictly increasing, each pose a displacement and a rotation (about
// the centre: the solid's middle unless stated).
void read_keys(const json& j, const std::string& path, Motion& m) {
  require(j.contains("keys") && j["keys"].is_array() && !j["keys"].empty() && j["keys"].size() <= 100000,
          "scene key '" + path + ".keys' must be an array of 1 to 100000 keyframes");
  for (size_t k = 0; k < j["keys"].size(); ++k) {
    const json& key = j["keys"][k];
    const std::string at = path + ".keys[" + std::to_string(k) + "]";
    require(key.is_object(), "scene key '" + at + "' must be an object with t, position and rotation");
    reject_unknown(key, json{{"t", 0}, {"position", 0}, {"rotation", 0}}, at);
    const double t = bounded(key, "t", at, 0, 1e9);
    require(m.keys.empty() || t > m.keys.back().t, "scene key '" + at + ".t' must come after the key before it");
    m.keys.push_back({t, vec3(key, "position", at + ".position", {}),
                      glm::quat_cast(euler_rotation(vec3(key, "rotation", at + ".rotation", {})))});
  }
}

// An obstacle's motion (sim/solids/motion.hpp); `middle` is where its keyframes turn about by default.
Motion motion(const json& j, const std::string& path, const glm::dvec3& middle) {
  require(j.is_object() && j.contains("type") && j["type"].is_string(),
          path + " needs a \"type\": \"oscillate\", \"rotate\" or \"keyframes\"");
  Motion m;
  const std::string type = j["type"];
  if (type == "oscillate") {
    reject_unknown(j, json{{"type", 0}, {"axis", 0}, {"amplitude", 0}, {"period", 0}}, path);
    m.type = Motion::Type::Oscillate;
    m.axis = unit_axis(j, path);
    m.amplitude = bounded(j, "amplitude", path, 0, kMaxCoordinate);
    m.period = bounded(j, "period", path, 1e-6, 1e9);
  } else if (type == "rotate") {
    reject_unknown(j, json{{"type", 0}, {"axis", 0}, {"centre", 0}, {"rate", 0}}, path);
    m.type = Motion::Type::Rotate;
    m.axis = unit_axis(j, path);
    m.centre = vec3(j, "centre", path + ".centre", middle);
    m.rate = bounded(j, "rate", path, -1e9, 1e9);
  } else if (type == "keyframes") {
    reject_unknown(j, json{{"type", 0}, {"keys", 0}, {"centre", 0}}, path);
    m.type = Motion::Type::Keyframes;
    m.centre = vec3(j, "centre", path + ".centre", middle);
    read_keys(j, path, m);
  } else {
    throw InputError(path + ".type must be \"oscillate\", \"rotate\" or \"keyframes\"");
  }
  return m;
}

Obstacle obstacle(const json& o, const std::string& path, const Scene& s, const SceneFiles& files) {
  require(o.is_object() && o.contains("type") && o["type"].is_string(),
          path + " needs a \"type\": \"box\", \"sphere\" or \"mesh\"");
  json shape = o;
  shape.erase("type");
  shape.erase("motion");
  shape.erase("slip");
  Obstacle ob;
  if (o["type"] == "mesh") {
    ob = mesh_solid(scene_mesh(shape, path, files), s, path);
  } else if (o["type"] == "box") {
    Box b = box(shape, path);
    ob.min = b.min, ob.max = b.max;
  } else if (o["type"] == "sphere") {
    Ball b = ball(shape, path);
    ob.kind = Obstacle::Kind::Sphere, ob.centre = b.centre, ob.radius = b.radius;
  } else {
    throw InputError(path + ".type must be \"box\", \"sphere\" or \"mesh\"");
  }
  require(glm::all(glm::lessThan(ob.low(), s.domain.max)) && glm::all(glm::greaterThan(ob.high(), s.domain.min)),
          path + " lies wholly outside the domain");
  if (o.contains("slip")) {
    require(o["slip"].is_boolean(), path + ".slip must be true or false");
    ob.slip = o["slip"].get<bool>();
  }
  if (o.contains("motion")) {
    ob.motion = motion(o["motion"], path + ".motion", ob.middle());
    ob.pose = ob.previous = ob.motion.at(0);
  }
  return ob;
}

// A rigid body (sim/solids/bodies.hpp): an obstacle's shape (box, sphere, closed mesh) with no
// motion, its density or mass, placed turned about its middle, moving at the start as it says.
Obstacle body(const json& b, const std::string& path, Scene& s, const SceneFiles& files) {
  json shape = b;
  if (shape.is_object())
    for (const char* key : {"density", "mass", "rotation", "velocity", "angular_velocity"}) shape.erase(key);
  for (const char* key : {"motion", "slip"}) require(!shape.contains(key), "unknown scene key '" + path + "." + key + "'");
  Obstacle ob = obstacle(shape, path, s, files);
  require(b.contains("density") != b.contains("mass"), path + " needs a \"density\" (kg/m^3) or a \"mass\" (kg), one of them");
  const double density = number(b, "density", 0), mass = number(b, "mass", 0);
  require(b.contains("mass") || (density > 0 && density <= 1e5), path + ".density must be a number in (0, 1e5] kg/m^3");
  require(b.contains("density") || (mass > 0 && mass <= 1e9), path + ".mass must be a number in (0, 1e9] kg");
  const glm::dmat3 turn = euler_rotation(vec3(b, "rotation", path + ".rotation", {}));
  ob.pose = ob.previous = {turn, ob.middle() - turn * ob.middle()};
  glm::dvec3 lo = ob.centre - ob.radius, hi = ob.centre + ob.radius;  // a sphere's; a box's turned corners
  if (ob.kind != Obstacle::Kind::Sphere) {
    lo = glm::dvec3(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 corner = ob.pose.world(glm::mix(ob.low(), ob.high(), glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1)));
      lo = glm::min(lo, corner), hi = glm::max(hi, corner);
    }
  }
  require(inside_domain(s, lo, hi), path + " must lie inside the domain");
  ob.body = int(s.bodies.size());
  Body made = make_body(ob, density, mass, s.particle_spacing);
  made.velocity = vec3(b, "velocity", path + ".velocity", {});
  made.angular_velocity = glm::radians(vec3(b, "angular_velocity", path + ".angular_velocity", {}));
  made.obstacle = s.obstacles.size();
  for (const Obstacle& other : s.obstacles)
    for (const glm::dvec3& p : made.samples)
      require(!other.contains(ob.pose.world(p)), path + " overlaps another solid at the start");
  s.bodies.push_back(std::move(made));
  return ob;
}

void read_bodies(const json& j, Scene& s, const SceneFiles& files) {
  const json& bodies = list(j, "bodies");
  for (size_t i = 0; i < bodies.size(); ++i) s.obstacles.push_back(body(bodies[i], "bodies[" + std::to_string(i) + "]", s, files));
}

// An emitter: a disc (radius) or a rectangle (size) facing along its normal, its layers' points
// inside the domain and clear of every solid by half a spacing.
Emitter emitter(const json& e, const std::string& path, const Scene& s) {
  require(e.is_object(), "scene key '" + path + "' must be an object with centre, normal, radius or size, and speed");
  reject_unknown(e, json{{"centre", 0}, {"normal", 0}, {"radius", 0}, {"size", 0}, {"speed", 0}, {"start", 0}, {"stop", 0}},
                 path);
  require(e.contains("centre"), "scene key '" + path + ".centre' is missing");
  require(e.contains("radius") != e.contains("size"), "scene key '" + path + "' needs a radius (a disc) or a size (a rectangle), not both");
  Emitter out;
  out.centre = vec3(e, "centre", path + ".centre", {});
  const glm::dvec3 normal = vec3(e, "normal", path + ".normal", {});
  require(glm::length(normal) > 0, "scene key '" + path + ".normal' must be a direction (not zero, not missing)");
  out.normal = glm::normalize(normal);
  if (e.contains("radius")) {
    out.radius = bounded(e, "radius", path, 0, kMaxCoordinate);
  } else {
    const json& size = e["size"];
    require(size.is_array() && size.size() == 2 && size[0].is_number() && size[1].is_number(),
            "scene key '" + path + ".size' must be an array of two numbers");
    out.size = {size[0].get<double>(), size[1].get<double>()};
    require(out.size.x >= 0 && out.size.y >= 0 && out.size.x <= kMaxCoordinate && out.size.y <= kMaxCoordinate,
            "scene key '" + path + ".size' must lie in [0, 1e6]");
  }
  out.speed = bounded(e, "speed", path, 0, 1e4);
  require(out.speed > 0, "scene key '" + path + ".speed' must be above 0");
  out.start = e.contains("start") ? bounded(e, "start", path, 0, 1e9) : 0.0;
  if (e.contains("stop")) out.stop = bounded(e, "stop", path, 0, 1e9);
  require(out.stop > out.start, "scene key '" + path + ".stop' must come after its start");
  out.inlet = inlet_points(out, s.particle_spacing);
  require(out.inlet.size() <= 1000000, "scene key '" + path + "': an inlet of over a million particles a layer");
  const double margin = 0.5 * s.particle_spacing;
  for (const glm::dvec3& x : out.inlet) {
    require(glm::all(glm::greaterThanEqual(x, s.domain.min + margin)) && glm::all(glm::lessThanEqual(x, s.domain.max - margin)),
            path + " reaches outside the domain (its inlet within half a spacing of the walls or past them)");
    for (size_t k = 0; k < s.obstacles.size(); ++k)
      require(!s.obstacles[k].grown(margin).contains(x),
              path + " lies inside a solid (obstacle " + std::to_string(k) + " or the domain's mesh, within half a spacing)");
  }
  return out;
}

// Emitters and drains (sim/flow.hpp). A drain that holds every fluid block and sphere would
// leave nothing to simulate.
void read_flow(const json& j, Scene& s) {
  const json &emitters = list(j, "emitters"), &drains = list(j, "drains");
  for (size_t i = 0; i < emitters.size(); ++i)
    s.emitters.push_back(emitter(emitters[i], "emitters[" + std::to_string(i) + "]", s));
  for (size_t i = 0; i < drains.size(); ++i) {
    const Box b = box(drains[i], "drains[" + std::to_string(i) + "]");
    s.drains.push_back({b.min, b.max});
  }
  auto drained = [&](glm::dvec3 lo, glm::dvec3 hi) {
    return std::any_of(s.drains.begin(), s.drains.end(), [&](const Drain& d) {
      return glm::all(glm::greaterThan(lo, d.min)) && glm::all(glm::lessThan(hi, d.max));
    });
  };
  bool all = !s.drains.empty();
  for (const Box& b : s.fluid_blocks) all = all && drained(b.min, b.max);
  for (const Ball& b : s.fluid_spheres) all = all && drained(b.centre - b.radius, b.centre + b.radius);
  require(!all, "the drains hold all the fluid: nothing would be left to simulate");
}

// A kernel radius a step, m/s: the most a falling particle (chosen_substeps), an emitter's layer
// or a body's fastest point moves.
double kernel_step_speed(const Scene& s) { return s.solver.kernel_ratio * s.particle_spacing * s.fps * s.solver.substeps; }

// A body's fastest point at the start, its speed and its turn at its reach, may move at most a
// kernel radius a step: its projection would pass particles it never met.
void check_body_speed(const Scene& s) {
  const double most = kernel_step_speed(s);
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const Body& b = s.bodies[i];
    const Obstacle& o = s.obstacles[b.obstacle];
    const double fastest = glm::length(b.velocity) + glm::length(b.angular_velocity) * o.extent();
    if (fastest <= most) continue;
    std::ostringstream m;
    m.precision(3);
    m << "bodies[" << i << "] starts at " << fastest << " m/s at its fastest point, faster than the " << most
      << " m/s this time step keeps sound (a kernel radius a step): slow it or raise solver.substeps";
    throw InputError(m.str());
  }
}

// An emitter's layer may move at most a kernel radius a step, as a falling particle.
void check_emitter_speed(const Scene& s) {
  const double most = kernel_step_speed(s);
  for (size_t i = 0; i < s.emitters.size(); ++i)
    if (s.emitters[i].speed > most) {
      std::ostringstream m;
      m.precision(3);
      m << "emitters[" << i << "].speed " << s.emitters[i].speed << " m/s is faster than the " << most
        << " m/s this time step keeps sound (a kernel radius a step): slow it or raise solver.substeps";
      throw InputError(m.str());
    }
}

// The tank and how it moves (simulated in its own frame), turning about the box's centre unless
// the motion names another.
void read_domain(const json& j, Scene& s) {
  json walls = j;
  if (walls.is_object()) walls.erase("motion"), walls.erase("mesh");  // the mesh: read_container
  s.domain = box(walls, "domain");
  if (j.contains("motion")) s.tank_motion = motion(j["motion"], "domain.motion", 0.5 * (s.domain.min + s.domain.max));
}

// A moving solid may move at most kSolidStep spacings a step (scene/scene.hpp says why).
void check_solid_speed(const Scene& s) {
  const double most = kSolidStep * s.particle_spacing * s.fps * s.solver.substeps;
  if (solid_speed(s) <= most) return;
  std::ostringstream m;
  m.precision(3);
  m << (tank_speed(s) > most ? "the tank's walls reach " : "a moving obstacle's surface reaches ") << solid_speed(s)
    << " m/s, faster than the " << most
    << " m/s this time step keeps sound (half a particle_spacing a step): slow its motion or raise solver.substeps";
  throw InputError(m.str());
}

void read_method(const json& j, SolverParams& p) {
  const json solver = j.value("solver", json::object());
  if (!solver.contains("method")) return;
  require(solver["method"].is_string(), "solver.method must be \"pbf\" or \"ldc\"");
  try {
    p.method = parse_method(solver["method"].get<std::string>());
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("solver.") + e.what());
  }
}

// The camera, framing the scene where it is left out.
void read_camera(const json& j, Scene& s) {
  const json camera = j.value("camera", json::object());
  const Camera framed = framing_camera(s);
  s.camera.target = vec3(camera, "target", "camera.target", framed.target);
  s.camera.eye = vec3(camera, "eye", "camera.eye", framed.eye);
  s.camera_framed = !camera.contains("eye");
  // At the renderer's float precision, and by more than its rounding at that distance from the
  // origin: eye and target that differ only in double give a view matrix of NaN, a blank frame.
  const glm::vec3 eye(s.camera.eye), target(s.camera.target);
  require(glm::length(eye - target) > 1e-5f * std::max({1.0f, glm::length(eye), glm::length(target)}),
          "camera.eye and camera.target must differ (by more than 1e-5 of their distance from the origin)");
}

Scene parse_checked(const std::string& json_text, const std::string& origin, const std::vector<std::string>& overrides) {
  json j = parse_user_json(json_text, origin);
  if (!j.is_object()) throw InputError(origin + ": a scene must be a JSON object ({...})");
  for (const std::string& o : overrides) apply_override(j, o);
  reject_unknown(j, schema(), "");
  // Files a scene names lie beside it; a built-in scene's (or a scene given as text) in the
  // working directory.
  SceneFiles files;
  files.directory = std::filesystem::is_regular_file(origin) ? std::filesystem::path(origin).parent_path().string() : "";
  files.builtin = std::any_of(builtin_scenes_text().begin(), builtin_scenes_text().end(),
                              [&](const auto& b) { return b.first == origin; });

  Scene s = scene_defaults();
  s.name = origin;
  s.resolved = j.dump();
  require(!j.contains("description") || j["description"].is_string(), "scene key 'description' must be a string");
  s.description = j.value("description", "");
  require(j.contains("domain"), "scene needs a 'domain'");
  read_domain(j["domain"], s);
  require(j.contains("particle_spacing"), "scene needs a 'particle_spacing'");
  read_scalars(j, s);
  check_iterations(j, s.solver);
  read_fluid(j, s);
  const json& obstacles = list(j, "obstacles");
  for (size_t i = 0; i < obstacles.size(); ++i)
    s.obstacles.push_back(obstacle(obstacles[i], "obstacles[" + std::to_string(i) + "]", s, files));
  read_bodies(j, s, files);
  read_container(j["domain"], s, files);
  read_flow(j, s);
  s.gravity = vec3(j, "gravity", "gravity", s.gravity);
  require(glm::length(s.gravity) <= 1e4, "gravity must not exceed 1e4 m/s^2 (a thousand g)");
  if (s.solver.substeps == SolverParams::kChosenSubsteps) s.solver.substeps = chosen_substeps(s);
  check_solid_speed(s);
  check_emitter_speed(s);
  check_body_speed(s);
  read_method(j, s.solver);
  read_camera(j, s);
  return s;
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& origin, const std::vector<std::string>& overrides) {
  // Every check above names its key; what a value could still make the JSON library throw
  // (a type the walk did not expect) is bad input all the same, named by where it came from.
  try {
    return parse_checked(json_text, origin, overrides);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(origin + ": " + e.what());
  }
}

Scene load_scene(const std::string& name_or_path, const std::vector<std::string>& overrides) {
  for (const auto& [name, text] : builtin_scenes_text())
    if (name == name_or_path) return parse_scene(std::string(text), std::string(name), overrides);
  // A scene is a regular file of modest size: a directory, FIFO or device (/dev/zero) is
  // refused before it is read, and so is a file too large to be a scene.
  std::error_code error;
  if (!std::filesystem::exists(std::filesystem::symlink_status(name_or_path, error)))
    throw InputError("no built-in scene or readable file named '" + name_or_path + "' (see 'pbflow scenes')");
  const std::string text = read_user_file(name_or_path, "scene '" + name_or_path + "'", {kMaxSceneBytes});
  return parse_scene(text, name_or_path, overrides);
}

std::vector<BuiltinScene> builtin_scenes() {
  std::vector<BuiltinScene> out;
  for (const auto& [name, text] : builtin_scenes_text())
    out.push_back({std::string(name), json::parse(text).value("description", "")});
  return out;
}

}  // namespace pbflow
