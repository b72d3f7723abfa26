// The matrix-form baselines for sine-Euler: what a user of Zeitlin's model
// would otherwise run. They integrate dW/dt = [B(W), W], B = (i/(2 eps)) P(W)
// (design notes, section 1) on the N x N Hermitian matrix W:
//   isomp       the isospectral midpoint method (fixed-point iteration),
//   rk4-matrix  classical RK4 on dW/dt,
// both with BLAS-3 products (zgemm) and O(N^2 log N) mode <-> matrix
// transforms (FFTW), and
//   direct-eq5  classical RK4 on the modes with eq. 5 summed directly, O(N^4)
//               per evaluation: a correctness reference for small N only.
#pragma once

#include <memory>

#include "../core/integrator.hpp"

namespace lpi {

// Largest N accepted by direct-eq5 (N^4 = 923521 terms per evaluation).
constexpr int kDirectEq5MaxN = 31;

// The integrator of an IsospectralMidpoint, RungeKutta4Matrix or DirectEq5
// method. Throws lpi::Error(LPI_ERR_UNSUPPORTED) with the reason when `model`
// is not a sine-Euler system, when the build lacks BLAS (isomp, rk4-matrix),
// or when N > kDirectEq5MaxN (direct-eq5).
std::unique_ptr<Integrator> make_sine_euler_matrix_integrator(const Method &method,
                                                              const Model &model,
                                                              const ImplicitSettings &implicit);

}  // namespace lpi
