// Compiled flows of a built-in algebra's linear pieces, the way FFTW ships
// codelets for small sizes: when the structure constants are known when the
// library is compiled, the plan SparseExponential makes when a piece is added
// (the pattern of A, the levels of its nilpotent series, the order of the
// sums, the diagonal's exponentials) is made by the compiler instead, for
// every abelian index set whose pattern is nilpotent or a diagonal that
// commutes with a nilpotent rest, and each flow is straight-line code with
// no tables to read. The arithmetic is SparseExponential's, operation for
// operation (each row's fixed columns first, then its moved ones, each in
// order of column; lanes k = 1..level; the increment summed in order of k;
// the diagonal's exponentials by powers; only a lane's sum starts from its
// first product instead of 0), so a compiled flow gives the same bits as the
// general one (test_compiled_flows checks every index set).
//
// An algebra is a type with `static constexpr int dim` (at most 16) and
// `static constexpr Bracket brackets[]`: {x_i, x_j} = c x_k for i < j, one
// term per pair.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "../core/cpu_features.hpp"
#include "expm.hpp"

namespace lpi {

struct Bracket {
    std::int32_t i, j, k;
    double c;
};

// An algebra's brackets as the four arrays lpi_generic_create takes.
template <class Algebra>
struct BracketColumns {
    static constexpr std::size_t count = sizeof Algebra::brackets / sizeof(Bracket);
    std::int32_t i[count] = {}, j[count] = {}, k[count] = {};
    double c[count] = {};
    constexpr BracketColumns() {
        for (std::size_t e = 0; e < count; ++e) {
            i[e] = Algebra::brackets[e].i;
            j[e] = Algebra::brackets[e].j;
            k[e] = Algebra::brackets[e].k;
            c[e] = Algebra::brackets[e].c;
        }
    }
};

// x <- exp(t A) x for the piece on the index set of its table entry, A_il =
// sum_p c_{i sigma_p}^l g_p with g in the order of the sorted index set.
// Returns -1, or, x untouched, the first component whose increment is not
// finite.
using CompiledFlow = long (*)(const double *g, double t, double *x);

namespace compiled {

constexpr int kMaxDim = 16;
constexpr int kMaxEntries = 64;

struct Entry {  // A_row,col += coefficient * g_parameter
    int row, col, parameter;
    double coefficient;
};

struct Scaling {  // a diagonal entry c g_p of index `index`
    int index, parameter;
    double coefficient;
    int group;     // its Group, or -1: its own expm1
    int multiple;  // k: c is k times the group's base
};
struct Group {  // diagonal entries k base g_p of one parameter
    int parameter;
    double base;
    int largest;  // the largest |k|
};
constexpr int kMaxMultiple = kMaxScalingMultiple;

// What SparseExponential's constructor works out for one index set (`mask`:
// bit j for index j), at compile time.
struct Plan {
    bool usable = false;  // abelian, A not zero, one term a position, and a
                          // nilpotent pattern or a diagonal that commutes
                          // with a nilpotent rest (in a block of three or more)
    int depth = 0;
    int level[kMaxDim] = {};  // 0: not moved
    int nodes = 0;
    int order[kMaxDim] = {};      // moved indices by level, then index
    int first[kMaxDim + 1] = {};  // entries of node n: first[n] .. first[n + 1]
    int count = 0;
    Entry entry[kMaxEntries] = {};
    int scalings = 0;
    Scaling scaling[kMaxDim] = {};
    int groups = 0;
    Group group[kMaxDim] = {};
    int parameters = 0;
    int shortening[kMaxDim] = {};  // per parameter, as SparseExponential's
};

constexpr double absolute(double v) { return v < 0 ? -v : v; }

template <class Algebra>
constexpr Plan plan(unsigned mask) {
    constexpr int dim = Algebra::dim;
    Plan P;
    // Abelian: no bracket between two indices of the set.
    for (const Bracket &b : Algebra::brackets)
        if ((mask >> b.i & 1u) && (mask >> b.j & 1u)) return P;
    // The terms of A: c_{i j}^k g_p for j the p-th index of the set.
    Entry raw[kMaxEntries] = {};
    int count = 0, parameter = 0;
    for (int j = 0; j < dim; ++j) {
        if (!(mask >> j & 1u)) continue;
        for (const Bracket &b : Algebra::brackets) {
            if (count + 2 > kMaxEntries) return P;  // too many to compile: the general plan
            if (b.j == j) raw[count++] = {b.i, b.k, parameter, b.c};
            if (b.i == j) raw[count++] = {b.j, b.k, parameter, -b.c};
        }
        ++parameter;
    }
    if (count == 0) return P;
    P.parameters = parameter;
    for (int e = 0; e < count; ++e) {
        const int bits = shortening_bits(raw[e].coefficient);
        if (bits > P.shortening[raw[e].parameter]) P.shortening[raw[e].parameter] = bits;
    }
    for (int e = 0; e < count; ++e)
        for (int f = e + 1; f < count; ++f)
            if (raw[e].row == raw[f].row && raw[e].col == raw[f].col) return P;
    // The diagonal: it must commute with the rest (an entry of the rest
    // joins two indices with the same diagonal term, or none), and the
    // pattern touch three indices or more (two: SparseExponential's closed
    // form of a plane).
    double diagonal[kMaxDim] = {};
    int diagonal_parameter[kMaxDim] = {}, touched = 0;
    bool has_diagonal[kMaxDim] = {}, touches[kMaxDim] = {};
    for (int e = 0; e < count; ++e) {
        touches[raw[e].row] = touches[raw[e].col] = true;
        if (raw[e].row != raw[e].col) continue;
        has_diagonal[raw[e].row] = true;
        diagonal[raw[e].row] = raw[e].coefficient;
        diagonal_parameter[raw[e].row] = raw[e].parameter;
        P.scaling[P.scalings++] = {raw[e].row, raw[e].parameter, raw[e].coefficient, -1, 0};
    }
    for (int v = 0; v < dim; ++v) touched += touches[v] ? 1 : 0;
    if (P.scalings > 0 && touched <= 2) return P;
    for (int e = 0; e < count; ++e) {
        const int r = raw[e].row, c = raw[e].col;
        if (r != c && (has_diagonal[r] != has_diagonal[c] ||
                       (has_diagonal[r] && (diagonal[r] != diagonal[c] ||
                                            diagonal_parameter[r] != diagonal_parameter[c]))))
            return P;
    }
    // Diagonal entries that are multiples k of their parameter's smallest
    // |c| take their exponentials by powers, as SparseExponential's do.
    for (int d = 0; d < P.scalings; ++d) {
        Scaling &scaling = P.scaling[d];
        const double size = absolute(scaling.coefficient);
        int g = 0;
        while (g < P.groups && P.group[g].parameter != scaling.parameter) ++g;
        if (g == P.groups) P.group[P.groups++] = {scaling.parameter, size, 0};
        if (size < P.group[g].base) P.group[g].base = size;
        scaling.group = g;
    }
    for (int d = 0; d < P.scalings; ++d) {
        Scaling &scaling = P.scaling[d];
        Group &group = P.group[scaling.group];
        const double c = scaling.coefficient, k = c / group.base;
        const int whole = absolute(k) <= kMaxMultiple ? static_cast<int>(k) : 0;
        if (whole == 0 || k != static_cast<double>(whole) || k * group.base != c) {
            scaling.group = -1;
            continue;
        }
        scaling.multiple = whole;
        const int size = whole < 0 ? -whole : whole;
        if (size > group.largest) group.largest = size;
    }
    // Levels: the longest path ending at each index off the diagonal; still
    // growing after dim rounds means a cycle (no nilpotent series).
    bool moved[kMaxDim] = {};
    for (int e = 0; e < count; ++e)
        if (raw[e].row != raw[e].col) moved[raw[e].row] = true;
    for (int round = 0; round <= dim; ++round) {
        bool grew = false;
        for (int e = 0; e < count; ++e) {
            if (raw[e].row == raw[e].col) continue;
            const int candidate = P.level[raw[e].col] + 1;
            if (candidate > P.level[raw[e].row]) {
                P.level[raw[e].row] = candidate;
                grew = true;
            }
        }
        if (!grew) break;
        if (round == dim) return P;
    }
    for (int v = 0; v < dim; ++v)
        if (P.level[v] > P.depth) P.depth = P.level[v];
    for (int l = 1; l <= P.depth; ++l)
        for (int v = 0; v < dim; ++v)
            if (moved[v] && P.level[v] == l) P.order[P.nodes++] = v;
    // Each node's entries: fixed columns first, then moved ones, each in
    // order of column.
    for (int n = 0; n < P.nodes; ++n) {
        P.first[n] = P.count;
        for (int pass = 0; pass < 2; ++pass)
            for (int col = 0; col < dim; ++col)
                for (int e = 0; e < count; ++e)
                    if (raw[e].row == P.order[n] && raw[e].col == col && raw[e].row != raw[e].col &&
                        (P.level[col] == 0) == (pass == 0))
                        P.entry[P.count++] = raw[e];
    }
    P.first[P.nodes] = P.count;
    P.usable = true;
    return P;
}

template <int First, class F, int... I>
inline void unroll(std::integer_sequence<int, I...>, F &&f) {
    (f(std::integral_constant<int, First + I>{}), ...);
}
// f(integral_constant<int, i>) for i = First .. Last - 1, in order.
template <int First, int Last, class F>
inline void unroll(F &&f) {
    unroll<First>(std::make_integer_sequence<int, Last - First>{}, f);
}

// v[0] + .. + v[Count - 1], in pairs (a tree of depth log2 Count, not a
// chain of Count additions).
template <int Count>
inline double pairwise_sum(const double *v) {
    if constexpr (Count <= 1)
        return Count == 1 ? v[0] : 0.0;
    else
        return pairwise_sum<Count / 2>(v) + pairwise_sum<Count - Count / 2>(v + Count / 2);
}
inline bool within_range(double v) { return std::fabs(v) <= std::numeric_limits<double>::max(); }

template <class Algebra, unsigned Mask>
struct Piece {
    static constexpr Plan P = plan<Algebra>(Mask);

