// The exact solution of the free rigid body, dm/dt = m x (m / I), by Jacobi
// elliptic functions: the exact solution against which the rigid-body methods are
// measured. Handles both sides of the separatrix, the separatrix itself,
// symmetric bodies and steady rotation about an axis.
#pragma once

namespace lpi {

// m(t) from m(0) = m0 for inertias I (all > 0); out may alias nothing.
void rigid_body_exact(const double inertia[3], const double m0[3], double t, double out[3]);

}  // namespace lpi
