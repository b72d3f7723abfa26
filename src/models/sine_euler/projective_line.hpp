// The geometry of the sine-Euler splitting (McLachlan 1993, section 3),
// independent of how the line flows are transformed: the directions of the
// projective line over Z_N (one piece each), which modes each piece owns, the
// parallel lines of a direction and their layout in the mode array, and the
// blocks of lines a flow is cut into. A second backend (MPI, GPU) reuses
// this and replaces the transforms.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "hamiltonian.hpp"

namespace lpi {
namespace sine_euler {

// One direction k of Z_N^2. The piece H_k, the terms of H of the modes it
// owns (1/2 sum |w_sk|^2 / |sk|^2 for Euler), leaves the line {s k} fixed and moves each parallel line
// {d j + s k}, d = 1 .. M (M = (N-1)/2; the lines -d are their conjugates).
struct Direction {
    int k1, k2;          // the direction
    int j1 = 0, j2 = 0;  // offset between parallel lines: d j + s k
    // Row: k = (1, k2), j = (0, 1): element s of line d is at row s, column
    //   s k2 + d, so a block's lines cross each row in one run.
    // Column: k = (k1, 1), j = (1, 0): row s k1 + d, column s (runs down the
    //   columns; all the other directions when N is a prime power).
    // General: any k, j with j x k = 1 (N with two or more prime factors).
    enum Layout { Row, Column, General } layout;
    // c = j x k of line d is sigma d: -d for Row directions, +d for the
    // others. With c = +-d, the phases of the lines of a block are read from
    // consecutive entries of the phase table (see apply_phase).
    int sigma;
    std::vector<unsigned char> owned;  // owned[s]: this piece holds the energy of s k
};

// The lines of D as the kernels address them in the transposed mode array
// (mode (a, b) at entry b N + a): k and j swapped, Row and Column exchanged.
// Everything else of a line (c = j x k, its phases, the modes D owns) stays
// D's; the view carries no ownership table.
Direction transposed_view(const Direction &D);
// Where a direction's blocks are moved fastest: a Row direction's lines cross
// each row of the modes in runs, a Column direction's cross each column, one
// mode from each of 16 rows a lane (4.3 ns a mode moved at N = 125, against
// 1.9), and cross the rows of the transposed modes in runs. (0,1)'s lines
// are rows and columns alike, and General ones go mode by mode either way.
enum class Orientation { Modes, Transposed, Either };
Orientation orientation(const Direction &D);

// The directions of the projective line over Z_N, in the paper's order for
// prime N ((0,1), then (1,m), m = 0..N-1), then, for composite N, the other
// classes in lexicographic order. Every nonzero mode is owned by exactly one.
std::vector<Direction> projective_line(int N);
// The same directions, handed to visit one at a time in that order: a
// caller that keeps only part of each (the MPI model keeps the ownership of
// its own modes) never holds every direction's table at once. The modes that
// only a later class can own (N with a squared prime factor) are claimed in
// a byte each: by default in a table of all N^2 modes; with `claims`, in the
// byte it returns for mode (a, b), and a mode for which it returns nullptr
// is left unowned in every table (its caller does not track it).
void for_each_direction(int N, const std::function<void(Direction &&)> &visit,
                        const std::function<unsigned char *(int a, int b)> &claims = {});

// The odd primes dividing N.
std::vector<int> prime_factors(int N);

// The energy of piece D: the terms of H of the modes it owns.
double piece_energy(const Direction &D, const Hamiltonian &H, const double *modes);

// The stream function on piece D's own line, b_s = lambda_sk w_sk + f_sk for
// the modes D owns and 0 elsewhere (N complex, interleaved), the input of
// the line spectrum, read from the half of the modes the flows keep
// (kernels.hpp), or from its transpose (transposed_view). Returns false when
// every b_s is zero.
bool line_stream(const Direction &D, const Hamiltonian &H, const double *modes, bool transposed, double *b);

// Lines d = 1 .. M of a direction, in blocks of kBlock. The block size is
// fixed (not derived from the thread count), so each block meets the same
// transform whichever thread runs it: results are identical to the bit for
// every thread count.
constexpr int kBlock = 16;
struct LineBlocks {
    int N, M;
    explicit LineBlocks(int n) : N(n), M((n - 1) / 2) {}
    int count() const { return (M + kBlock - 1) / kBlock; }
    int first_line(int block) const { return 1 + block * kBlock; }
    int lines(int block) const { return M - block * kBlock < kBlock ? M - block * kBlock : kBlock; }
    // Blocks start at different lanes, so that threads working on different
    // blocks are not in the same lane of the modes at the same moment (lanes
    // meet at the blocks' edges, in shared cache lines). Every mode is
    // written once per flow, so the order changes no bit.
    int first_lane(int block) const {
        return static_cast<int>(static_cast<long long>(block) * N / count());
    }
};

}  // namespace sine_euler
}  // namespace lpi
