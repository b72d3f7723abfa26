// The hot loops of a line flow: moving a block of lines between the mode
// array and a transform buffer, and multiplying the transformed lines by
// their flows' increments. On x86-64 (GCC or Clang) each is compiled for
// AVX2 and for the baseline, and the first call picks one for the CPU (FFTW
// does the same for its own codelets). AVX2 without FMA: the same IEEE
// operations, the same bits.
#pragma once

#include <cmath>
#include <cstddef>

#include "projective_line.hpp"

namespace lpi {
namespace sine_euler {

// During the flows the modes w are kept in one half: rows 1 .. M (M =
// (N - 1) / 2) and row 0 up to column M. Every other mode is read as the
// conjugate of its mirror and left out of date, so that each flow writes a
// mode once; write_conjugate_half brings the other half up to date.

// Copies lines d0 .. d0+count-1 of D out of the modes w: element s of line
// d0 + i goes to x[s * count + i] (complex entries).
void gather_block(const Direction &D, int N, int d0, int count, int first_lane, const double *w,
                  double *x);
// Adds the increments x (as gathered) to those lines of w, in place: to the
// kept half (a mode outside it through its mirror, which is kept).
void scatter_block(const Direction &D, int N, int d0, int count, int first_lane, const double *x,
                   double *w);
// Writes every mode outside the kept half as the conjugate of its mirror.
void write_conjugate_half(int N, double *w);
// Writes the kept half of dst as the transpose of the modes src keeps: entry
// (r, c) of dst is mode (c, r) of src, copied or conjugated exactly. The
// transpose has the same mirrors, so dst is a kept half in its own right, and
// the same call takes it back.
void transpose_kept_half(int N, const double *src, double *dst);
// The phase tables of one flow: kPhaseArrays arrays of 2N doubles, array a
// at tables + 2 N a, written by write_phase and read by apply_phase.
constexpr int kPhaseArrays = 6;
inline std::size_t phase_table_doubles(int N) { return 2 * static_cast<std::size_t>(N) * kPhaseArrays; }

// Multiplies the transformed block x (N rows of `count` lines d0 ..
// d0+count-1) by the line flows' increments (exp(t Lambda_l) - 1) / N read
// from the phase tables (see the definition).
void apply_phase(int N, int d0, int count, const double *tables, double sign, double *x);

// "avx2" or "baseline": the kernels that gather_block, scatter_block and
// apply_phase run on this CPU.
const char *kernel_instruction_set();

// The baseline kernels whatever the CPU has, for the tests to compare.
namespace baseline {
void gather_block(const Direction &D, int N, int d0, int count, int first_lane, const double *w, double *x);
void scatter_block(const Direction &D, int N, int d0, int count, int first_lane, const double *x, double *w);
void apply_phase(int N, int d0, int count, const double *tables, double sign, double *x);
}  // namespace baseline

// v_l = u_l - 1 = exp(i phi_l) - 1 = (-2 sin^2(phi_l / 2), sin phi_l), phi_l =
// factor B_l (B: the transformed line spectrum, factor = t / (2 eps)), as
// real and imaginary parts in arrays of their own, so that apply_phase
// multiplies four lines at a time without shuffling the tables: P = v_l / N
// at entry l (Re P, Im P: arrays 0, 1), and at entry -l (the table read
// backwards) Q = v_l / N and q = v_l (Re Q, Im Q, Re q, Im q: arrays 2 .. 5).
// Each array holds its N entries twice over, so that l + d and N + d - l need
// no reduction mod N and run forwards along the lines of a block (see
// apply_phase). Each l writes its own entries only, so threads may share the
// loop over l.
inline void write_phase(int n, int l, double factor, const double *spectrum, double *tables) {
    const std::size_t N = n, array = 2 * N;
    const double angle = factor * spectrum[2 * l];
    const double half = std::sin(0.5 * angle);
    const double re = -2.0 * half * half, im = std::sin(angle);
    const double n_real = n;
    const double scaled_re = re / n_real, scaled_im = im / n_real;
    const std::size_t minus = l == 0 ? 0 : N - l;
    const double entries[kPhaseArrays] = {scaled_re, scaled_im, scaled_re, scaled_im, re, im};
    for (std::size_t copy = 0; copy < 2; ++copy)
        for (std::size_t a = 0; a < kPhaseArrays; ++a)
            tables[a * array + (a < 2 ? l : minus) + copy * N] = entries[a];
}

}  // namespace sine_euler
}  // namespace lpi
