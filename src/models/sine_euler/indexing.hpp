// Index arithmetic on the N x N mode array of sine-Euler (N odd): mode
// (a, b), a, b in Z_N, is entry a N + b, stored as interleaved re, im. Entries
// pass int past N = 46340, so every offset is a std::size_t, and products of
// two residues are formed in 64 bits before they are reduced.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lpi {
namespace sine_euler {

// a mod N in 0 .. N-1, for any sign of a.
inline int modulo(std::int64_t a, int N) {
    const std::int64_t r = a % N;
    return static_cast<int>(r < 0 ? r + N : r);
}
// The representative of a residue in -(N-1)/2 .. (N-1)/2.
inline int signed_residue(int a, int N) { return a > N / 2 ? a - N : a; }
inline std::size_t mode_index(int a, int b, int N) { return static_cast<std::size_t>(a) * N + b; }
// -a mod N for a residue a in 0 .. N-1.
inline int negated_residue(int a, int N) { return a ? N - a : 0; }
// Entry of the conjugate mode -(a, b).
inline std::size_t mirror_index(int a, int b, int N) {
    return mode_index(negated_residue(a, N), negated_residue(b, N), N);
}
// The half of the modes the line flows keep during a run: rows a = 1 ..
// (N-1)/2, and row 0 up to column (N-1)/2. Every other mode is its mirror's
// conjugate, read from there and written once the flows are done
// (kernels.hpp).
inline bool kept_mode(int a, int b, int N) {
    const int M = (N - 1) / 2;
    return static_cast<unsigned>(a - 1) < static_cast<unsigned>(M) || (a == 0 && b <= M);
}
// The mean of a mode's value and the one its mirror implies, which a
// symmetric field makes equal: kept as is when they are (such a field is
// stored to the bit), and halved before the sum, which no finite pair
// overflows (0.5 (x + y) did, for values beyond DBL_MAX / 2).
inline double mirror_mean(double x, double y) { return x == y ? x : 0.5 * x + 0.5 * y; }
// |m|^2 of the representative of mode (a, b), exact (in 64 bits: an int
// overflows past N = 65535).
inline double norm2(int a, int b, int N) {
    const std::int64_t ra = signed_residue(a, N), rb = signed_residue(b, N);
    return static_cast<double>(ra * ra + rb * rb);
}

}  // namespace sine_euler
}  // namespace lpi
