// The matrix exponential behind every exact linear piece flow x' = A x.
// Self-contained (no LAPACK): the matrices of generic systems are small.
//  - A structurally nilpotent (its nonzero pattern is an acyclic graph, which
//    covers the triangular-after-permutation systems of the paper) is applied
//    as the finite series sum_k (tA)^k x / k!, exactly, with work
//    O(nnz * depth) where depth is the longest path in the pattern;
//  - a 1x1 or 2x2 block (the rotations of so(3) and e(2)) in closed form;
//  - otherwise a dense scaling-and-squaring Pade exponential (N. J. Higham,
//    "The scaling and squaring method for the matrix exponential revisited",
//    SIAM J. Matrix Anal. Appl. 26 (2005) 1179-1193, Algorithm 2.3) of the
//    block of indices the nonzeros touch.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "../core/cpu_features.hpp"
#include "../core/exact_sums.hpp"

namespace lpi {

// The n * n entries of a dense n x n matrix of doubles; LPI_ERR_NO_MEMORY
// naming `what` when their bytes cannot even be counted in a size_t (the
// product would wrap around to a small, wrong allocation).
std::size_t square_entries(std::size_t n, const char *what);

// Dense exponential E = exp(A), both n x n row-major. Accurate to round-off
// relative to the conditioning of exp at A (Higham 2005).
void expm_dense(std::size_t n, const double *A, double *E);
// The same with its scratch kept in `scratch`.
void expm_dense(std::size_t n, const double *A, double *E, std::vector<double> &scratch);
// W = exp(A) - I, computed without cancellation: accurate relative to ||A||
// when exp(A) is close to I (what the increment form of a flow needs).
void expm1_dense(std::size_t n, const double *A, double *W);
// The same with its scratch kept in `scratch` (no allocation once it is large
// enough).
void expm1_dense(std::size_t n, const double *A, double *W, std::vector<double> &scratch);
// ||A||_1, the largest column sum of |A|.
double dense_norm1(std::size_t n, const double *A);

// One term of a matrix A = sum_p g_p C_p with fixed sparse C_p: the
// coefficient of C_parameter at (row, col).
struct SparseTerm {
    std::uint32_t row;
    std::uint32_t col;
    std::uint32_t parameter;
    double coefficient;
};

enum class ExpmPath { Nilpotent, DiagonalSeries, Plane, Pade, EllipticSeries };

// The largest |k| for which a diagonal entry k c g_p of the DiagonalSeries
// path takes exp(t k c g_p) - 1 by powers of expm1(+-t c g_p).
constexpr int kMaxScalingMultiple = 8;

// e^a as hi + lo, to about 2^-104 of itself, for a scaling z e^a =
// fma(hi, z, lo z): one rounding, of a product that depends on the state. A
// growth is a constant wherever the gradient is (a linear piece), rounded
// alike in every flow, and a pair e^a, e^-a rounded apart moved their product
// with one sign (sl(2), H = a h: e f, and the Casimir h^2 + 4 e f, 690
// standard errors over 2e5 flows at t = a = 1, through the plane's closed
// form; 149 through expm1 and -v / (1 + v) in doubles). Here one expm1 makes
// every power of a group: (1 + v)^k and its reciprocals agree to 2^-100.
struct Exponential {
    double hi, lo;
};
// a + b, a b and 1 / a as double-doubles (exact_sums.hpp: the exact parts
// through fma).
inline Exponential exponential_sum(double a, double b) {
    Exponential sum;
    two_sum(a, b, sum.hi, sum.lo);
    return sum;
}
inline Exponential exponential_product(Exponential a, Exponential b) {
    Exponential product;
    two_product(a.hi, b.hi, product.hi, product.lo);
    product.lo += a.hi * b.lo + a.lo * b.hi;
    return product;
}
inline Exponential exponential_reciprocal(Exponential a) {
    const double r = 1.0 / a.hi;
    // 1 - r a, its first part exact through fma.
    return {r, (-std::fma(r, a.hi, -1.0) - r * a.lo) * r};
}

// M[k] = e^(k s) for k = +-1 .. +-largest (M points at k = 0), from one
// side's base 1 + expm1 as an exact sum, the other side its reciprocal, the
// powers by products: each keeps its relative accuracy. The base is the
// side that does not contract by more than half (1 + expm1(s) near e^s << 1
// would keep only an absolute 2^-106); that test, and not the sign of s,
// picks it, so that flows near the identity take one branch. Where the base
// overflows, the other side is 0, and those scalings go to
// scaled_beyond_range. The DiagonalSeries path and the compiled flows share
// it, so that they give the same bits.
inline void exponential_side_powers(int side, int largest, Exponential *M) {
    for (int k = 2; k <= largest; ++k) M[side * k] = exponential_product(M[side * (k - 1)], M[side]);
}
inline void exponential_powers(double s, int largest, Exponential *M) {
    const int base = s >= -0.6931471805599453 ? 1 : -1;
    const double v = std::expm1(base * s);
    M[base] = std::isfinite(v) ? exponential_sum(1.0, v) : Exponential{v, 0.0};
    M[-base] = std::isfinite(v) ? exponential_reciprocal(M[base]) : Exponential{0.0, 0.0};
    exponential_side_powers(1, largest, M);
    exponential_side_powers(-1, largest, M);
}
// exponential_powers where |s| <= 1/2 (every multiple within [-1/2, 1/2], as
// the compiled flows' near case asks): the same bits without its tests.
inline void exponential_powers_near(double s, int largest, Exponential *M) {
    M[1] = exponential_sum(1.0, std::expm1(s));
    M[-1] = exponential_reciprocal(M[1]);
    exponential_side_powers(1, largest, M);
    exponential_side_powers(-1, largest, M);
}
// e^a for an entry in no group: from expm1(|a|), so that the entry -a of
// another index (a Casimir x y under e^a, e^-a) takes the reciprocal of the
// very same value. From expm1(a) and expm1(-a) they were rounded apart, alike
// in every flow (sl(2)-like pairs of weights 2 and 3, or of two parameters:
// 107 to 252 standard errors over 2e5 flows).
inline Exponential exponential_of(double a) {
    const double v = std::expm1(std::fabs(a));
    if (!std::isfinite(v)) return a >= 0.0 ? Exponential{v, 0.0} : Exponential{0.0, 0.0};
    const Exponential grown = exponential_sum(1.0, v);
    return a >= 0.0 ? grown : exponential_reciprocal(grown);
}

// z e^a from M = e^a (exponential_powers): fma(M.hi, z, M.lo z), where M is
// a normal double; past that range z e^a may still be a double
// (scaled_beyond_range). The DiagonalSeries path, the 1x1 plane and the
// compiled flows share it.
double scaled_beyond_range(double z, double a);
// Below it exp(a) is subnormal and keeps fewer significant bits: a huge z
// contracted past e^-708 took the error of that rounding (2.6e-3 of z
// e^-740 for z = 1e300).
constexpr double kSmallestNormalExponent = -708.39641853226408;  // ln DBL_MIN
inline double scaled(double z, Exponential M) { return std::fma(M.hi, z, M.lo * z); }
inline double scaled_by_exponential(double z, Exponential M, double a) {
    if (M.hi >= std::numeric_limits<double>::min() && M.hi <= std::numeric_limits<double>::max() &&
        a >= kSmallestNormalExponent)
        return scaled(z, M);
    return scaled_beyond_range(z, a);
}
// z exp(a), past the range of exp as well: the 2x2 plane's eigencomponents
// and its e^tau, where a tiny component under a growth beyond e^709 is a
// double (and inf times 0 was not).
inline double times_exponential(double z, double a) {
    const double e = std::exp(a);
    return e <= std::numeric_limits<double>::max() && a >= kSmallestNormalExponent ? z * e
                                                                                    : scaled_beyond_range(z, a);
}
// Whether exp(a) - 1 may fall below -1/2: not for |a| <= 1/2, where it is at
// least e^-1/2 - 1 > -0.4 however it is rounded, so a flow whose exponents
// are all that small takes z + growth z without asking, with the same bits.
inline bool may_contract_by_half(double a) { return std::fabs(a) > 0.5; }

// ---- Flows without a systematic error -----------------------------------
// A flow keeps the Casimirs without bias only where its map leaves the group
// by the rounding of values that depend on the state. A constant rounded the
// same way in every flow (the same t and g) moves each flow off the group in
// the same direction, and the Casimirs drift linearly: the moments' I by
// -8.6e-18 of its terms in one flow of V at t = 0.2 (38 standard errors over
// 2e5 random states), 2e-12 after 1e6 leapfrog steps, where rounding alone
// gives 1e-13. Two such constants are kept out:
//  - the entries t c g_p of t A, each rounded on its own, are no multiple of
//    the C_p. So s_p = t g_p is rounded once (exp(s_p C_p) is still a flow
//    of the algebra) and cut to a width at which c s_p is exact for every
//    coefficient c of parameter p (shortening_bits; a coefficient with more
//    than kMaxShorteningBits significant bits is left to round).
//  - the 1/k of the series (1/3, 1/5, ...): the k-th terms are acc / k =
//    acc hi + acc lo, hi + lo = 1/k to twice the precision.
constexpr int kMaxShorteningBits = 8;

// The bits s must end in zeros for c s to be exact: as many as c has
// significant bits (a product of m and n bits has at most m + n), none for a
// power of two or 0; -1 beyond kMaxShorteningBits.
constexpr int shortening_bits(double c) {
    double v = c < 0 ? -c : c;
    if (!(v > 0.0) || v > std::numeric_limits<double>::max()) return 0;
    for (int guard = 0; v < 4503599627370496.0 && guard < 1100; ++guard) v *= 2.0;  // 2^52
    while (v >= 9007199254740992.0) v *= 0.5;                                        // 2^53
    std::uint64_t significand = static_cast<std::uint64_t>(v);
    int bits = 53;
    while ((significand & 1u) == 0) significand >>= 1, --bits;
    if (bits == 1) return 0;
    return bits <= kMaxShorteningBits ? bits : -1;
}

// s rounded to its leading 53 - bits bits, to nearest (half a unit of the
// last kept bit added to the magnitude, then the rest cleared: a carry into
// the exponent gives the next power of two): a time off by at most
// 2^(bits-53) of itself, of either sign, so the flow is still one of the
// algebra and a state-dependent g errs as often long as short. (Cut towards
// zero, every flow was short: so(3) scaled by 255/256 lagged 3.9e-9 after
// 1e5 steps, against 4e-11 from the rounding of t g alone.) On the bit
// pattern, which vector types keep in a floating-point register (a round
// trip through an integer register lengthened every flow's chain). Near the
// largest double, where the rounding would carry into infinity, s is cut.
inline double shortened(double s, int bits) {
    if (bits <= 0) return s;
    const std::uint64_t half = std::uint64_t{1} << (bits - 1), mask = ~((std::uint64_t{1} << bits) - 1);
    double rounded;
#if defined(__GNUC__)
    typedef double Double2 __attribute__((vector_size(16)));
    typedef std::uint64_t Bits2 __attribute__((vector_size(16)));
    const Double2 value = {s, s};
    Bits2 pattern;
    std::memcpy(&pattern, &value, sizeof value);
    pattern = (pattern + Bits2{half, 0}) & Bits2{mask, mask};
    Double2 cut;
    std::memcpy(&cut, &pattern, sizeof cut);
    if (std::fabs(cut[0]) <= std::numeric_limits<double>::max()) return cut[0];
    rounded = cut[1];
#else
    std::uint64_t pattern = 0;
    std::memcpy(&pattern, &s, sizeof s);
    const std::uint64_t up = (pattern + half) & mask;
    std::memcpy(&rounded, &up, sizeof rounded);
    if (std::fabs(rounded) <= std::numeric_limits<double>::max()) return rounded;
    pattern &= mask;
    std::memcpy(&rounded, &pattern, sizeof rounded);
#endif
    return rounded;
}

// 1/k as hi + lo: hi the double nearest 1/k, lo the rest (0 for a power of
// two). Where long double is double, lo comes out 0: the plain product.
struct Reciprocal {
    double hi, lo;
};
constexpr Reciprocal reciprocal(int k) {
    const double hi = 1.0 / k;
    return {hi, static_cast<double>((1.0L - static_cast<long double>(k) * hi) / k)};
}
// acc / k without 1/k's own rounding, r = reciprocal(k). Asked of k, not of
// r.lo, so that unrolled lanes know the answer when they are compiled.
inline double divided(double acc, std::size_t k, const Reciprocal &r) {
    return (k & (k - 1)) == 0 ? acc * r.hi : acc * r.hi + acc * r.lo;
}

// The terms split by the blocks of indices they join (rows and columns
// together; an index touched by no term is in none), each block's terms in
// their order. One block: the terms themselves.
std::vector<std::vector<SparseTerm>> disjoint_blocks(const std::vector<SparseTerm> &terms);

// LPI_ERR_NONFINITE: the exact flow's increment of `component` is not finite.
[[noreturn]] void fail_flow_overflow(std::size_t component);

// Most squarings a flow may take (||t A||_1 <= 5.37 * 2^32 ~ 2.3e10): the
// Casimir error of the Pade path grows like 2^squarings unit round-offs. The
// closed form of the plane path is held to the same bound, so whether a step
// is refused does not depend on the path.
constexpr int kMaxSquarings = 32;
// theta_13 of Higham (2005), Table 2.3: the largest ||A||_1 that the degree-13
// Pade approximant takes without scaling.
constexpr double kPadeTheta13 = 5.371920351148152e0;

// The EllipticSeries path (SparseExponential::apply_elliptic): at most 2^6
// substeps (||t A||_1 <= 32); a longer flow takes Pade. And its terms: as
// many as bring the series' remainder below 2^-70 of x (18 at ||h C|| = 1/2).
constexpr int kMaxEllipticHalvings = 6;
constexpr int kMaxEllipticTerms = 24;
// And only for a block of at most this order (elliptic_block takes 86
// products of m x m matrices when the piece is added).
constexpr std::size_t kMaxEllipticOrder = 64;

// Whether exp(tau C) of the dense m x m C (row-major) grows no faster than
// a polynomial in tau: ||exp(+-2^k C / ||C||_1)||_1 <= 2^(20 + k (m - 1)),
// at most 2^900, for k = 0 .. 42 (repeated squaring). Every eigenvalue of C
// then has |Re| <= 624 ||C||_1 / 2^42, so over the flows the series takes
// (||t A||_1 <= 32) no component grows or contracts exponentially by more
// than e^(5e-9): an elliptic C (imaginary eigenvalues) as far as any of
// those flows can tell, semisimple or not (a nilpotent part, or a nearly
// parabolic block bounded only by about 1/delta, grows polynomially). A
// hyperbolic C fails: its contracted coordinates keep their relative
// accuracy on the Pade path.
bool elliptic_block(std::size_t m, const std::vector<double> &C);

// ||C^k||_1 for k = 1 .. count of the dense m x m C (row-major).
std::vector<double> power_norms(std::size_t m, const std::vector<double> &C, int count);

// x <- exp(t A) x for the matrices A = sum_p g_p C_p of fixed sparse C_p,
// the parameters g changing from call to call: a piece flow, whose C_p
// depend only on the structure constants and the index set, its g on the
// gradient. What the pattern of A alone decides is worked out once, at
// construction:
//  - an acyclic pattern (A nilpotent, A^(depth+1) = 0, depth the longest
//    path): the finite series sum_k (tA)^k x / k!, in one sweep over the
//    indices it moves in topological order, each index's terms k = 1..depth
//    at once from those of the indices its row reads; work O(nnz * depth),
//    nothing dense (depth 1, a shear: one sum a moved index, no series);
//  - a diagonal D that commutes with an acyclic rest N (each entry of N
//    joins two indices with the same diagonal terms: the scalings of a
//    graded algebra, such as the moment algebra's <qp>) in a block of three
//    or more: exp(tD) exp(tN), the series of N then one expm1 per distinct
//    diagonal entry;
//  - otherwise the block of the indices the pattern touches: of order 1 or 2
//    in closed form (A = tau I + N with N^2 = delta I: exponentials,
//    sines or hyperbolic sines), larger ones by the Pade exponential;
//  - except a block of three or more that one parameter couples, A = s C,
//    whose flows are all bounded (elliptic_block: every eigenvalue of C
//    imaginary, as in su(3), so(4), so(3) in a dense basis): the Taylor
//    series on the vector, sum_k (hC)^k x / k!, over 2^j substeps h = s /
//    2^j with ||h C||_1 <= 1/2, each rounding x once (EllipticSeries).
// apply() allocates nothing.
class SparseExponential {
public:
    // Indices < n; terms at the same position add (in the order of their
    // parameters).
    SparseExponential(std::size_t n, std::vector<SparseTerm> terms);

