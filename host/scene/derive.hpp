#pragma once
// What a scene means for the passes: its Derived constants, and the time-step check.
#include <string>

#include "scene/scene.hpp"
#include "sim/params.hpp"

namespace pbflow {

// Everything a pass needs from the scene; throws InputError where the scene's numbers
// leave the solver's stable range (an LDC strength past its limit, a grid too large).
Derived derive(const Scene& scene);

// A CFL-style check: empty when a particle at the fall speed over the domain's height
// moves at most one kernel radius h per step (beyond that it passes neighbours it never
// saw); else a warning naming the substeps that would keep it within h.
std::string time_step_warning(const Scene& scene, const Derived& d);

// What to change after a run diverged, naming only the keys that matter in this run: the
// substeps where a fall outruns h per step, the vorticity where it is on (it adds energy),
// an LDC stiffness raised past its default; else more substeps or iterations.
std::string divergence_advice(const Scene& scene, const Derived& d);

}  // namespace pbflow
