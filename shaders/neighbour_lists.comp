#version 450
// The neighbour lists (docs/design.md, "The passes"): after each grid build, every particle
// walks the 27 cells around it once and lists the particles within h (itself included);
// the passes that follow read the list (neighbours.glsl) instead of walking the ~8x as
// many candidates again. Its own pass, so that the lists are whole before any reader
// gathers them through its read-only texel view (vk/program.hpp).
// A list holds at most NEIGHBOUR_CAPACITY entries; the count goes on past it (squeezed
// fluid), and such a particle is never cut short: it is appended to the overflow list
// after the counts (count[n] entries from count[n + 1] on), and the readers' cell-walking
// variant redoes it in an indirect dispatch whose group counts this pass raises
// (neighbours.glsl).
// Near a wall the list goes on with the neighbours' images within h (common.glsl,
// image_entry), each neighbour's after each other, in the order the cell walkers yield them.
// Where the scene has obstacles the pass has two variants (OBSTACLE_MIRRORS, solids.glsl): the
// walk, over every particle and blind to the obstacles' mirrors, lists the neighbours and, away
// from the obstacles, the walls' images; a particle with an obstacle within h goes to the near
// list instead, its count flagged (NEAR_FLAG), and the near variant, dispatched over that list
// as the cell walkers are, finds its mesh's creases and lists its images: a CPU device runs a
// branch for every lane, masked, and the creases' probes and the images' field reads cost the
// walk of every particle. On a GPU the walk does it all, compiled with the obstacles' mirrors
// (NEAR_IN_WALK), and still collects the near list for the readers: there the near variant's
// dispatch, after the walk's, cost more than the branches. Where there are no lists (capacity 0:
// they would not fit the device, host/gpu/memory_estimate.hpp) the near variant runs over every
// particle for a mesh's creases alone, and the walk not at all. The walk also keeps each
// particle's distance from every obstacle for the near readers of the step (DISTANCES).
// Layout, for the readers' coalesced uvec4 fetches: entries go in groups of four, group g
// of particle i at texel g * count + i (neighbour-major: adjacent invocations read
// adjacent texels), entry k in group k / 4, lane k % 4.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "grid_walk.glsl"
#include "contract.h"
#define OBSTACLES_BINDING 5

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;  // the positions the lists are built at
// count[0, n), then the overflow list's length and the near list's, the overflow list's entries
// from n + 2, the near list's from 2n + 2 (where the scene has obstacles); the host zeroes the lengths.
layout(std430, binding = 2) buffer NeighbourCount { uint neighbour_count[]; };
// Entry k of particle i is neighbour_list[(k / 4) * n + i][k % 4] (entry_group): word
// ((k / 4) * n + i) * 4 + k % 4 of the buffer.
layout(std430, binding = 3) buffer NeighbourList { uvec4 neighbour_list[]; };
// The cell walkers' VkDispatchIndirectCommand, then the near readers' (from NEAR_GROUPS_WORD,
// contract.h), each reset by the host to (0, 1, 1). They run this pass's workgroup size; a count
// past the device's x limit folds into y.
layout(std430, binding = 4) buffer OverflowGroups { uint overflow_groups[2 * NEAR_GROUPS_WORD]; };
// Each particle's crease record (solids.glsl, crease_record), for the passes of the step.
layout(std430, binding = 6) writeonly buffer CreaseRecords { vec4 crease_records[]; };
#define DISTANCES_OUT_BINDING 7  // each particle's distances from the obstacles, kept for the step (solids.glsl)
#include "solids.glsl"
layout(constant_id = 1) const uint NEIGHBOUR_CAPACITY = 64;  // Derived::neighbour_capacity (groups rounded up: list_words)
layout(constant_id = 2) const uint MAX_GROUPS_X = 65535;     // maxComputeWorkGroupCount[0]
// Whether the walk finds the near particles' creases and lists their images itself, in one
// dispatch (GpuLayout::near_in_walk: a GPU, where the near variant's dispatch after the walk
// cost more than its branches), rather than leaving them to the near variant.
layout(constant_id = 3) const bool NEAR_IN_WALK = false;