    // The first node, in order, whose new value is not finite.
    static long first_nonfinite(const double *values) {
        for (int n = 0; n < P.nodes; ++n)
            if (!std::isfinite(values[P.order[n]])) return P.order[n];
        return -1;
    }

    // Near the identity (every scaling exponent at most 1/2 in size, every
    // factor a normal double within [e^-1/2, e^1/2]) the flow scales without
    // asking; otherwise a second instantiation, out of the first one's way,
    // asks scaled_by_exponential for each scaling. Both give the general
    // plan's bits.
    static long flow(const double *g, double t, double *x) { return flow_body(g, t, x); }
#if LPI_FMA_DISPATCH
    // The same flow with the exponentials' fma as instructions (the same bits).
    LPI_TARGET_FMA static long flow_fma(const double *g, double t, double *x) { return flow_body(g, t, x); }
#endif

    [[gnu::always_inline]] static inline long flow_body(const double *g, double t, double *x) {
        double s[P.parameters];
        unroll<0, P.parameters>([&](auto p) { s[p] = shortened(t * g[p], P.shortening[p]); });
        bool far = false;
        unroll<0, P.groups>([&](auto q) {
            constexpr Group G = P.group[q];
            far |= may_contract_by_half(G.largest * (G.base * s[G.parameter]));
        });
        unroll<0, P.scalings>([&](auto d) {
            constexpr Scaling S = P.scaling[d];
            if constexpr (S.group < 0) far |= may_contract_by_half(S.coefficient * s[S.parameter]);
        });
        if (far) return far_flow(s, x);
        return flow_in<false>(s, x);
    }

