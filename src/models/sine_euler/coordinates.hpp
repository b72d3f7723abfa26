// Conversions between the three forms of a sine-Euler field: the public
// coordinates (N^2 doubles: w_0, then re, im of the half plane
// (0, 1) .. (0, M), then (a, -M) .. (a, M), a = 1 .. M), the working mode
// array (2 N^2 doubles, both halves, FFT order) and the real grid.
#pragma once

namespace lpi {
namespace sine_euler {

void public_from_state(int N, const double *state, double *x);
// LPI_ERR_NONFINITE for a coordinate that is not finite.
void state_from_public(int N, const double *x, double *state);
// Validates modes (finite, Hermitian within 1e-10 of the largest) and writes
// the public coordinates of the symmetrised field.
void public_from_modes(int N, const double *modes, double *x);
// Validates a real grid (N^2, finite; LPI_ERR_OVERFLOW when its transform
// overflows) and writes public coordinates. Needs FFTW3.
void public_from_grid(int N, const double *grid, double *x);

}  // namespace sine_euler
}  // namespace lpi
