#pragma once
// The particles a scene's fluid starts with.
#include <glm/glm.hpp>

#include <vector>

#include "scene/scene.hpp"

namespace pbflow {

// Lattice points of `particle_spacing` filling the fluid blocks (cell centres, so
// that a block [a, b] holds (b - a)/spacing particles per axis) and the fluid spheres
// (a lattice from the domain's corner); overlaps counted once; none where an obstacle
// grown by half a spacing would push it out.
std::vector<glm::dvec3> initial_particles(const Scene& scene);

}  // namespace pbflow
