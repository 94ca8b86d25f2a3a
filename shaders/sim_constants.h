// The push-constant block every particle pass reads, declared once for both sides: common.glsl
// expands it into the GLSL block `Sim`, host/sim/params.hpp into the C++ struct SimConstants.
// Each field is SIM_FIELD(glsl type, name). std430 and C++ lay it out alike only because every
// vec3 is followed by a scalar (a vec3 then fills 16 bytes on both sides); Program checks the
// block's size against the struct's at creation, ProgramContract the offsets field by field.
// The Vulkan floor for the whole block is 128 bytes.
#ifndef PBFLOW_SHADERS_SIM_CONSTANTS_H
#define PBFLOW_SHADERS_SIM_CONSTANTS_H

#define SIM_CONSTANTS(SIM_FIELD)                                        \
  SIM_FIELD(vec3, domain_min) SIM_FIELD(float, h)                       \
  SIM_FIELD(vec3, domain_max) SIM_FIELD(float, dt)                      \
  SIM_FIELD(vec3, gravity) SIM_FIELD(float, mass)                       \
  SIM_FIELD(ivec3, grid) SIM_FIELD(uint, count)                         \
  SIM_FIELD(vec3, wall_min) SIM_FIELD(float, rho0)                      \
  SIM_FIELD(vec3, wall_max) SIM_FIELD(float, epsilon)                   \
  SIM_FIELD(float, poly6_scale) SIM_FIELD(float, spiky_grad_scale)      \
  SIM_FIELD(float, ldc_k) SIM_FIELD(float, relaxation) /* this constraint pass's under-relaxation */ \
  SIM_FIELD(float, elapsed) /* the white water passes': the frame's time, s */                   \
  SIM_FIELD(uint, frame) /* and the frames advanced so far, their births' random stream */

#endif
