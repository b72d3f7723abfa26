// The hot loops of a line flow: moving a block of lines between the mode
// array and a transform buffer, and multiplying the transformed lines by
// their flows' increments. On x86-64 with GCC each is compiled for AVX2 and
// for the baseline, and the loader picks one for the CPU (FFTW does the same
// for its own codelets). AVX2 without FMA: the same IEEE operations, the same
// bits.
#pragma once

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

}  // namespace sine_euler
}  // namespace lpi
