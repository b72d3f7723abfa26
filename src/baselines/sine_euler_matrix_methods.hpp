// The matrix-form baselines for sine-Euler: what a user of Zeitlin's model
// would otherwise run. They integrate dW/dt = [B(W), W], B = (i/(2 eps)) P(W)
// on the N x N Hermitian matrix W (conventions in the .cpp):
//   isomp       the isospectral midpoint method (fixed-point iteration),
//   rk4-matrix  classical RK4 on dW/dt,
// both with BLAS-3 products (zgemm) and O(N^2 log N) mode <-> matrix
// transforms (FFTW), and
//   direct-eq5  classical RK4 on the modes with eq. 5 summed directly, O(N^4)
//               per evaluation: a correctness check for small N only.
#pragma once

#include <vector>

#include "../core/methods.hpp"

namespace lpi {

// Largest N accepted by direct-eq5 (N^4 = 923521 terms per evaluation).
constexpr int kDirectEq5MaxN = 31;

// The rows of isomp, rk4-matrix and direct-eq5 (listed in src/registry.cpp).
// Their factories refuse with LPI_ERR_UNSUPPORTED and the reason a system
// that is not sine-Euler, a build without BLAS or FFTW (isomp, rk4-matrix),
// and N > kDirectEq5MaxN (direct-eq5).
std::vector<Method> sine_euler_matrix_methods();

}  // namespace lpi
