// The systems lpi builds for its scenes and stress cases, each configured and
// set to its initial state; a failed call stops the command (check).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common.hpp"

namespace lpi_cli {

Handle rigid_body(double I1, double I2, double I3, const std::vector<double> &m);
Handle pendulum(const std::vector<double> &x);
// Sine-Euler of size N with the modes `modes(N)` (fields.hpp makes them).
// The system is created first: the library refuses an N too large for
// memory (exit status 1, its message) before lpi allocates 2 N^2 modes.
Handle sine_euler(int N, const std::function<std::vector<double>(int N)> &modes);
// The paper's Figure 2 system: sine-Euler N = 7 with figure2_field().
Handle figure2_system();

// Why this build cannot make a sine-Euler system ("" when it can).
std::string sine_euler_unavailable();

// The moment algebra's product piece P(x1 x3) used by the scenes and stress
// cases: P(u) = u/50 + u^2/100 (lpi_moments_add_product_piece).
int product_energy(double u, double *out, void *);
int product_derivative(double u, double *out, void *);

}  // namespace lpi_cli
