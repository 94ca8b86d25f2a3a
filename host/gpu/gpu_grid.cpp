#include "gpu/gpu_grid.hpp"

#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace pbflow {

GpuGrid::GpuGrid(const vk::Context& ctx, const GridBuffers& plan)
    : count_(ctx, "grid_count", sizeof(SimConstants)),
      order_(ctx, "grid_order", sizeof(SimConstants)),
      scatter_(ctx, "grid_scatter", sizeof(SimConstants)),
      cell_(ctx, plan.cell),
      rank_(ctx, plan.rank),
      slots_(ctx, plan.order),
      scan_(ctx, plan.scan) {}

void GpuGrid::build(vk::CommandList& cmd, const SimConstants& sim, Particles in, Particles out) {
  cmd.fill(scan_.data(), 0);
  cmd.set_program(count_);
  cmd.bind("x", *in.x);
  cmd.bind("cell", cell_);
  cmd.bind("rank", rank_);
  cmd.bind("count", scan_.data());
  cmd.push(sim);
  cmd.dispatch(sim.count);

  scan_.run(cmd);

  cmd.set_program(order_);
  cmd.bind("cell", cell_);
  cmd.bind("rank", rank_);
  cmd.bind("cell_start", scan_.data());
  cmd.bind("order", slots_);
  cmd.push(sim);
  cmd.dispatch(sim.count);

  cmd.set_program(scatter_);
  cmd.bind("order", slots_);
  cmd.bind("cell", cell_);
  cmd.bind("cell_start", scan_.data());
  cmd.bind("x_in", *in.x);
  cmd.bind("payload_in", *in.payload);
  cmd.bind("id_in", *in.id);
  cmd.bind("x_out", *out.x);
  cmd.bind("payload_out", *out.payload);
  cmd.bind("id_out", *out.id);
  cmd.push(sim);
  cmd.dispatch(sim.count);
}

}  // namespace pbflow
