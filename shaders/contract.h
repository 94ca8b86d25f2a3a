// Facts that the C++ host and the GLSL passes must agree on, in one file both include
// (preprocessor definitions only, so that it is valid C++ and GLSL alike).
#ifndef PBFLOW_SHADERS_CONTRACT_H
#define PBFLOW_SHADERS_CONTRACT_H

// The constraint pass's gain grows with compression as (1 + COMPRESSED_GAIN C) times its value
// at rho0 (host/sim/stability.hpp); lambda is divided by that factor (constraint_lambda.comp).
#define COMPRESSED_GAIN (1.0 / 3.0)

// check_converged.comp's indirect buffer: the next iteration's dispatch (three words), then
// the iterations run so far this frame, at this word.
#define INDIRECT_ITERATIONS_WORD 3

#endif
