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
std::vector<glm::dvec3> lattice_particles(const Scene& scene);

// Each lattice point moved by up to kSeedJitter spacings along each axis (uniform, from the
// scene's `seed` key: one seed, one start). A lattice's order outlives the flow: its columns
// drew stripes on the water's faces, and the drop's mirror symmetry a seam that no particle
// crossed (docs/rendering.md). A solver starts from this seed relaxed (sim/settle.hpp).
inline constexpr double kSeedJitter = 0.25;
std::vector<glm::dvec3> initial_particles(const Scene& scene);

}  // namespace pbflow