    // The far case out of line, so that the near one is inlined in flow
    // (s then stays in registers).
    [[gnu::noinline]] static long far_flow(const double *s, double *x) { return flow_in<true>(s, x); }

    template <bool Far>
    [[gnu::always_inline]] static inline long flow_in(const double *s, double *x) {
        constexpr int depth = P.depth;
        // For exp(tD): M_k = exp(k s) of each group by powers of one
        // expm1 (exponential_powers, shared with SparseExponential); first,
        // so that nothing of x is held across the calls.
        Exponential factors[P.groups > 0 ? P.groups : 1][2 * kMaxMultiple + 1];
        unroll<0, P.groups>([&](auto q) {
            constexpr Group G = P.group[q];
            if constexpr (Far)
                exponential_powers(G.base * s[G.parameter], G.largest, factors[q] + kMaxMultiple);
            else
                exponential_powers_near(G.base * s[G.parameter], G.largest, factors[q] + kMaxMultiple);
        });
        // c[v][k] = ((tN)^k x / k!)_v, written for k <= level(v) and read
        // only there (the general sweep's lanes above are exact zeros).
        double c[Algebra::dim][depth + 1];
        unroll<0, Algebra::dim>([&](auto v) { c[v][0] = x[v]; });
        double increment[Algebra::dim];
        unroll<0, P.nodes>([&](auto n) {
            constexpr int v = P.order[n], level = P.level[v];
            // The sums start from their first product, not from 0.0 + it:
            // the two differ only in the sign of a zero, which reaches no
            // result (each increment is summed from 0.0), and the additions
            // of zero were a sixth of the flow's operations.
            constexpr Entry first = P.entry[P.first[n]];
            constexpr int first_lanes = P.level[first.col] + 1 < level ? P.level[first.col] + 1 : level;
            double acc[level];
            unroll<first_lanes, level>([&](auto k) { acc[k] = 0.0; });
            unroll<P.first[n], P.first[n + 1]>([&](auto e) {
                constexpr Entry E = P.entry[e];
                constexpr int lanes = P.level[E.col] + 1 < level ? P.level[E.col] + 1 : level;
                const double a = E.coefficient * s[E.parameter];
                if constexpr (e == P.first[n])
                    unroll<0, lanes>([&](auto k) { acc[k] = a * c[E.col][k]; });
                else
                    unroll<0, lanes>([&](auto k) { acc[k] += a * c[E.col][k]; });
            });
            double total = 0.0;
            unroll<0, level>([&](auto k) {
                constexpr Reciprocal inverse = reciprocal(k + 1);
                const double term = divided(acc[k], k + 1, inverse);
                total += term;
                c[v][k + 1] = term;
            });
            increment[v] = total;
        });
        double y[Algebra::dim];  // exp(tN) x
        unroll<0, Algebra::dim>([&](auto v) { y[v] = x[v]; });
        unroll<0, P.nodes>([&](auto n) { y[P.order[n]] = c[P.order[n]][0] + increment[P.order[n]]; });
        // One test for all the new values (x + a finite increment may
        // overflow): their sum, in pairs, is finite unless one of them is
        // not or the sum itself overflows, which the test of each then tells
        // apart.
        double moved[P.nodes > 0 ? P.nodes : 1];
        unroll<0, P.nodes>([&](auto n) { moved[n] = y[P.order[n]]; });
        if (!within_range(pairwise_sum<P.nodes>(moved))) {
            const long failed = first_nonfinite(y);
            if (failed >= 0) return failed;
        }
        double scaled[P.scalings > 0 ? P.scalings : 1];
        unroll<0, P.scalings>([&](auto d) {
            constexpr Scaling S = P.scaling[d];
            Exponential factor;
            double exponent;
            if constexpr (S.group < 0) {
                exponent = S.coefficient * s[S.parameter];
                factor = exponential_of(exponent);
            } else {
                constexpr Group G = P.group[S.group];
                exponent = S.multiple * (G.base * s[G.parameter]);
                factor = factors[S.group][kMaxMultiple + S.multiple];
            }
            if constexpr (Far)
                scaled[d] = scaled_by_exponential(y[S.index], factor, exponent);
            else
                scaled[d] = lpi::scaled(y[S.index], factor);
        });
        // Near the identity every factor lies in [e^-1/2, e^1/2], so
        // no scaled value can overflow where every |y| is at most half the
        // largest double: a test on y, known before the exponentials, instead
        // of one at the end of the flow's chain of operations (with that one
        // the squeeze took 2.26x a hand-written flow's time, with this one
        // 2.04x; design.md, "Overflow checks").
        bool may_overflow = true;
        if constexpr (!Far && P.scalings > 0) {
            double sizes[P.scalings];
            unroll<0, P.scalings>([&](auto d) { sizes[d] = std::fabs(y[P.scaling[d].index]); });
            may_overflow = !(pairwise_sum<P.scalings>(sizes) <= 0.5 * std::numeric_limits<double>::max());
        }
        if constexpr (P.scalings > 0) {
            if (may_overflow && !within_range(pairwise_sum<P.scalings>(scaled))) {
                for (int d = 0; d < P.scalings; ++d)
                    if (!std::isfinite(scaled[d])) return P.scaling[d].index;
            }
        }
        unroll<0, P.scalings>([&](auto d) { y[P.scaling[d].index] = scaled[d]; });
        unroll<0, P.nodes>([&](auto n) { x[P.order[n]] = y[P.order[n]]; });
        unroll<0, P.scalings>([&](auto d) { x[P.scaling[d].index] = y[P.scaling[d].index]; });
        return -1;
    }
};

template <class Algebra, unsigned Mask, bool Fma>
constexpr CompiledFlow flow_of() {
    if constexpr (!Piece<Algebra, Mask>::P.usable)
        return nullptr;
#if LPI_FMA_DISPATCH
    // Only where the flow scales: compiled for FMA, the nilpotent V(x1, x4)
    // took 21 ns a flow against 17.6 for the baseline's (bench_piece_flows).
    else if constexpr (Fma && Piece<Algebra, Mask>::P.scalings > 0)
        return &Piece<Algebra, Mask>::flow_fma;
#endif
    else
        return &Piece<Algebra, Mask>::flow;
}

template <class Algebra, bool Fma, unsigned... Masks>
constexpr void fill_table(CompiledFlow *table, std::integer_sequence<unsigned, Masks...>) {
    ((table[Masks] = flow_of<Algebra, Masks, Fma>()), ...);
}

// The compiled flows of every index set of the algebra, by mask (nullptr
// where there is none), for the baseline and for processors with FMA.
template <class Algebra>
struct Table {
    static_assert(Algebra::dim <= kMaxDim, "a compiled algebra has at most kMaxDim indices");
    CompiledFlow flows[1u << Algebra::dim] = {};
    CompiledFlow fma_flows[1u << Algebra::dim] = {};
    constexpr Table() {
        fill_table<Algebra, false>(flows, std::make_integer_sequence<unsigned, 1u << Algebra::dim>{});
        fill_table<Algebra, true>(fma_flows, std::make_integer_sequence<unsigned, 1u << Algebra::dim>{});
    }
    CompiledFlow flow(unsigned mask) const {
        if (mask >= sizeof flows / sizeof flows[0]) return nullptr;
        return cpu_has_fma() ? fma_flows[mask] : flows[mask];
    }
};

}  // namespace compiled

}  // namespace lpi