    ExpmPath path() const { return path_; }
    // The longest path of a nilpotent pattern (A^(depth+1) = 0), else -1.
    long depth() const { return path_ == ExpmPath::Nilpotent ? static_cast<long>(depth_) : -1; }

    // Per parameter, the bits cut from s_p = t g_p (see shortened), and a
    // wider cut to share with the other blocks of one flow (disjoint_blocks),
    // so that every block runs for the very same times s_p.
    const std::vector<int> &shortening() const { return shortening_; }
    void widen_shortening(const std::vector<int> &bits);

    // Applies x <- exp(t A) x in place for A = sum_p g[p] C_p.
    // Throws lpi::Error, x unchanged, when the result is not finite
    // (LPI_ERR_NONFINITE) or, off the nilpotent path, ||t A||_1 needs more
    // than kMaxSquarings squarings (LPI_ERR_INVALID).
    void apply(const double *g, double t, double *x);

private:
    // A moved index of the nilpotent path. The nodes are in topological
    // order (by level); the positions of A follow in the same order, each
    // node's own first: those whose column is a fixed index, then those whose
    // column is an earlier node.
    struct SeriesNode {
        std::uint32_t global;
        std::uint32_t fixed_columns;
        std::uint32_t moved_columns;
    };
    struct BlockEntry {  // where a position lies in the block (local indices)
        std::uint32_t row;
        std::uint32_t col;
    };
    struct Scaling {  // a diagonal position of the DiagonalSeries path
        std::uint32_t global;
        std::uint32_t position;
        int group;     // its PowerGroup, or -1: its own expm1
        int multiple;  // k: the entry is k times the group's base
    };
    struct PowerGroup {  // diagonal entries k c g_p of one parameter p
        std::uint32_t parameter;
        double base;  // c
        int largest;  // the largest |k|
    };
    static constexpr int kMaxMultiple = kMaxScalingMultiple;
    struct Term {  // a further term of a position with several
        std::uint32_t position;
        std::uint32_t parameter;
        double coefficient;
    };

