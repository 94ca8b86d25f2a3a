// Reading a step's neighbour sets (docs/design.md, "The passes"), as built by neighbour_lists.comp.
// Every neighbour pass comes in variants (specialisation constants), each over its own particles:
// - the list readers, over every particle whose list holds all its neighbours;
// - where the scene has obstacles, those readers split in two: the near readers, over the
//   particles that had an obstacle within h when the lists were built (the lists pass collects
//   them and flags their counts, NEAR_FLAG), and the rest, whose only mirrors are the walls
//   (OBSTACLE_MIRRORS false, solids.glsl): a CPU device runs an obstacle's image for every
//   neighbour of every particle, masked, and a mesh's field code in a loop's body slowed a GPU's
//   loop where no particle took it (docs/performance.md);
// - the cell walkers, over the particles whose lists overflowed (squeezed fluid; the
//   lists pass collects them after the counts, and the host dispatches them indirectly),
//   or over every particle where there are no lists (capacity 0). The body then tests r < h.
// Two variants, not one loop that can do both: a CPU device runs every branch for all SIMD
// lanes, masked, and every loop at least once, so a cell walk kept in the readers' loop
// for the rare overflow cost every particle a row of the walk per neighbour
// (docs/performance.md, "Measurements behind the code").
//
// The includer defines NEIGHBOUR_BINDING (the counts; the list is the next binding) and
// NEIGHBOUR_CAPACITY_ID (its last specialisation constant; WALK_CELLS is the next).
// It also defines OBSTACLES_BINDING: every solid is a mirror (solids.glsl); and
// CREASES_BINDING, the particles' crease records.
// Binding 0 is the grid's cell_start (grid_walk.glsl). All three are read-only storage
// texel buffers (vk/program.hpp): counts and cell_start R32_UINT, the list
// R32G32B32A32_UINT, four entries a fetch.
#include "grid_walk.glsl"
#include "solids.glsl"
layout(constant_id = NEIGHBOUR_CAPACITY_ID) const uint NEIGHBOUR_CAPACITY = 64;  // Derived::neighbour_capacity
layout(constant_id = NEIGHBOUR_CAPACITY_ID + 1) const bool WALK_CELLS = false;
// The counts, then the overflow list's length, the near list's, the overflow list, the near list
// (neighbour_lists.comp; the near list where the scene has obstacles).
layout(binding = NEIGHBOUR_BINDING, r32ui) uniform readonly uimageBuffer neighbour_count;
layout(binding = NEIGHBOUR_BINDING + 1, rgba32ui) uniform readonly uimageBuffer neighbour_list;

// Each particle's creases, found when the lists were built (neighbour_lists.comp, take_creases).
layout(std430, binding = CREASES_BINDING) readonly buffer CreaseRecords { vec4 crease_records[]; };

// i's mirrors for a reader: a list's obstacle images were tested when it was built, and i's
// creases found then.
Mirrors neighbour_mirrors(uint i, vec3 xi) {
  Mirrors m = mirrors_near(xi);
  m.listed = !WALK_CELLS && NEIGHBOUR_CAPACITY > 0u;
  if (mirrors_mesh())
    take_creases(m, crease_records[4u * i], crease_records[4u * i + 1u], crease_records[4u * i + 2u], crease_records[4u * i + 3u]);
  return m;
}

// The near readers' variant: where the scene has obstacles, the readers that mirror them.
const bool NEAR_READERS = MIRRORS_OBSTACLES && !WALK_CELLS;

// Entry t of the overflow list (0) or the near list (1), if it has one.
bool listed_particle(uint list, uint t, out uint i) {
  if (t >= imageLoad(neighbour_count, int(sim.count + list)).x) return false;
  i = imageLoad(neighbour_count, int(sim.count + 2u + list * sim.count + t)).x;
  return true;
}

// The particle this invocation serves, if any: its own for the list readers, its entry in the
// near list for the near readers (each skipping overflowed lists, which the cell walkers redo,
// and the readers the near readers' flagged ones: a pass's variants run at once), its entry in
// the overflow list for the cell walkers, its own again where there are no lists.
bool neighbour_pass_particle(out uint i) {
  uint t = thread_index();
  if (WALK_CELLS && NEIGHBOUR_CAPACITY > 0u) return listed_particle(0u, t, i);
  if (NEAR_READERS)
    return listed_particle(1u, t, i) && (imageLoad(neighbour_count, int(i)).x & ~NEAR_FLAG) <= NEIGHBOUR_CAPACITY;
  i = t;
  return i < sim.count && (WALK_CELLS || imageLoad(neighbour_count, int(i)).x <= NEIGHBOUR_CAPACITY);
}

