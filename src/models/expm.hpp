// The matrix exponential behind every exact linear piece flow x' = A x.
// Self-contained (no LAPACK): the matrices of generic systems are small.
//  - A structurally nilpotent (its nonzero pattern is an acyclic graph, which
//    covers the triangular-after-permutation systems of the paper) is applied
//    as the finite series sum_k (tA)^k x / k!, exactly, with work
//    O(nnz * depth) where depth is the longest path in the pattern;
//  - otherwise a dense scaling-and-squaring Pade exponential (N. J. Higham,
//    "The scaling and squaring method for the matrix exponential revisited",
//    SIAM J. Matrix Anal. Appl. 26 (2005) 1179-1193, Algorithm 2.3) of the
//    block of indices the nonzeros touch.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace lpi {

// The n * n entries of a dense n x n matrix of doubles; LPI_ERR_NO_MEMORY
// naming `what` when their bytes cannot even be counted in a size_t (the
// product would wrap around to a small, wrong allocation).
std::size_t square_entries(std::size_t n, const char *what);

// Dense exponential E = exp(A), both n x n row-major. Accurate to round-off
// relative to the conditioning of exp at A (Higham 2005).
void expm_dense(std::size_t n, const double *A, double *E);
// W = exp(A) - I, computed without cancellation: accurate relative to ||A||
// when exp(A) is close to I (what the increment form of a flow needs).
void expm1_dense(std::size_t n, const double *A, double *W);

// A sparse n x n matrix in coordinate form; repeated (row, col) pairs add.
struct SparseEntry {
    std::uint32_t row;
    std::uint32_t col;
    double value;
};

enum class ExpmPath { Nilpotent, Pade };

// Most squarings a flow may take (||t A||_1 <= 5.37 * 2^32 ~ 2.3e10): the
// Casimir error of the Pade path grows like 2^squarings unit round-offs.
constexpr int kMaxSquarings = 32;

// Scratch space reused between calls, so a flow allocates nothing once warm.
class ExpmWorkspace {
public:
    // Applies x <- exp(t A) x in place for A given by `entries` (dimension n).
    // Exact zeros in entries are ignored. Returns the path taken. Throws
    // lpi::Error, x unchanged, when the result is not finite
    // (LPI_ERR_NONFINITE) or ||t A||_1 needs more than kMaxSquarings
    // squarings (LPI_ERR_INVALID).
    ExpmPath apply(std::size_t n, const std::vector<SparseEntry> &entries, double t, double *x);

    // Longest path in the nonzero pattern of the last apply() when it was
    // nilpotent (A^(depth+1) = 0), otherwise -1. For tests and diagnostics.
    long last_depth() const { return last_depth_; }

private:
    long topological_depth();  // on local_ (active indices); -1 if cyclic
    void check_finite(std::size_t m) const;  // of increment_, before x changes

    std::vector<std::int64_t> local_of_;  // global index -> local, -1 if inactive
    std::vector<std::uint32_t> active_;   // local -> global
    std::vector<SparseEntry> local_;      // nonzero entries in local indices
    std::vector<std::size_t> start_, cursor_;  // offsets into adjacency_ (nnz)
    std::vector<std::uint32_t> adjacency_, indegree_, queue_;
    std::vector<long> depth_;
    std::vector<double> term_, next_, increment_, dense_, exp_;
    long last_depth_ = -1;
};

}  // namespace lpi
