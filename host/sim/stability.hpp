#pragma once
// How much correction one step can carry. Both the constraint pass and the LDC force
// act on density modes; on a uniform lattice each Fourier mode u e^{ik.x} is an
// eigenvector, so their largest per-step effect is a maximum over k (computed once per
// scene, in units of the spacing: the numbers depend only on h / spacing).
//
// Why it matters: PBF's velocity is (x* - x)/dt, so a step maps a mode q to
// q' = (1 - mu)(2q - q_prev - nu q) with mu the constraint pass's gain and nu = K dt^2 s
// the LDC force's stiffness. The step is damped for 0 < mu <= 1, oscillates and grows
// past mu = 4/3 (one Jacobi pass of PBF reaches mu = 2.8 on a lattice: the blow-ups),
// and the explicit force alone is stable only for nu < 4.

#include <vector>

#include "shaders/contract.h"

namespace pbflow {

// Largest gain mu of one Jacobi pass of the density constraint (lambda_i + lambda_j form,
// poly6 density, spiky gradients, eps = relaxation * denominator at rest) over all lattice
// modes, on a lattice squeezed uniformly to (1 + compression) rho0 (same mass: more
// neighbours inside h, so a larger gain), lambda averaged `smoothing` times over the
// neighbours inside h first (constraint_smooth.comp): that multiplies a mode's gain by
// F(k)^smoothing, F the mean of cos(k.o) over them weighted by kernels::smoothing_weight,
// 1 for the longest modes.
double jacobi_gain_max(double kernel_ratio, double relaxation, double compression = 0, int smoothing = 0);

// The same pass's least gain over all modes: negative where a mode's correction turns
// around (the pass then grows it). An odd smoothing count gets there (-0.2 for one
// average); without smoothing or with an even count it stays within rounding of 0.
double jacobi_gain_min(double kernel_ratio, double relaxation, int smoothing);

// The gain of the longest modes per (k spacing)^2, k -> 0: how fast the pass corrects the
// compression a column of fluid holds. Smoothing leaves it.
double jacobi_long_mode_gain(double kernel_ratio, double relaxation, int smoothing);

// The gain's growth with compression: jacobi_gain_max at rho0 (1 + C) stays within 3 % of
// (1 + kCompressedGain C) times its value at rho0 for C up to 1 (tests/energy_test.cpp);
// lambda is divided by that factor so that compressed fluid is not over-corrected. The
// constant is shared with constraint_lambda.comp through shaders/contract.h.
inline constexpr double kCompressedGain = COMPRESSED_GAIN;

// Largest stiffness s of the LDC force per unit K (the acceleration of a mode of unit
// amplitude is K s): dimensionless; K dt^2 s < 4 is the explicit force's stability limit.
// Without the density clamp, as the linearisation at rho0 sees both sides. It grows with
// compression a little under (rho/rho0)^2 (8x at C = 2): correction_force.comp caps K by
// that (Derived::ldc_room), so the step's limit holds in squeezed fluid too.
double ldc_stiffness_max(double kernel_ratio, double compression = 0);

// The most of the LDC force's limit that a squeezed particle's K may reach (ldc_strength
// is the fraction at rho0; the force scales K down where (rho/rho0)^2 would pass this).
inline constexpr double kLdcCap = 0.9;

// Largest eigenvalue of the dashpot (viscosity_vorticity.comp) per unit damping: a mode
// loses the fraction damping * eigenvalue of its velocity per step and is reversed past
// 1, driven past 2. ~5 at rho0; it grows with compression more slowly than rho/rho0, by
// which the pass caps each pair (Derived::damping_limit).
double damping_gain_max(double kernel_ratio, double compression = 0);

// rho / rho0 that the solver reads (poly6 sum) on a lattice squeezed to (1 + compression) rho0.
double lattice_density(double kernel_ratio, double compression);

// Relaxation factors for `passes` Jacobi passes such that their combined gain on any mode,
// 1 - prod(1 - w_k lambda), lies in [0, gain] for every lambda up to gain_max (gain <= 1).
std::vector<double> jacobi_schedule(int passes, double gain, double gain_max);

}  // namespace pbflow
