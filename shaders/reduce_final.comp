#version 450
// Combines the partials of reduce_stats.comp (two vec4 a group) into what the host reads:
// (mean compression, max compression, kinetic energy, max speed), (potential energy, the moving
// solids' work this frame, 0, 0):
// the first fields of the host's FrameResult (host/gpu/buffer_plan.hpp).
layout(local_size_x = 256) in;

layout(std430, binding = 0) readonly buffer Partials { vec4 partials[]; };
layout(std430, binding = 1) writeonly buffer Result { vec4 result; vec4 energy; };
layout(push_constant) uniform Push { uint partial_count; uint particle_count; float mass; } push;

shared vec4 acc[256];
shared vec2 potential_acc[256];  // and the work

void main() {
  uint t = gl_LocalInvocationID.x;
  vec4 a = vec4(0.0);
  vec2 potential = vec2(0.0);
  for (uint k = t; k < push.partial_count; k += 256) {
    vec4 b = partials[2 * k];
    a = vec4(a.x + b.x, max(a.y, b.y), a.z + b.z, max(a.w, b.w));
    potential += partials[2 * k + 1].xy;
  }
  acc[t] = a;
  potential_acc[t] = potential;
  barrier();
  for (uint half_ = 128; half_ > 0; half_ >>= 1) {
    if (t < half_) {
      vec4 x = acc[t], y = acc[t + half_];
      acc[t] = vec4(x.x + y.x, max(x.y, y.y), x.z + y.z, max(x.w, y.w));
      potential_acc[t] += potential_acc[t + half_];
    }
    barrier();
  }
  if (t == 0) {
    vec4 s = acc[0];
    result = vec4(s.x / float(max(push.particle_count, 1u)), s.y, 0.5 * push.mass * s.z, sqrt(s.w));
    energy = vec4(push.mass * potential_acc[0], 0.0, 0.0);
  }
}
