#include "scene/keys.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace pbflow {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using K = KeyKind;
using P = SolverParams;
using W = WhiteWaterParams;

// The rows. A comment above a row says why its default is what it is, in a sentence; the
// measurements behind it are in docs/physics.md.
const SceneKey kKeys[] = {
    {"description", K::Text, "\"\"", {}, {}, "", "a line for `pbflow scenes`", "", {}},
    {"domain", K::Box, "required", {}, {}, "m", "the tank `{min, max}`: closed walls", "", {}},
    {"domain.motion", K::Motion, "none", {}, {}, "m, s",
     "the tank moved rigidly, as an obstacle's `motion` (turning about the box's centre unless it names one): "
     "the fluid is simulated in the tank's frame, where it feels g and the frame's acceleration, Coriolis, "
     "centrifugal and Euler terms; drawn and exported in the world; `solid_work` counts the motion's work",
     "", {}},
    {"domain.mesh", K::Mesh, "none", {}, {}, "m, degrees",
     "the tank as a closed mesh (a glass, a bowl) `{file, scale, position, rotation}`, placed as a mesh "
     "obstacle is: the fluid lies inside it and the box, the solid all around it; a built-in scene's mesh is "
     "built in (scenes/meshes)",
     "", {}},
    {"particle_spacing", K::Number, "required", {}, KeyRange{1e-6, 1e6}, "m",
     "lattice spacing of the fluid; halving it makes 8x the particles", "", &Scene::particle_spacing},
    {"fluid_blocks", K::Boxes, "[]", {}, {}, "m", "boxes `{min, max}` filled with particles (lattice from the box's corner)",
     "", {}},
    {"fluid_spheres", K::Balls, "[]", {}, {}, "m",
     "balls `{centre, radius}` filled with particles (lattice from the domain's corner); blocks or spheres must hold "
     "some fluid",
     "", {}},
    {"obstacles", K::Shapes, "[]", {}, {}, "m",
     "solids `{\"type\": \"box\", min, max}`, `{\"type\": \"sphere\", centre, radius}` or `{\"type\": "
     "\"mesh\", file, scale, position, rotation}` (a closed OBJ, STL or PLY mesh, its path relative to the scene "
     "file; scale a number or three; rotation in degrees about x, then y, then z, fixed axes); mirrors to the fluid as "
     "the walls are. Each may move rigidly with `\"motion\"`: `{\"type\": \"oscillate\", axis, amplitude (m), period "
     "(s)}` (a sine from rest position), `{\"type\": \"rotate\", axis, centre, rate (degrees/s)}` or `{\"type\": "
     "\"keyframes\", keys: [{t, position, rotation}, ...], centre}` (times increasing; position a displacement from "
     "where the scene places it, rotation as above about centre, the solid's middle if left out; linear and slerp "
     "between keys, held before the first and after the last); its surface at most half a particle_spacing a step. "
     "The fluid slips along each; `\"slip\": false` makes it stick, carried at the surface's velocity",
     "", {}},
    {"bodies", K::Shapes, "[]", {}, {}, "m, kg/m^3, kg, m/s, degrees/s",
     "rigid bodies the water moves and that move it: `{\"type\": \"box\", min, max}`, `{\"type\": \"sphere\", "
     "centre, radius}` or `{\"type\": \"mesh\", file, scale, position}` (a closed mesh; it collides as its convex hull) "
     "with a `density` (kg/m^3) or a `mass` (kg), and optionally `rotation` (degrees about x, then y, then z, about its "
     "middle), `velocity` and `angular_velocity` (degrees/s) at the start; Bullet moves them under gravity and their "
     "contacts with the walls, the obstacles and each other; not in a moving tank",
     "", {}},
    {"emitters", K::Emitters, "[]", {}, {}, "m, m/s, s",
     "inlets `{centre, normal, radius}` (a disc) or `{centre, normal, size: [across, along]}` (a rectangle), "
     "`speed` along the normal, `start` and `stop` in s (0 and never if left out): particles enter in layers at the "
     "rest spacing, one every spacing / speed seconds, moving at the speed; a layer moves at most a kernel radius a "
     "step",
     "", {}},
    {"drains", K::Boxes, "[]", {}, {}, "m", "boxes `{min, max}`: every particle inside one at a frame's start is removed",
     "", {}},
    // Room for the start and all the emitters bring over the scene's frames, drains aside.
    {"capacity", K::Whole, "chosen", {}, KeyRange{1, double(kMaxParticles)}, "",
     "the most particles a run holds at once (emitters wait past it, and the run says so once); left out: the start's "
     "count and what the emitters bring over the scene's `frames`",
     "", &Scene::capacity},
    {"gravity", K::Vector, "[0, -9.81, 0]", {}, {}, "m/s²", "at most 1e4 m/s² (a thousand g)", "", {}},
    // A tank starts in the solver's own equilibrium only when asked: a drop in the air must not settle.
    {"settle", K::Boolean, {}, 0.0, {}, "",
     "start at rest in the solver's own equilibrium (sim/settle.hpp): for a tank, not for a drop in the air", "",
     &Scene::settle},
    // One fixed default: every run of a scene starts alike unless asked otherwise.
    {"seed", K::Whole, {}, 20261126.0, KeyRange{0, 1e9}, "",
     "random seed of the start's jitter (each particle moved up to a quarter spacing per axis): another seed, "
     "another start of the same fluid",
     "", &Scene::seed},
    {"fps", K::Number, {}, 60.0, KeyRange{1e-3, 1e5}, "", "output rate: frame k shows time k/fps", "", &Scene::fps},
    {"frames", K::Whole, {}, 240.0, KeyRange{1, double(kMaxFrames)}, "", "frames written, frame 0 the initial state", "",
     &Scene::frames},
    // With two iterations LDC reads as PBF does and costs a pass more (docs/physics.md): the
    // front's cheapest setting under 1 % is pbf@2. ldc is the LDC paper's, for one iteration.
    {"solver.method", K::Method, "pbf", {}, {}, "", "`pbf` or `ldc` (PBF with the local density correction force)", "",
     {}},
    // The fewest on the accuracy-against-cost front that hold the dam break under 1 % at 60 fps x 2
    // (bench/results/pareto_*/cheapest.md); one, the LDC paper's setting, reads 1.5 %.
    {"solver.iterations", K::Whole, {}, 2.0, KeyRange{1, 1000}, "",
     "constraint iterations per step (the minimum when adaptive); left out: 2, the fewest that keep the dam break under 1 % "
     "mean compression at 60 fps x 2 (1 reads 1.5-1.7 %; the run's first line says which)",
     "", &P::iterations},
    // SPlisHSPlasH's PBF stops at an average density error; here the mean compression.
    {"solver.target_compression", K::Number, {}, 0.0, KeyRange{0, 1, false, true}, "",
     "adaptive iterations when > 0: after `iterations`, pairs run while the mean compression exceeds it",
     "0 is a fixed number of iterations", &P::target_compression},
    {"solver.max_iterations", K::Whole, {}, 100.0, KeyRange{1, 1000}, "",
     "the adaptive mode's limit per step, at least `iterations`", "", &P::max_iterations},
    // dt = 1/120 s at 60 fps: a falling column of 0.8 m reaches ~4 m/s, under two spacings a step.
    {"solver.substeps", K::Whole, "chosen", double(P::kChosenSubsteps), KeyRange{1, 1000}, "",
     "steps per frame, dt = 1/(fps·substeps); left out: the fewest that keep dt ≤ 1/120 s, a fall through the domain "
     "within h a step and a moving solid's surface within half a spacing (2 for the built-in scenes; the run's first "
     "line says which); set, too few for a moving solid is an error",
     "", &P::substeps},
    // h = 2 spacings: ~33 neighbours inside h on a lattice, the usual SPH choice.
    // The range's edges measured (docs/physics.md, "Accepted ranges").
    {"solver.kernel_ratio", K::Number, {}, 2.0, KeyRange{2, 4}, "", "h / particle_spacing",
     "below 2 spacings the passes make energy (1.5: +28-54 % in the dam break) or the tank at rest churns (1.8: 0.4 m/s)",
     &P::kernel_ratio},
    // The GPU computes in float: below 1e-3 a particle's mass at the smallest spacing (1e-21 kg at
    // 1e-6 m) and the energies summed from it near float's smallest numbers (tests/scale_test.cpp).
    {"solver.rest_density", K::Number, {}, 1000.0, KeyRange{1e-3, 1e6}, "kg/m³", "ρ0 (water)",
     "the GPU's float arithmetic holds the lightest particles (1e-3 kg/m³ at 1e-6 m spacing) and no lighter",
     &P::rest_density},
    // Relative to the denominator's own scale, so that it means the same at any spacing.
    {"solver.relaxation", K::Number, {}, 0.01, KeyRange{0, 1e6, true}, "",
     "ε as a fraction of an interior particle's Σ‖∇C‖²: keeps λ bounded where neighbours are few", "",
     &P::relaxation},
    // Gain 1 corrects no density mode by more than its own error; past 4/3 a step grows it.
    {"solver.jacobi_gain", K::Number, {}, 1.0, KeyRange{0, 1, true}, "",
     "the most any density mode is corrected per step, as a fraction of its error (sets each pass's under-relaxation)",
     "a constraint pass that moves a mode past its error makes energy", &P::jacobi_gain},
    // Averaging λ cuts the worst mode's gain and leaves the long modes': the pairs run bolder.
    {"solver.lambda_smoothing", K::Whole, "chosen", double(P::kChosenSmoothing), KeyRange{0, 4}, "",
     "0, 2 or 4 averages of λ before a pair of iterations' Δp; left out: four from 3 iterations on where a step moves "
     "at most h, else two (the run's first line says which)",
     "", &P::lambda_smoothing},
    // 2 % of the kernel-averaged relative velocity a step damps noise without thickening a dam break.
    // The range's upper edge measured (docs/physics.md, "Accepted ranges"): where the fluid is
    // squeezed several times rho0 (pbf@1's floor), the sum over its many neighbours overshoots.
    {"solver.xsph", K::Number, {}, 0.02, KeyRange{0, 0.3}, "", "XSPH viscosity c",
     "past 0.3 the smoothing overshoots where the fluid piles up (pbf@1's dam break: 0.4 +10 %, 0.5 and 1 blew up)",
     &P::xsph},
    // Off unless a scene asks: it adds energy and a pass.
    {"solver.vorticity", K::Number, {}, 0.0, KeyRange{0, 1}, "m/s", "vorticity confinement ε (0: pass not run)",
     "the confinement adds energy: at 2 m/s the dam break blew up (pbf@1)", &P::vorticity},
    // 0.2 times the sum's largest eigenvalue (~5 at h = 2 spacings) is 1: the most an explicit
    // damping takes off a mode in one step without reversing it.
    {"solver.damping", K::Number, {}, 0.2, KeyRange{0, 0.3}, "",
     "a pairwise dashpot on the relative normal velocity; keeps momentum, only removes energy",
     "past that the explicit dashpot reverses the fastest modes", &P::damping},
    // Half the stiffness the step carries: 0.25-0.9 all lose energy; 0.5 keeps a margin below the limit.
    {"solver.ldc_strength", K::Number, {}, 0.5, KeyRange{0, 1, false, true}, "",
     "LDC's K as a fraction of the largest K the step carries, 4/(dt² s): the same meaning at any dt and spacing",
     "a fraction of the stiffness the step carries", &P::ldc_strength},
    {"solver.ldc_k", K::Number, "from `ldc_strength`", -1.0, KeyRange{0, kInf}, "1/s²",
     "LDC strength K stated directly; refused at or past the step's limit", "", &P::ldc_k},
    // The LDC paper's force reads a free surface's missing neighbours as low density and lifts a tank at rest.
    {"solver.ldc_clamp", K::Boolean, {}, 1.0, {}, "",
     "LDC reads densities below ρ0 as ρ0 (false: the LDC paper's force)", "", &P::ldc_clamp},
    // On: a demo's dam break should foam; it costs nothing where nothing draws or exports it.
    {"white_water.enabled", K::Boolean, {}, 1.0, {}, "",
     "spray, foam and bubbles (massless, made from the solver's fields) in fluid-style frames and `--export`", "",
     &W::enabled},
    // As many as the fluid's particles: enough for the dam break's front and wall at its peak.
    {"white_water.max_particles", K::Whole, "chosen", double(W::kChosenCapacity), KeyRange{1, double(kMaxParticles)}, "",
     "white water alive at once; at the cap no more is born until some dies; left out: as many as the fluid's "
     "particles (the run's first line says which)",
     "", &W::max_particles},
    // Ihmsen et al. 2012 give foam 2-5 s; shorter keeps a demo's floor from turning white.
    {"white_water.lifetime", K::Number, {}, 1.5, KeyRange{0, 60, true}, "s",
     "mean life of a white water particle (each lives 0.5-1.5 times it)", "", &W::lifetime},
    {"white_water.emission", K::Number, {}, 35.0, KeyRange{0, 1e4}, "1/s",
     "white water born per fluid particle per second where air is trapped or a crest runs out fast", "",
     &W::emission},
    {"camera.eye", K::Vector, "framing the domain", {}, {}, "m",
     "where the renderer looks from; left out: from the front, 30° up, as close as the domain fits a 16:9 image", "",
     {}},
    {"camera.target", K::Vector, "the domain's centre", {}, {}, "m", "where it looks at; must differ from the eye", "",
     {}},
    {"camera.fov", K::Number, {}, 45.0, KeyRange{1, 179, true, true}, "°", "vertical field of view", "",
     &Camera::fov_degrees},
};