uint entry_group(uint i, uint k) { return (k >> 2) * sim.count + i; }

// Appends an entry to the list; past the capacity only the count goes on. `word` is entry
// `listed`'s word, carried along rather than computed from (listed, i) at the store: a CPU
// device stores lane by lane, and its lane loop redid that arithmetic for every lane from two
// vectors it spilled to the stack each time (docs/performance.md). One view of the buffer, for the stores and the
// image loop's reads: a second (of words) would be a second variable, which SPIR-V lets a
// compiler assume does not alias the first (glslang adds no Aliased decoration).
void list_entry(uint entry, inout uint listed, inout uint word) {
  if (listed < NEIGHBOUR_CAPACITY) neighbour_list[word >> 2][word & 3u] = entry;
  ++listed;
  word += (listed & 3u) == 0u ? 4u * sim.count - 3u : 1u;  // a new group: the next texel's first word
}

// Lists candidate `base + bit` for each bit of `hits`, in order.
void store_hits(uint base, uint hits, inout uint listed, inout uint word) {
  for (; hits != 0u; hits &= hits - 1u) list_entry(base + uint(findLSB(hits)), listed, word);
}

// Appends i to the overflow list (0) or the near list (1) and raises its dispatch's groups.
void join_list(uint list, uint i) {
  uint slot = atomicAdd(neighbour_count[sim.count + list], 1u);
  neighbour_count[sim.count + 2u + list * sim.count + slot] = i;
  uint groups = slot / gl_WorkGroupSize.x + 1u;
  uint first = list * NEAR_GROUPS_WORD;
  atomicMax(overflow_groups[first], min(groups, MAX_GROUPS_X));
  atomicMax(overflow_groups[first + 1u], (groups + MAX_GROUPS_X - 1u) / MAX_GROUPS_X);
}

// The images of i's first `neighbours` entries within h, listed after them (`listed`, `word`).
// An image lies farther than its particle, so only a neighbour's can be within h; in a loop
// of its own, as inside the walk a CPU device would run the image loop for every candidate.
// The neighbours are read four at a time and their images' hits kept as bits, two entries
// a word: bit 16q + 15 - k for image k of the pair's entry q, so that storing them in bit
// order lists each neighbour's images together, in next_image's order (that of the cell
// walkers). An image that does not count lies far away (solids.glsl), never within h.
void list_images(uint i, vec3 xi, Mirrors mirrors, uint neighbours, inout uint listed, inout uint word) {
  for (uint k = 0u; k < neighbours; k += 4u) {
    uvec4 group = neighbour_list[entry_group(i, k)];
    for (uint pair = 0u; pair < 4u; pair += 2u) {
      uint hits = 0u;
      for (uint q = 0u; q < 2u; ++q) {
        bool listed_neighbour = k + pair + q < neighbours;  // the group's last slots may lie past them
        uint j = listed_neighbour ? group[pair + q] : i;
        vec3 xj = imageLoad(x, int(j)).xyz;
        // The obstacle's image once, not once per subset of the walls with it: a CPU device
        // ran it masked in every turn of the loop (docs/performance.md).
        vec3 behind = xj;
        if (MIRRORS_OBSTACLES && (mirrors.axes & OBSTACLE_MIRROR) != 0) behind = obstacle_image(mirrors, j, xj);
        for (int image = mirrors.axes; image != 0; image = next_image(mirrors.axes, image)) {
          vec3 d = xi - across_walls(mirrors, image, (image & OBSTACLE_MIRROR) != 0 ? behind : xj);
          hits |= uint(listed_neighbour && dot(d, d) < sim.h * sim.h) << (16u * q + 15u - uint(image));
        }
      }
      for (; hits != 0u; hits &= hits - 1u) {
        uint bit = uint(findLSB(hits));
        list_entry(image_entry(group[pair + (bit >> 4)], 15 - int(bit & 15u)), listed, word);
      }
    }
  }
}

