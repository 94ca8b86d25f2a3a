#pragma once
// The cubic lattice that a scene's fluid starts on: the particle mass and the constraint's
// scale are measured on it, so that an interior particle there reads exactly rho0.

namespace pbflow {

// Particle mass that gives an interior particle of a cubic lattice of `spacing` exactly rho0.
double lattice_mass(double spacing, double h, double rho0);
// sum_k |grad_k C_i|^2 for that particle: the scale of the constraint's denominator.
double lattice_gradient_sq(double spacing, double h, double mass, double rho0);

}  // namespace pbflow
