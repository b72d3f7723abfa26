// The matrix exponential behind every exact linear piece flow x' = A x.
// Self-contained (no LAPACK): the matrices of generic systems are small.
//  - A structurally nilpotent (its nonzero pattern is an acyclic graph, which
//    covers the triangular-after-permutation systems of the paper) is applied
//    as the finite series sum_k (tA)^k x / k!, exactly, with work at most
//    O(nnz * depth) where depth is the longest path in the pattern;
//  - a 1x1 or 2x2 block (the rotations of so(3) and e(2)) in closed form;
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

// One term of a matrix A = sum_p g_p C_p with fixed sparse C_p: the
// coefficient of C_parameter at (row, col).
struct SparseTerm {
    std::uint32_t row;
    std::uint32_t col;
    std::uint32_t parameter;
    double coefficient;
};

enum class ExpmPath { Nilpotent, Plane, Pade };

// Most squarings a flow may take (||t A||_1 <= 5.37 * 2^32 ~ 2.3e10): the
// Casimir error of the Pade path grows like 2^squarings unit round-offs. The
// closed form of the plane path is held to the same bound, so whether a step
// is refused does not depend on the path.
constexpr int kMaxSquarings = 32;

// x <- exp(t A) x for the matrices A = sum_p g_p C_p of fixed sparse C_p,
// the parameters g changing from call to call: a piece flow, whose C_p
// depend only on the structure constants and the index set, its g on the
// gradient. What the pattern of A alone decides is worked out once, at
// construction:
//  - an acyclic pattern (A nilpotent, A^(depth+1) = 0, depth the longest
//    path): the finite series sum_k (tA)^k x / k!, its k-th term computed
//    only on the indices at the end of a path of length k, from the entries
//    that feed them; work O(nnz) per term, nothing dense;
//  - otherwise the block of the indices the pattern touches: of order 1 or 2
//    in closed form (A = tau I + N with N^2 = delta I: exponentials,
//    sines or hyperbolic sines), larger ones by the Pade exponential.
// apply() allocates nothing.
class SparseExponential {
public:
    // Indices < n; terms at the same position add (in the order of their
    // parameters).
    SparseExponential(std::size_t n, std::vector<SparseTerm> terms);

    ExpmPath path() const { return path_; }
    // The longest path of a nilpotent pattern (A^(depth+1) = 0), else -1.
    long depth() const { return path_ == ExpmPath::Nilpotent ? static_cast<long>(depth_) : -1; }

    // Applies x <- exp(t A) x in place for A = sum_p g[p] C_p.
    // Throws lpi::Error, x unchanged, when the result is not finite
    // (LPI_ERR_NONFINITE) or, off the nilpotent path, ||t A||_1 needs more
    // than kMaxSquarings squarings (LPI_ERR_INVALID).
    void apply(const double *g, double t, double *x);

private:
    // An entry of the nilpotent path, in the row of the moved index it
    // feeds: its column is read from x in the first term (global index) and
    // from the previous term after that (local index).
    struct SeriesEntry {
        std::uint32_t col_local;
        std::uint32_t col_global;
        std::uint32_t source;  // the distinct position (index into scaled_)
    };
    struct BlockEntry {  // an entry of the block, local indices
        std::uint32_t row;
        std::uint32_t col;
        std::uint32_t source;
    };

    void scale_entries(const double *g, double t);  // scaled_ = entries of t A
    void apply_series(double *x);
    void apply_block(double t, double *x);
    void check_norm(double norm, double t) const;
    // Of increment_, before x changes: throws LPI_ERR_NONFINITE naming the
    // first non-finite component.
    void check_finite(std::size_t m) const;
    [[noreturn]] void fail_nonfinite(std::size_t m) const;

    ExpmPath path_ = ExpmPath::Nilpotent;
    // Indices the flow moves (nilpotent: by level, deepest first; block: all
    // the pattern touches), local -> global.
    std::vector<std::uint32_t> moved_;
    // Nilpotent path: entries by row, and in a row by the level of their
    // column, deepest first. Term k (k = 1..depth) is nonzero on the first
    // rows_used_[k] moved indices only; in row v it sums the entries
    // row_begin_[v] .. row_end_[k * moved + v] - 1 (columns of level >= k - 1).
    std::vector<SeriesEntry> series_;
    std::vector<std::size_t> row_begin_, row_end_, rows_used_;
    std::vector<double> inverse_;  // 1/k
    std::size_t depth_ = 0;
    std::vector<BlockEntry> block_;
    // The terms by distinct position: position j sums terms
    // term_begin_[j] .. term_begin_[j + 1] - 1.
    std::vector<SparseTerm> terms_;
    std::vector<std::size_t> term_begin_;
    std::vector<double> scaled_, term_, next_, increment_, dense_, exp_, pade_scratch_;
};

}  // namespace lpi
