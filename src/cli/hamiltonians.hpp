// The sine-bracket family in lpi's scenes: sine-Euler systems with the
// Hamiltonians of surface quasi-geostrophy, quasi-geostrophy with a
// deformation wavenumber, and Euler over a bottom topography
// (lpi_sine_euler_set_hamiltonian(3) gives the conventions).
#pragma once

#include "common.hpp"

namespace lpi_cli {

// SQG: lambda = 1/|n|, from the smooth field of the sine-euler scene.
Handle sqg_system(int N);
// QG: lambda = 1/(|n|^2 + kd^2), the same field.
Handle qg_system(int N, double kd);
// Euler over a smooth random topography h (sum |h_n|^2 = 1): the state is
// q = w + h, lambda = 1/|n|^2 and f = -h/|n|^2; q starts as the same field.
Handle topography_system(int N);
// That scene's h on the grid (entry a*N + b at (2 pi a/N, 2 pi b/N)), which
// lpi run writes with the data: w = q - h.
std::vector<double> topography_grid(int N);

}  // namespace lpi_cli
