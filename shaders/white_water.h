// White water's model (Ihmsen et al. 2012, "Unified spray, foam and bubbles for particle-based
// fluids"), in one file the GLSL passes (white_water_emit.comp, white_water_advect.comp) and the
// C++ reference (host/sim/reference_white_water.cpp) include: preprocessor definitions only.
#ifndef PBFLOW_SHADERS_WHITE_WATER_H
#define PBFLOW_SHADERS_WHITE_WATER_H

// A fluid particle's potentials, each mapped onto [0, 1] between its two thresholds, speeds in
// units of the scene's flow speed (Derived::flow_speed, a fall through the domain's height, 4.4
// m/s in the dam break), so that they mean the same at any spacing:
// - trapped air: the kernel-weighted mean over the neighbours of |v_ij| (1 - v^_ij . x^_ij),
//   the speed at which fluid closes in on it (a front folding over, a wave hitting a wall);
// - wave crest: at a free surface (its neighbours' weighted centre lies off it by WHITE_SURFACE_*
//   kernel radii), its speed out along the surface's normal;
// - kinetic energy, as a speed: slow fluid makes none, whatever the other two read.
#define WHITE_TRAPPED_AIR_MIN 0.04
#define WHITE_TRAPPED_AIR_MAX 0.16
#define WHITE_SURFACE_MIN 0.08
#define WHITE_SURFACE_MAX 0.2
#define WHITE_CREST_MIN 0.15
#define WHITE_CREST_MAX 0.6
#define WHITE_SPEED_MIN 0.3
#define WHITE_SPEED_MAX 0.85
// At most this many born per fluid particle per frame (the tag's room, below).
#define WHITE_MOST_BORN 4u

// What a white water particle is, from the fluid's density around it as a fraction of rho0:
// spray below WHITE_SPRAY_BELOW (flies ballistically), bubbles above WHITE_BUBBLE_ABOVE (rise
// against gravity, dragged towards the fluid's velocity), foam between (carried by the fluid).
#define WHITE_SPRAY_BELOW 0.2
#define WHITE_BUBBLE_ABOVE 0.6
#define WHITE_BUOYANCY 2.0  // a bubble's upward acceleration, in units of |g|
#define WHITE_DRAG 0.5      // the fraction of a bubble's lag behind the fluid made up per frame
#define WHITE_SPRAY 0u
#define WHITE_FOAM 1u
#define WHITE_BUBBLE 2u

// A particle is two vec4s: (x, life left in s) and (v, tag). The tag's bits (read as a float's):
// the kind in the low two, then the emitter's id times WHITE_MOST_BORN plus its birth's number.
// The id's low 26 bits only (an emitter's particles count ids on): past them the tag, read as a
// float, could reach an all-ones exponent, a NaN a device may rewrite.
#define WHITE_KIND_BITS 2u
#define WHITE_TAG_ID_MASK 0x3FFFFFFu
// The count of particles alive (a word; the rest of the 16 bytes pad), then the capacity's
// positions, then their velocities: where the frame buffer keeps them (host/sim/solver.hpp).
#define WHITE_HEADER_BYTES 16

#endif