// Lists i's neighbours within h, in the 27 cells about it; returns how many (listed, word).
uint list_neighbours(uint i, vec3 xi, inout uint word) {
  uint listed = 0u;
  // Each row of three cells is tested in chunks of up to 32 candidates, the hits kept as
  // bits, and only then stored: a CPU device stores to a storage buffer lane by lane, testing
  // each lane's mask, and a store in the test loop ran that for every candidate (~7 of 8
  // miss), over half of this pass. Stored after the chunk it runs as often as the most
  // hits any lane of the SIMD group has.
  ivec3 first = first_cell(xi), last = last_cell(xi);
  for (int z = first.z; z <= last.z; ++z)
    for (int y = first.y; y <= last.y; ++y) {
      uint end = row_end(last, y, z);
      for (uint base = row_begin(first, y, z); base < end; base += 32u) {
        uint hits = 0u;
        for (uint c = 0u; c < min(end - base, 32u); ++c) {
          vec3 d = xi - imageLoad(x, int(base + c)).xyz;
          hits |= uint(dot(d, d) < sim.h * sim.h) << c;
        }
        store_hits(base, hits, listed, word);
      }
    }
  return listed;
}

void write_creases(uint i, Mirrors mirrors) {
  for (int slot = 0; slot < 4; ++slot) crease_records[4u * i + uint(slot)] = crease_record(mirrors, slot);
}

// The walk: i's neighbours, then their images, where no obstacle is within h of i or the walk
// lists the obstacles' too (NEAR_IN_WALK); a particle with one within h joins the near list.
void walk(uint i) {
  vec3 xi = imageLoad(x, int(i)).xyz;
  Mirrors mirrors = mirrors_near(xi);  // the walls' alone, but where the walk lists the obstacles'
  bool near = keep_distances(i, xi) < sim.h, images = NEAR_IN_WALK || !near;  // an obstacle within h
  if (NEAR_IN_WALK && has_shape(MESH)) find_creases(mirrors);
  if (has_shape(MESH) && images) write_creases(i, mirrors);  // none away from a mesh: every record is this step's
  uint word = 4u * i;  // entry 0: group 0, texel i, its first word
  uint neighbours = list_neighbours(i, xi, word), listed = neighbours;
  if (images && mirrors.axes != 0 && listed <= NEIGHBOUR_CAPACITY) list_images(i, xi, mirrors, neighbours, listed, word);
  neighbour_count[i] = listed | (near ? NEAR_FLAG : 0u);
  if (near) join_list(1u, i);
  if (images && listed > NEIGHBOUR_CAPACITY) join_list(0u, i);
}

// The near variant: a particle of the near list (each particle where there are no lists), its
// mesh's creases (a probe of the field is costly: once a step, every pass reads them) and its
// images, after the neighbours the walk listed.
void near_images(uint t) {
  uint i = t;
  if (NEIGHBOUR_CAPACITY > 0u) {
    if (t >= neighbour_count[sim.count + 1u]) return;
    i = neighbour_count[2u * sim.count + 2u + t];
  } else if (t >= sim.count) {
    return;
  }
  vec3 xi = imageLoad(x, int(i)).xyz;
  Mirrors mirrors = mirrors_near(xi);
  if (has_shape(MESH)) {
    find_creases(mirrors);
    write_creases(i, mirrors);
  }
  if (NEIGHBOUR_CAPACITY == 0u) return;
  uint neighbours = neighbour_count[i] & ~NEAR_FLAG, listed = neighbours;
  uint word = 4u * entry_group(i, listed) + (listed & 3u);
  if (mirrors.axes != 0 && listed <= NEIGHBOUR_CAPACITY) list_images(i, xi, mirrors, neighbours, listed, word);
  neighbour_count[i] = listed | NEAR_FLAG;
  if (listed > NEIGHBOUR_CAPACITY) join_list(0u, i);
}

void main() {
  uint t = thread_index();
  if (MIRRORS_OBSTACLES && !NEAR_IN_WALK) near_images(t);
  else if (t < sim.count) walk(t);
}
