#pragma once
// The uniform grid on the GPU, built by counting sort: each particle's cell and a rank in it
// (atomics), an exclusive prefix sum over all cells (GpuScan), each cell's particles ranked by
// their index (the same order on every run), then a scatter that reorders the particle data
// by cell.
#include "gpu/gpu_scan.hpp"
#include "sim/params.hpp"

namespace pbflow {

class GpuGrid {
 public:
  GpuGrid(const vk::Context& ctx, const GridBuffers& plan);

  // Particle data that travels with the sort: positions, one more vec4 array, ids.
  struct Particles {
    const vk::Buffer* x;
    const vk::Buffer* payload;
    const vk::Buffer* id;
  };
  // Bins `in.x` and writes in's arrays to `out` in cell order; cell_start() then holds,
  // for every cell c, the first sorted index of c (and the total at index cells).
  void build(vk::CommandList& cmd, const SimConstants& sim, Particles in, Particles out);
  const vk::Buffer& cell_start() const { return scan_.data(); }

 private:
  vk::Program count_, order_, scatter_;
  vk::Buffer cell_, rank_, slots_;  // slots_: each cell's particles in the count's order (grid_order.comp)
  GpuScan scan_;                    // a count per cell, scanned in place into cell_start
};

}  // namespace pbflow