    void shorten_times(const double *g, double t);  // times_ = s_p = t g_p, shortened
    void scale_entries();                           // scaled_ = entries of t A from times_
    template <std::size_t Lanes>
    bool sweep(double *x);
    bool sweep(double *x);                // in lanes_ lanes
    void apply_scalings(double *x);  // DiagonalSeries: exp(tD) after N, from times_
    // Its body, compiled for the baseline and with FMA (cpu_features.hpp).
    [[gnu::always_inline]] inline void scale(double *x);
    void scale_baseline(double *x);
#if LPI_FMA_DISPATCH
    LPI_TARGET_FMA void scale_fma(double *x);
#endif
    bool shear(double *x);  // depth 1, x untouched on failure
    // shear_ with one node of one term (a kick): shear's arithmetic without
    // its loops, s_p formed here (the same bits).
    bool single_shear(const double *g, double t, double *x);
    void apply_plane(double t, double *x);  // a block of order 1 or 2
    // The plane's elliptic flows: M = exp(t A) as three shears (see
    // elliptic_shears), applied to x0, x1.
    struct Shears {
        double first, lower, last;
        bool turned;  // past a quarter turn: the shears of -M
    };
    static Shears rotation_shears(double b);  // t A = [[0, b], [-b, 0]]
    static Shears elliptic_shears(const double A[4]);
    void apply_shears(const Shears &M, double x0, double x1, double *x);
    bool rotate(double t, double *x);  // rotation_: see the definition
    void apply_pade(double t, double *x);
    // EllipticSeries: exp(s C) x as 2^j substeps of the series on the vector
    // (see the definition); Pade beyond kMaxEllipticHalvings.
    void apply_elliptic(double t, double *x);
    void check_norm(double norm, double t) const;
    // Throws LPI_ERR_NONFINITE naming the first moved index whose entry of
    // increment_ (its new value, or its increment on the plane path) is not finite.
    [[noreturn]] void fail_nonfinite() const;

