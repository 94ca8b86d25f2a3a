#include "gpu/buffer_plan.hpp"

#include <algorithm>

#include "sim/solids/obstacles.hpp"

namespace pbflow {

namespace {

uint64_t scan_blocks(uint64_t values) { return (values + kScanBlock - 1) / kScanBlock; }

GridBuffers plan_grid(const Derived& d, uint64_t particles) {
  GridBuffers g;
  g.cell = g.rank = g.order = particles * sizeof(uint32_t);
  g.scan = plan_scan(uint64_t(d.grid.x) * d.grid.y * d.grid.z);
  return g;
}

}  // namespace

ScanBuffers plan_scan(uint64_t values) {
  ScanBuffers s;
  // One more entry than values: after the exclusive scan it holds the total, so that value
  // k's range is [start[k], start[k + 1]) for every k.
  uint64_t size = values + 1;
  for (;;) {
    s.level_entries.push_back(uint32_t(size));
    s.levels.push_back(scan_blocks(size) * kScanBlock * sizeof(uint32_t));  // the scan moves whole blocks
    if (size == 1) break;
    // The next level holds this one's block sums, or only its total where it scans in one group.
    size = scan_blocks(size) <= kOneGroupBlocks ? 1 : scan_blocks(size);
  }
  return s;
}

uint64_t ScanBuffers::total() const {
  uint64_t sum = 0;
  for (uint64_t level : levels) sum += level;
  return sum;
}

SolverBuffers plan_buffers(const Derived& d, uint64_t particles, FrameOutputs outputs) {
  const uint64_t vec4 = particles * sizeof(glm::vec4), word = particles * sizeof(uint32_t);
  SolverBuffers b;
  b.particle_vec4 = vec4;
  b.id = b.rho = word;
  b.neighbour_count = ((d.obstacles.empty() ? 2 : 3) * particles + 2) * sizeof(uint32_t);  // and the near list
  b.neighbour_list = word * list_words(d.neighbour_capacity);
  b.x_lambda_spare = d.smooths_lambda() ? vec4 : 0;
  b.curl = d.solver.vorticity > 0 ? vec4 : 0;
  b.partials = 2 * partial_count(particles) * sizeof(glm::vec4);
  b.obstacles = packed_obstacle_vec4s(d.obstacles) * sizeof(glm::vec4);
  b.watch = sizeof(WatchWords);
  b.work = d.moving() ? word : sizeof(float);
  b.crease_records = (any_mesh(d.obstacles) ? particles : 1) * 4 * sizeof(glm::vec4);
  b.distances = keeps_distances(d) ? d.obstacles.size() * word : sizeof(float);
  b.overflow_groups = 2 * NEAR_GROUPS_WORD * sizeof(uint32_t);  // two dispatches (neighbour_lists.comp)
  b.adaptive_words = d.solver.target_compression > 0 ? 2 * sizeof(glm::vec4) : 0;
  if (d.coarse.strength > 0) {
    const uint64_t nodes = uint64_t(d.coarse.count());
    b.coarse_sums = (COARSE_WORDS * nodes + COARSE_TOTALS) * sizeof(uint32_t);
    b.coarse_phi = nodes * sizeof(float);
    b.coarse_open = nodes * sizeof(float);
    b.coarse_grad = nodes * sizeof(glm::vec4);
  }
  b.grid = plan_grid(d, particles);
  if (!d.drains.empty()) {
    b.drains = 2 * d.drains.size() * sizeof(glm::vec4);
    b.drained = 2 * vec4;
    b.drain_counts = 2 * sizeof(uint32_t);
    b.drain_keep = plan_scan(particles);
  }
  b.body_push = d.bodies.size() * BODY_PUSH_WORDS * sizeof(uint32_t);
  if (outputs.surface) b.shape = 2 * vec4;
  if (outputs_made(d, outputs).white_water) {
    b.white_count = 2 * sizeof(uint32_t);
    b.white_array = uint64_t(d.white_water.max_particles) * sizeof(glm::vec4);
    b.white_survivors = plan_scan(uint64_t(d.white_water.max_particles));
    b.white_births = plan_scan(particles);
  }
  return b;
}

uint64_t SolverBuffers::total() const {
  uint64_t sum = (kParticleVec4s + 1) * particle_vec4 + kIdArrays * id + rho + neighbour_count + neighbour_list +
                 x_lambda_spare + curl + partials + obstacles + work + crease_records + 2 * distances + watch + overflow_groups + 3 * adaptive_words +
                 coarse_sums + coarse_phi + coarse_grad + coarse_open + result + grid.cell + grid.rank + grid.order + shape +
                 white_water() + grid.scan.total() + drains + drained + drain_counts + drain_keep.total() +
                 2 * body_push + (body_push ? coarse_grad : 0);
  return sum;
}

uint64_t SolverBuffers::white_water() const {
  return white_count + kWhiteLists * 2 * white_array + white_survivors.total() + white_births.total();
}

uint64_t SolverBuffers::largest() const {
  return std::max({particle_vec4, neighbour_list, neighbour_count, grid.scan.levels.front(), shape});
}

}  // namespace pbflow
