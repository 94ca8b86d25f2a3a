// Walking the grid: the 27 cells around a position, as nine contiguous ranges of the
// sorted particles. cell_start (binding 0) is read through a texel view, like every array a
// neighbour pass gathers from (host/vk/program.hpp says why).
layout(binding = 0, r32ui) uniform readonly uimageBuffer cell_start;

// The 27 cells around position xi, clipped to the grid: the first and last cell per axis.
ivec3 first_cell(vec3 xi) { return max(cell_of(xi) - 1, ivec3(0)); }
ivec3 last_cell(vec3 xi) { return min(cell_of(xi) + 1, sim.grid - 1); }
// Cells are numbered x-fastest, so each row of three cells (x from first.x to last.x at
// y, z) is one contiguous range of the sorted particles: nine ranges instead of 27.
uint row_begin(ivec3 first, int y, int z) { return imageLoad(cell_start, int(cell_id(ivec3(first.x, y, z)))).x; }
uint row_end(ivec3 last, int y, int z) { return imageLoad(cell_start, int(cell_id(ivec3(last.x, y, z)) + 1u)).x; }
