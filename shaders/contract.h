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

// The lists pass's dispatch buffer (neighbour_lists.comp): the cell walkers' indirect dispatch
// (three words), then from this word the near readers'.
#define NEAR_GROUPS_WORD 4

// watch.comp's buffer, in 32-bit words (the host reads it as WatchWords, host/gpu/buffer_plan.hpp):
// the failures seen this frame (WATCH_* bits), the step within the frame of the first (all ones:
// none), the particles per failure at that step from WATCH_COUNTS on (not finite, too fast,
// outside, in the order of the bits), and the step being watched, written by the host before each
// dispatch.
#define WATCH_FLAGS 0
#define WATCH_FIRST_STEP 1
#define WATCH_COUNTS 2
#define WATCH_STEP 5
#define WATCH_WORDS 6
#define WATCH_NOT_FINITE 1u
#define WATCH_TOO_FAST 2u
#define WATCH_OUTSIDE 4u

// The coarse correction (coarse_deposit, coarse_prepare, coarse_sweep, coarse_gradient and
// coarse_apply.comp; the reference's coarse_correction): nodes COARSE_CELL spacings apart; a
// node is fluid where the particles deposited there fill more than COARSE_FILL of its reach's
// open part, or where a solid fills all but COARSE_FILL of it (fluid at rest to the solve,
// Derived::Coarse::open says why);
// COARSE_SWEEPS red-black Gauss-Seidel sweeps; the deposit's sums in fixed point, COARSE_UNIT
// to a particle's whole weight, a particle's compression counted up to COARSE_MAX_COMPRESSION
// (so the sums fit 32 bits) and past COARSE_FLOOR: a disordered packing's density reads a few
// tenths of a percent off whatever the step, and a correction of that noise, a move independent
// of dt, is a velocity that grows as 1/dt (docs/physics.md, "The coarse correction").
#define COARSE_CELL 4.0
#define COARSE_STRENGTH 0.5
// A lone smoothed pass has no second pass to take back what the move overshoots.
#define COARSE_LONE_STRENGTH 0.15
#define COARSE_FILL 0.1
#define COARSE_OPEN_SAMPLES 4
#define COARSE_SWEEPS 20
#define COARSE_UNIT 65536.0
#define COARSE_MAX_COMPRESSION 8.0
// A node's words in the deposit (COARSE_WORDS): the weight deposited, the excess, and the walls
// the particles nearest it touch (within a quarter of h, the wall layer: bit 2 axis for the low
// wall, the next for the high). coarse_prepare makes the first the node's flags: COARSE_FLUID,
// and COARSE_AIR_PAST << (2 axis + side) for each wall above it (its outward normal within 60
// degrees of up, against the scene's gravity: COARSE_UP) that it borders and none of those
// particles touches, where its deposit makes it fluid and no solid lies in its reach: past that
// wall is air (phi 0), not a wall without flux. A free surface in the cells under the tank's lid
// left the solve no air node at all: its Neumann problem has no solution, and water 0.26 m deep
// in a tank 0.3 m tall churned at 0.2 m/s. Taken past the floor and the side walls too, it let
// shallow water that bodies fell into gain 10 % of its potential energy.
#define COARSE_WORDS 3
// After the nodes' words, COARSE_TOTALS more (COARSE_TOTAL_*), summed by coarse_prepare: the fluid
// nodes, the nodes with air (none, or past a wall), and the fluid nodes' excess in fixed point
// (low word, then the carries). Where no node has air the solve is a Neumann problem, solvable
// only with a mean-free source: each sweep takes the mean excess off every node's. Without it
// phi grew without bound in a closed tank filled to its lid (0.13 after 300 steps, 3e-4 with
// room above), and the GPU's float sweeps churned it at 0.2 m/s.
#define COARSE_TOTALS 4
#define COARSE_TOTAL_FLUID 0
#define COARSE_TOTAL_AIR 1
#define COARSE_TOTAL_EXCESS 2
#define COARSE_FLUID 1u
#define COARSE_AIR_PAST 2u
#define COARSE_UP 0.5
#define COARSE_FLOOR 0.003

