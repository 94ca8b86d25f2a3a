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

namespace pbflow {

// Largest gain mu of one Jacobi pass of the density constraint (lambda_i + lambda_j form,
// poly6 density, spiky gradients, eps = relaxation * denominator) over all lattice modes.
double jacobi_gain_max(double kernel_ratio, double relaxation);

// Largest stiffness s of the LDC force per unit K (the acceleration of a mode of unit
// amplitude is K s): dimensionless; K dt^2 s < 4 is the explicit force's stability limit.
// Without the density clamp, as the linearisation at rho0 sees both sides.
double ldc_stiffness_max(double kernel_ratio);

// Relaxation factors for `passes` Jacobi passes such that their combined gain on any mode,
// 1 - prod(1 - w_k lambda), lies in [0, gain] for every lambda up to gain_max (gain <= 1).
std::vector<double> jacobi_schedule(int passes, double gain, double gain_max);

}  // namespace pbflow
