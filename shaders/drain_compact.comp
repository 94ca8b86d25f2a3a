#version 450
// Drains, 2 of 2 (sim/flow.hpp): `keep`, scanned, gives each kept particle its slot, in order,
// so that x, v and the ids are packed as the reference's drain packs them; each drained one's
// (x, v) goes to the drained list in order, where the host reads the energy it took. The count
// kept and drained go to `counts`.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 1) readonly buffer Slots { uint slots[]; };  // keep, exclusive-scanned
layout(std430, binding = 2) readonly buffer XIn { vec4 x_in[]; };
layout(std430, binding = 3) readonly buffer VIn { vec4 v_in[]; };
layout(std430, binding = 4) readonly buffer IdIn { uint id_in[]; };
layout(std430, binding = 5) writeonly buffer XOut { vec4 x_out[]; };
layout(std430, binding = 6) writeonly buffer VOut { vec4 v_out[]; };
layout(std430, binding = 7) writeonly buffer IdOut { uint id_out[]; };
layout(std430, binding = 8) writeonly buffer Drained { vec4 drained[]; };  // (x, v) each
layout(std430, binding = 9) writeonly buffer Counts { uint counts[]; };    // kept, drained

void main() {
  uint i = thread_index();
  if (i == sim.count) counts[0] = slots[i], counts[1] = sim.count - slots[i];
  if (i >= sim.count) return;
  if (slots[i + 1] != slots[i]) {
    x_out[slots[i]] = x_in[i];
    v_out[slots[i]] = v_in[i];
    id_out[slots[i]] = id_in[i];
  } else {
    uint k = i - slots[i];
    drained[2 * k] = x_in[i];
    drained[2 * k + 1] = v_in[i];
  }
}
