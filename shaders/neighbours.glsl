// A step's neighbour sets (DESIGN.md, step 5): the first pass after a grid build walks
// the 27 cells around each particle (FOR_EACH_CANDIDATE) and lists the particles within
// h of it (build_neighbour_list); every pass reads the list (FOR_EACH_NEIGHBOUR) instead
// of walking the ~8x as many candidates again. A list holds
// at most NEIGHBOUR_CAPACITY entries; the count goes on past it (squeezed fluid), and
// such a particle is never cut short: later passes walk its cells instead, so a full
// list costs time, not neighbours. A capacity of 0 means no lists at all (one would not
// fit the device's storage buffer range, host/memory_estimate.hpp): every pass walks.
//
// The includer defines NEIGHBOUR_BINDING (the count buffer; the list is the next
// binding), NEIGHBOUR_CAPACITY_ID (its next free specialisation constant), and in a pass
// that builds lists NEIGHBOUR_BUILDER and NEIGHBOUR_X, the positions they are built from.
// It needs `cell_start`. The list is
// neighbour-major, entry k of particle i at k * count + i, so that adjacent invocations
// read adjacent words.
layout(constant_id = NEIGHBOUR_CAPACITY_ID) const uint NEIGHBOUR_CAPACITY = 64;  // Derived::neighbour_capacity
#ifdef NEIGHBOUR_BUILDER
#define NEIGHBOUR_ACCESS
#else
#define NEIGHBOUR_ACCESS readonly
#endif
layout(std430, binding = NEIGHBOUR_BINDING) NEIGHBOUR_ACCESS buffer NeighbourCount { uint neighbour_count[]; };
layout(std430, binding = NEIGHBOUR_BINDING + 1) NEIGHBOUR_ACCESS buffer NeighbourList { uint neighbour_list[]; };

// The 27 cells around position xi, clipped to the grid: the first and last cell per axis.
ivec3 first_cell(vec3 xi) { return max(cell_of(xi) - 1, ivec3(0)); }
ivec3 last_cell(vec3 xi) { return min(cell_of(xi) + 1, sim.grid - 1); }
// Cells are numbered x-fastest, so each row of three cells (x from first.x to last.x at
// y, z) is one contiguous range of the sorted particles: nine ranges instead of 27.
uint row_begin(ivec3 first, int y, int z) { return cell_start[cell_id(ivec3(first.x, y, z))]; }
uint row_end(ivec3 last, int y, int z) { return cell_start[cell_id(ivec3(last.x, y, z)) + 1u]; }

// Loops j over every particle binned in the 27 cells around position xi (the body tests
// the distance).
#define FOR_EACH_CANDIDATE(xi, j)                                                          \
  ivec3 first_##j = first_cell(xi), last_##j = last_cell(xi);                              \
  for (int z_##j = first_##j.z; z_##j <= last_##j.z; ++z_##j)                              \
    for (int y_##j = first_##j.y; y_##j <= last_##j.y; ++y_##j)                            \
      for (uint j = row_begin(first_##j, y_##j, z_##j), end_##j = row_end(last_##j, y_##j, z_##j); \
           j < end_##j; ++j)

#ifdef NEIGHBOUR_BUILDER
// Lists the particles within h of particle i at xi (positions NEIGHBOUR_X), and stores
// the count. Only this loop walks the candidates: a pass's own sum then reads the list,
// for on SIMD lanes (lavapipe's 8, a GPU's 32) a sum inside the walk runs, masked, for
// all ~8x as many candidates as there are neighbours (the first lambda pass took 6.9 ms
// instead of 4.5 on lavapipe, peer scene).
void build_neighbour_list(uint i, vec3 xi) {
  if (NEIGHBOUR_CAPACITY == 0u) {  // no lists (too large for the device): every pass walks
    neighbour_count[i] = 1u;
    return;
  }
  uint listed = 0u;
  FOR_EACH_CANDIDATE(xi, j) {
    vec3 d = xi - NEIGHBOUR_X[j].xyz;
    if (dot(d, d) >= sim.h * sim.h) continue;
    if (listed < NEIGHBOUR_CAPACITY) neighbour_list[listed * sim.count + i] = j;
    ++listed;
  }
  neighbour_count[i] = listed;
}
#endif

// Reading the lists: a particle's entries, or, where its list overflowed, every particle
// in its 27 cells (the body tests r < h).
struct Neighbours {
  uint i, k, n;        // the particle, entries read, entries listed
  bool cells;          // the list overflowed: walking the cells
  ivec3 first, last;   // the walk's cells (first_cell, last_cell)
  int y, z;            // its current row
  uint j, end;         // the sorted range of that row
};

Neighbours neighbours_of(uint i, vec3 xi) {
  Neighbours w;
  w.i = i;
  w.k = 0u;
  w.n = neighbour_count[i];
  w.cells = w.n > NEIGHBOUR_CAPACITY;
  w.first = first_cell(xi);
  w.last = last_cell(xi);
  w.y = w.first.y - 1;  // the first step of the walk opens row (first.y, first.z)
  w.z = w.first.z;
  w.j = w.end = 0u;
  return w;
}

bool next_neighbour(inout Neighbours w, out uint j) {
  if (!w.cells) {
    if (w.k >= w.n) return false;
    j = neighbour_list[w.k++ * sim.count + w.i];
    return true;
  }
  while (w.j >= w.end) {  // the next row of three cells (FOR_EACH_CANDIDATE's order)
    if (++w.y > w.last.y) {
      w.y = w.first.y;
      if (++w.z > w.last.z) return false;
    }
    w.j = row_begin(w.first, w.y, w.z);
    w.end = row_end(w.last, w.y, w.z);
  }
  j = w.j++;
  return true;
}

// for each listed neighbour j of particle i at xi (j = i included):
// FOR_EACH_NEIGHBOUR(i, xi, j) { ... }
#define FOR_EACH_NEIGHBOUR(i, xi, j)            \
  Neighbours walk_##j = neighbours_of(i, xi); \
  for (uint j; next_neighbour(walk_##j, j);)
