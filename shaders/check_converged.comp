#version 450
// Adaptive iterations: after the reduction of the last lambda pass's densities, decides
// whether the next constraint iteration runs. It writes that iteration's group counts
// (zero once the mean compression is at or below the target; it then stays zero for the
// rest of the step) and counts the iterations run, so the host never waits mid-step.
layout(local_size_x = 1) in;

layout(std430, binding = 0) readonly buffer Measure { vec4 measure; };  // x: mean compression (reduce_final)
layout(std430, binding = 1) buffer Indirect {
  uint groups_x, groups_y, groups_z;  // VkDispatchIndirectCommand of the next iteration
  uint iterations;                    // run so far this frame (word INDIRECT_ITERATIONS_WORD, shaders/contract.h)
};
// The same for the cell walkers and the near readers of the iteration (neighbours.glsl): the
// lists pass's dispatches where the iteration runs, none where it does not.
// (The near readers' starts at NEAR_GROUPS_WORD, contract.h: the second uvec4.)
layout(std430, binding = 2) readonly buffer Overflow { uvec4 overflow[2]; };
layout(std430, binding = 3) writeonly buffer OverflowGated { uvec4 gated[2]; };
layout(push_constant) uniform Push { float target; uint full_x; uint full_y; uint per_check; } push;

void main() {
  bool more = groups_x != 0u && measure.x > push.target;
  groups_x = more ? push.full_x : 0u;
  groups_y = more ? push.full_y : 0u;
  groups_z = more ? 1u : 0u;
  for (int list = 0; list < 2; ++list) gated[list] = more ? overflow[list] : uvec4(0u);
  if (more) iterations += push.per_check;
}
