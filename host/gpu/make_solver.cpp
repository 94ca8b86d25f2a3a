#include "gpu/make_solver.hpp"

#include "gpu/gpu_solver.hpp"
#include "gpu/memory_estimate.hpp"
#include "sim/reference_solver.hpp"
#include "vk/context.hpp"

namespace pbflow {

std::unique_ptr<vk::Context> make_context(const std::string& device, bool validate) {
  if (device == "cpu") return nullptr;
  return std::make_unique<vk::Context>(vk::Context::Options{device, validate, 0});
}

std::unique_ptr<Solver> make_solver(const vk::Context* ctx, const Derived& d, const std::vector<glm::dvec3>& x0) {
  if (!ctx) return std::make_unique<ReferenceSolver>(d, x0);
  Derived on_device = d;
  // The lists hold every particle the solver has room for (Derived::capacity_for), as the
  // memory estimate counts them: a flow's room can take them past the device's largest array.
  on_device.neighbour_capacity = neighbour_capacity_on(d, double(d.capacity_for(x0.size())), ctx->info());
  return std::make_unique<GpuSolver>(*ctx, on_device, x0);
}

}  // namespace pbflow
