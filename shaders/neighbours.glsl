// Reading a step's neighbour sets (DESIGN.md, step 5), as built by neighbour_lists.comp:
// a particle's listed entries, or, where its list overflowed, every particle in its 27
// cells (the body then tests r < h).
//
// The includer defines NEIGHBOUR_BINDING (the counts; the list is the next binding) and
// NEIGHBOUR_CAPACITY_ID (its next free specialisation constant). Binding 0 is the grid's
// cell_start (grid_walk.glsl). All three are texel buffers: counts and cell_start
// R32_UINT, the list R32G32B32A32_UINT, four entries a fetch.
#include "grid_walk.glsl"
layout(constant_id = NEIGHBOUR_CAPACITY_ID) const uint NEIGHBOUR_CAPACITY = 64;  // Derived::neighbour_capacity
layout(binding = NEIGHBOUR_BINDING) uniform usamplerBuffer neighbour_count;
layout(binding = NEIGHBOUR_BINDING + 1) uniform usamplerBuffer neighbour_list;

struct Neighbours {
  uint i, k, n;        // the particle, entries read, entries listed
  uvec4 group;         // the four entries from k & ~3 on
  bool cells;          // the list overflowed: walking the cells
  ivec3 first, last;   // the walk's cells (first_cell, last_cell)
  int y, z;            // its current row
  uint j, end;         // the sorted range of that row
};

Neighbours neighbours_of(uint i, vec3 xi) {
  Neighbours w;
  w.i = i;
  w.k = 0u;
  w.n = texelFetch(neighbour_count, int(i)).x;
  w.group = uvec4(0u);
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
    if ((w.k & 3u) == 0u) w.group = texelFetch(neighbour_list, int((w.k >> 2) * sim.count + w.i));
    j = w.group[w.k & 3u];
    ++w.k;
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
