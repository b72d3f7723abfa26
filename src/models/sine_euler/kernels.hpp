// The hot loops of a line flow: moving a block of lines between the mode
// array and a transform buffer, and multiplying the transformed lines by
// their flows' increments. On x86-64 with GCC each is compiled for AVX2 and
// for the baseline, and the loader picks one for the CPU (FFTW does the same
// for its own codelets). AVX2 without FMA: the same IEEE operations, the same
// bits.
#pragma once

#include <cmath>
#include <cstddef>

#include "projective_line.hpp"

namespace lpi {
namespace sine_euler {

// Copies lines d0 .. d0+count-1 of D out of the modes w: element s of line
// d0 + i goes to x[s * count + i] (complex entries).
void gather_block(const Direction &D, int N, int d0, int count, int first_lane, const double *w,
                  double *x);
// Adds the increments x (as gathered) to those lines of w, in place, and
// writes the conjugates of the sums to the mirror lines -d (which no block
// gathers), so every mode is written once.
void scatter_block(const Direction &D, int N, int d0, int count, int first_lane, const double *x,
                   double *w);
// Multiplies the transformed block x (N rows of `count` lines) by the line
// flows' increments (exp(t Lambda_l) - 1) / N; up and down point into the
// phase tables at entry N + d0 (up: v_l / N, down: v_l / N then v_l; see
// the definition).
void apply_phase(int N, int count, const double *up, const double *down, double sign, double *x);

// v_l = u_l - 1 = exp(i phi_l) - 1 = (-2 sin^2(phi_l / 2), sin phi_l), phi_l =
// factor B_l (B: the transformed line spectrum, factor = t / (2 eps)), stored
// three times over, forwards (up: v_l / N) and backwards (down: v_l / N, then
// v_l), so that v_{l-c} and v_{l+c} need no reduction mod N and run forwards
// along the lines of a block (see apply_phase). Each l writes its own entries
// only, so threads may share the loop over l.
inline void write_phase(int n, int l, double factor, const double *spectrum, double *up,
                        double *down) {
    const std::size_t N = n;
    const double angle = factor * spectrum[2 * l];
    const double half = std::sin(0.5 * angle);
    const double re = -2.0 * half * half, im = std::sin(angle);
    const double n_real = n;
    const double scaled_re = re / n_real, scaled_im = im / n_real;
    const std::size_t minus = l == 0 ? 0 : N - l;
    for (std::size_t copy = 0; copy < 3; ++copy) {
        double *forwards = up + 2 * (l + copy * N), *backwards = down + 4 * (minus + copy * N);
        forwards[0] = scaled_re;
        forwards[1] = scaled_im;
        backwards[0] = scaled_re;
        backwards[1] = scaled_im;
        backwards[2] = re;
        backwards[3] = im;
    }
}

}  // namespace sine_euler
}  // namespace lpi