    ExpmPath path_ = ExpmPath::Nilpotent;
    std::size_t depth_ = 0;
    bool shear_ = false;  // depth 1, one term a position: shear() applies it
    bool single_shear_ = false;  // and one node of one term: single_shear()
    // A plane whose t A is [[0, b], [-b, 0]], b = rotation_coefficient_ s_p
    // (so(3)'s axes, e(2)'s rotation): rotate() applies it.
    bool rotation_ = false;
    std::uint32_t rotation_parameter_ = 0;
    double rotation_coefficient_ = 0.0;
    // The increments' indices, local -> global (nilpotent: the nodes; block:
    // every index the pattern touches).
    std::vector<std::uint32_t> moved_;
    // Each distinct position of A sums its first term and the further ones.
    std::vector<SparseTerm> first_terms_;
    std::vector<Term> further_terms_;
    // Nilpotent path. Node v keeps the Taylor coefficients of its component,
    // c_v[k] = ((tA)^k x / k!)_v for k < lanes_, in coefficients_[v * lanes_ +
    // k]; c_v[k] = (1/k) sum_u (tA)_vu c_u[k - 1] over the entries of its row.
    // lanes_ >= depth_ (rounded up to a width the compiler unrolls).
    std::vector<SeriesNode> nodes_;
    std::vector<std::uint32_t> columns_;  // per position: global index or earlier node
    std::size_t lanes_ = 1;
    std::vector<Reciprocal> inverse_;  // 1 / (k + 1), k < lanes_
    std::vector<int> shortening_;      // per parameter: bits cleared from s_p
    std::vector<double> times_;        // per parameter: s_p
    std::vector<double> coefficients_, accumulator_;
    std::vector<Scaling> scalings_;
    std::vector<PowerGroup> power_groups_;
    std::vector<Exponential> powers_;  // per group: exp(k s), k = -kMaxMultiple .. kMaxMultiple
    std::vector<double> scaled_values_;
    std::vector<BlockEntry> block_;  // per position, block paths
    std::vector<bool> alone_;        // Pade: per local index, a component of its own
    // EllipticSeries: its one parameter, ||C||_1, and the positions by row
    // (local): those of row i are elliptic_positions_[elliptic_rows_[i] ..
    // elliptic_rows_[i + 1]).
    std::uint32_t elliptic_parameter_ = 0;
    double elliptic_norm_ = 0.0;
    double elliptic_rate_ = 0.0;                 // the largest ||C^k||_1^(1/k), k >= 2
    std::vector<double> elliptic_power_norms_;  // ||C^k||_1, k = 1 .. kMaxEllipticTerms + 1
    std::vector<std::uint32_t> elliptic_rows_, elliptic_positions_;
    std::vector<double> elliptic_entries_, elliptic_terms_;
    std::vector<double> scaled_, increment_, dense_, exp_, direct_, pade_scratch_;
};

}  // namespace lpi
