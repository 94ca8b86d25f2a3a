#pragma once
// The one place that picks a solver for a device: the run, the benchmarks and the tests share it.
#include <glm/glm.hpp>

#include <memory>
#include <string>
#include <vector>

#include "sim/params.hpp"
#include "sim/solver.hpp"

namespace pbflow {

namespace vk {
class Context;
}

// The Vulkan context for `device`, or null for "cpu" (the reference solver).
std::unique_ptr<vk::Context> make_context(const std::string& device, bool validate);
// The reference solver where `ctx` is null, else the GPU solver on it; `ctx` must outlive it.
std::unique_ptr<Solver> make_solver(const vk::Context* ctx, const Derived& d, const std::vector<glm::dvec3>& x0);

}  // namespace pbflow