// A move toward a mesh is marched (obstacles.cpp's trace, solids.glsl's stop_at_solids): its
// surface is looked for at evenly spaced points a field voxel apart at most (up to TRACE_STEPS
// of them), and the first met found to 1/2^TRACE_BISECTIONS of a step.
#define TRACE_STEPS 32
#define TRACE_BISECTIONS 6
// A mesh's square creases (host/sim/solids/mirrors.cpp, crease_faces): its faces are read from
// the field at two rings of CREASE_PROBES points about the particle, h away and CREASE_REACH h
// away lifted CREASE_LIFT of that to the fluid's side, where the field's gradient is within 1 -
// CREASE_STEEP of unit length (else it blends two faces), and two are a crease's where the
// cosine between their normals is under CREASE_COSINE.
// Two faces meet where their line reads within CREASE_MEET voxels of the surface: OpenVDB's field
// reads a thin wall's inner edge up to a voxel inside the solid. The field marks a crease only
// where its faces are flat along it (mark_creases), the field's normal each face's to a cosine
// over CREASE_FLAT, so that a round one (a cup's inner floor edge) keeps its pair image.
#define CREASE_PROBES 8
#define CREASE_REACH 0.4
#define CREASE_LIFT 0.5
#define CREASE_MEET 1.5
#define CREASE_STEEP 0.97
#define CREASE_COSINE 0.25
#define CREASE_FLAT 0.995

// The smoothed positions the fluid style draws (smoothed_positions.comp; the reference's
// smoothed_positions): each particle moved this much of the way to its neighbourhood's mean
// (Yu & Turk 2013's lambda).
#define POSITION_SMOOTHING 0.9

// The drawn particle's shape (Yu & Turk 2013's anisotropy; smoothed_positions.comp, the
// reference's drawn_shape): an ellipsoid of the sphere's volume, its axes along the
// eigenvectors of the neighbourhood's weighted covariance and proportional to its eigenvalues,
// each at least 1/SHAPE_MAX_STRETCH of the largest; a sphere where fewer than
// SHAPE_MIN_NEIGHBOURS particles (itself and wall images included) lie within h.
// SHAPE_SWEEPS Jacobi sweeps diagonalise the covariance. The frame holds T = R diag(a^2) R^T,
// the ellipsoid's matrix, and its longest semi-axis, both in particle radii
// (shape_layout.glsl).
#define SHAPE_MAX_STRETCH 4.0
#define SHAPE_MIN_NEIGHBOURS 6
#define SHAPE_SWEEPS 4

// Where the fluid does not slip along an obstacle (its scene key "slip": false), the viscosity
// pass pulls a particle's velocity along the surface towards its images', which move as their
// neighbours reversed relative to the solid, by this gain times each image's kernel volume
// (Mirrors::stick): the wall layer's slip relaxes by about 40 % a step, and the largest
// eigenvalue of the pull stays under 1 (the images' share of a neighbourhood is under a half of
// up to 1.2 rho0), so that it never overshoots.
#define NO_SLIP_GAIN 0.5

// The obstacle buffer (host/sim/solids/obstacles.hpp's pack_obstacles, shaders/solids.glsl): vec4 0 the
// count and margin, then TANK_KICK_VEC4S of the tank's kick, then OBSTACLE_VEC4S per obstacle.
#define TANK_KICK_VEC4S 7
#define OBSTACLE_VEC4S 9

// The bodies' push sums (solids.glsl's push_body, host/gpu/gpu_bodies.cpp): BODY_PUSH_WORDS words
// a body, six 64-bit fixed-point sums (two words each, BODY_FIXED_UNIT to a metre or a square
// metre: 2^-40 m, and 2^23 m at most), then at BODY_LINE_WORD its water line (an ordered float,
// 0 for none), at BODY_TOP_WORD its top (a float), both heights along up, and at BODY_UP_WORD
// that direction (three floats, the host's up()).
#define BODY_PUSH_WORDS 20
#define BODY_FIXED_UNIT 1099511627776.0
#define BODY_LINE_WORD 12
#define BODY_TOP_WORD 13
#define BODY_UP_WORD 14

#endif