// A number as a message shows it: %g without the exponent's sign and padding (1e-6, 1e6).
std::string show(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  std::string out;
  for (const char* c = text; *c; ++c) {
    const bool exponent_sign = *c == '+' && c > text && c[-1] == 'e';
    const bool exponent_pad = *c == '0' && c - text >= 2 && (c[-1] == '-' || c[-1] == '+') && c[-2] == 'e';
    if (!exponent_sign && !exponent_pad) out += *c;
  }
  return out;
}

}  // namespace

std::span<const SceneKey> scene_keys() { return kKeys; }

std::string describe_range(const KeyRange& r) {
  std::ostringstream m;
  m << (r.lo_open ? "(" : "[") << show(r.lo) << ", " << show(r.hi) << (r.hi_open || std::isinf(r.hi) ? ")" : "]");
  return m.str();
}

namespace {
// A group's key into its parameters in the Scene: a whole number or boolean as such.
template <class P, class V>
void set(V P::*member, double v, Scene& s) {
  P* group = nullptr;
  if constexpr (std::is_same_v<P, SolverParams>) group = &s.solver;
  if constexpr (std::is_same_v<P, WhiteWaterParams>) group = &s.white_water;
  group->*member = std::is_same_v<V, bool> ? V(v != 0) : V(v);
}
void assign_param(const ParamTarget& target, double v, Scene& s) {
  std::visit(
      [&](auto member) {
        if constexpr (!std::is_same_v<decltype(member), std::monostate>) set(member, v, s);
      },
      target);
}
}  // namespace