// An entry is a neighbour j within h of i, or one of j's images behind the solids within h
// (image_entry, common.glsl). The images are entries, not a loop in every reader's body: on
// a CPU device a loop runs at least once per neighbour, masked, even where no particle of the
// SIMD group is near a wall (the image loop was a third of the constraint passes).
struct Neighbours {
  uint i, k, n;        // the particle, entries read (a multiple of four), entries listed
  uvec4 group;         // the round's entries: four listed, or the cell walk's candidate
  int axes;            // the cell walk's: i's mirrors (Mirrors.axes), whose images it yields
  int image;           // the cell walk's: the image of candidate j - 1 it yielded last
  ivec3 first, last;   // the cell walk's cells (first_cell, last_cell)
  int y, z;            // its current row
  uint j, end;         // the sorted range of that row
};

Neighbours neighbours_of(uint i, vec3 xi, Mirrors mirrors) {
  Neighbours w;
  w.i = i;
  w.k = 0u;
  w.n = WALK_CELLS ? 0u : imageLoad(neighbour_count, int(i)).x & ~NEAR_FLAG;
  w.group = uvec4(0u);
  w.axes = mirrors.axes;
  w.image = 0;
  w.first = first_cell(xi);
  w.last = last_cell(xi);
  w.y = w.first.y - 1;  // the first step of the walk opens row (first.y, first.z)
  w.z = w.first.z;
  w.j = w.end = 0u;
  return w;
}

// The cell walk's next candidate, or the last one's next image.
bool next_candidate(inout Neighbours w, out uint j, out int image) {
  // The last candidate's next image (its images follow it: 0 first, then every subset of
  // the axes), as the lists pass would list them, beyond h or not. end > 0 once a
  // candidate was yielded: a row is only left open with one taken from it.
  int next = w.image == 0 ? w.axes : next_image(w.axes, w.image);
  if (w.end > 0u && next != 0) {
    j = w.j - 1u;
    image = w.image = next;
    return true;
  }
  while (w.j >= w.end) {  // the next row of three cells (neighbour_lists.comp's order)
    if (++w.y > w.last.y) {
      w.y = w.first.y;
      if (++w.z > w.last.z) return false;
    }
    w.j = row_begin(w.first, w.y, w.z);
    w.end = row_end(w.last, w.y, w.z);
  }
  j = w.j++;
  image = w.image = 0;
  return true;
}

// The walk goes in rounds of ROUND entries, each entry's body under an `if`: a list
// reader's round is the four entries of one fetch, a cell walker's one candidate. The
// rounds' inner loop has a constant trip count, so the compiler unrolls it: on a CPU device
// every loop iteration costs a mask update and an all-lanes test. A body must not use
// `continue`: it keeps the loop from being unrolled. Both measured: docs/performance.md,
// "Measurements behind the code".
const uint ROUND = WALK_CELLS ? 1u : 4u;

bool next_round(inout Neighbours w) {
  if (!WALK_CELLS) {  // a constant: the other variant's code is compiled out
    if (w.k >= w.n) return false;
    w.group = imageLoad(neighbour_list, int((w.k >> 2) * sim.count + w.i));
    w.k += 4u;  // the round's last entries may lie past n: round_entry masks them
    return true;
  }
  uint j;
  int image;
  if (!next_candidate(w, j, image)) return false;
  w.group.x = image_entry(j, image);
  return true;
}

// Entry q of the round: false past the list's end.
bool round_entry(Neighbours w, uint q, out uint j, out int image) {
  uint entry = w.group[q];
  j = entry & IMAGE_INDEX_MASK;
  image = int(entry >> IMAGE_SHIFT);
  return WALK_CELLS || w.k - 4u + q < w.n;
}

// for each neighbour j of particle i at xi and its images behind i's mirrors: j's position
// is mirror(mirrors, image, j, x_j) (image 0: j itself). j = i is included, and so are i's own
// images; the cell walkers' candidates include particles beyond h, the body tests r < h.
// FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) { ... }   (no `continue` in the body: see ROUND)
#define FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image)     \
  Neighbours walk_##j = neighbours_of(i, xi, mirrors); \
  while (next_round(walk_##j))                       \
    for (uint q_##j = 0u, j; q_##j < ROUND; ++q_##j)  \
      if (round_entry(walk_##j, q_##j, j, image))