void assign(const SceneKey& k, double v, Scene& s) {
  std::visit(
      [&](auto member) {
        using T = decltype(member);
        if constexpr (std::is_same_v<T, double Scene::*>) s.*member = v;
        else if constexpr (std::is_same_v<T, int Scene::*>) s.*member = int(v);
        else if constexpr (std::is_same_v<T, bool Scene::*>) s.*member = v != 0;
        else if constexpr (std::is_same_v<T, ParamTarget>) assign_param(member, v, s);
        else if constexpr (std::is_same_v<T, double Camera::*>) s.camera.*member = v;
      },
      k.target);
}

Scene scene_defaults() {
  Scene s{};
  s.solver.method = Method::Pbf;
  s.gravity = {0, -9.81, 0};
  for (const SceneKey& k : kKeys)
    if (k.value) assign(k, *k.value, s);
  return s;
}

std::string shown_default(const SceneKey& k) {
  if (!k.shown.empty() || !k.value) return std::string(k.shown);
  if (k.kind == K::Boolean) return *k.value != 0 ? "true" : "false";
  if (k.kind == K::Whole) return std::to_string(int64_t(*k.value));
  return show(*k.value);
}

std::string scene_keys_markdown() {
  std::ostringstream m;
  m << "| key | default | range | unit | meaning |\n|---|---|---|---|---|\n";
  for (const SceneKey& k : kKeys) {
    std::string range = k.range ? describe_range(*k.range) : "";
    if (k.kind == K::Whole && k.range) range = show(k.range->lo).append(" to ").append(show(k.range->hi));
    m << "| `" << k.name << "` | " << shown_default(k) << " | " << range << " | " << k.unit << " | " << k.meaning << " |\n";
  }
  return m.str();
}

}  // namespace pbflow
