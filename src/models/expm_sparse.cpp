// The sparse exponentials of a fixed pattern (SparseExponential, expm.hpp):
// what the pattern decides is planned once, each flow only fills in values.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../core/text.hpp"
#include "expm.hpp"

namespace lpi {

namespace {

// exp(A) - I of a 2x2 A = [[a, b], [c, d]] (W row-major) in closed form:
// A = tau I + N, tau = (a + d) / 2, N^2 = delta I with delta = -det N, so
// exp(A) = e^tau (C I + S N), C = cosh or cos of r = sqrt|delta|, S = sinh r
// or sin r over r. Formed as differences from I (C - 1 from the half angle,
// expm1 for e^tau) so that W is accurate relative to ||A||.
void plane_expm1(double a, double b, double c, double d, double W[4]) {
    const double tau = 0.5 * (a + d), p = 0.5 * (a - d);
    double c_minus_1 = 0.0, sp = p, sb = b, sc = c;  // C - 1 and S times p, b, c
    if (p == 0.0 && c == -b) {
        // A rotation generator (the Lie-Poisson rotations: so(3), e(2)):
        // r = |b| and S b = sin b, with no square root or division.
        const double h = std::sin(0.5 * b);
        c_minus_1 = -2.0 * h * h;
        sb = 2.0 * h * std::cos(0.5 * b);
        sc = -sb;
    } else {
        const double delta = p * p + b * c;
        double s = 1.0;
        if (delta > 0.0) {
            const double r = std::sqrt(delta), inverse_r = 1.0 / r, h = std::sinh(0.5 * r);
            c_minus_1 = 2.0 * h * h;
            s = 2.0 * h * std::sqrt(1.0 + h * h) * inverse_r;  // sinh r / r
        } else if (delta < 0.0) {
            const double r = std::sqrt(-delta), inverse_r = 1.0 / r, h = std::sin(0.5 * r);
            c_minus_1 = -2.0 * h * h;
            s = 2.0 * h * std::cos(0.5 * r) * inverse_r;  // sin r / r
        }
        sp = s * p;
        sb = s * b;
        sc = s * c;
    }
    // The Lie-Poisson rotations are traceless: no exponential to take.
    const double scale_minus_1 = tau == 0.0 ? 0.0 : std::expm1(tau);
    const double scale = 1.0 + scale_minus_1;
    W[0] = scale * (c_minus_1 + sp) + scale_minus_1;
    W[1] = scale * sb;
    W[2] = scale * sc;
    W[3] = scale * (c_minus_1 - sp) + scale_minus_1;
}

// exp(A) x of a 2x2 A = [[a, b], [c, d]] with real eigenvalues lambda+- =
// tau +- r (delta = r^2 > 0), as e^lambda+ P+ x + e^lambda- P- x with the
// spectral projectors P+- = (I +- N / r) / 2 (N = A - tau I), written so that
// nothing cancels: for p = (a - d) / 2 >= 0 the diagonal of P+ is ((r + p) /
// 2r, bc / (2r (r + p))) (as (r - p) / 2r = (r^2 - p^2) / (2r (r + p))), that
// of P- the same swapped, and for p < 0 the roles swap. Each eigencomponent
// is scaled by its own exponential, so the component the flow contracts keeps
// its relative accuracy; formed from cosh r - sinh r it would lose a factor
// e^2r. For r well away from 0 only: the projectors grow like 1 / r.
void plane_hyperbolic_apply(double a, double b, double c, double d, double &x0, double &x1) {
    const double tau = 0.5 * (a + d), p = 0.5 * (a - d);
    const double r = std::sqrt(p * p + b * c), q = std::fabs(p);
    const double high = (r + q) / (2.0 * r), low = b * c / (2.0 * r * (r + q));
    const double up_b = b / (2.0 * r), up_c = c / (2.0 * r);
    const double plus00 = p >= 0.0 ? high : low, plus11 = p >= 0.0 ? low : high;
    // P+ x and P- x = (I - P+) x, each formed from x directly.
    const double u0 = plus00 * x0 + up_b * x1, u1 = up_c * x0 + plus11 * x1;
    const double v0 = plus11 * x0 - up_b * x1, v1 = plus00 * x1 - up_c * x0;
    x0 = times_exponential(u0, tau + r) + times_exponential(v0, tau - r);
    x1 = times_exponential(u1, tau + r) + times_exponential(v1, tau - r);
}

// The m indices of a block in an order that makes its matrix block upper
// triangular: edges holds (j, i) for each entry A_ij != 0 off the diagonal
// (x_j drives x_i). Tarjan's algorithm emits a strongly connected component
// after every component it reaches, so the driven come first and an entry
// between two components lies above the diagonal blocks. The dense
// exponential's pivoting then never picks a row from a later component (the
// entries below the diagonal blocks are exact zeros), so exp(tA) keeps those
// zeros and a triangular block's diagonal its relative accuracy. In the
// order of first appearance, a lower-triangular block was pivoted into
// fill-in that the squarings multiplied into the contracted coordinate's row
// (e^-20 came out as -6e-7).
struct BlockOrder {
    std::vector<std::uint32_t> order;  // the indices, driven first
    std::vector<bool> alone;           // per place in order: a component of one index
};

BlockOrder driven_first(std::size_t m, const std::vector<std::pair<std::uint32_t, std::uint32_t>> &edges) {
    std::vector<std::size_t> start(m + 1, 0);
    for (const auto &e : edges) ++start[e.first + 1];
    for (std::size_t v = 0; v < m; ++v) start[v + 1] += start[v];
    std::vector<std::uint32_t> adjacency(edges.size());
    std::vector<std::size_t> cursor(start.begin(), start.end() - 1);
    for (const auto &e : edges) adjacency[cursor[e.first]++] = e.second;
    // Iterative Tarjan: a frame is a node and the next of its edges to follow.
    std::vector<std::int64_t> index(m, -1), low(m, 0);
    std::vector<bool> on_stack(m, false);
    std::vector<std::uint32_t> stack;
    BlockOrder result;
    std::vector<std::pair<std::uint32_t, std::size_t>> frames;
    std::int64_t counter = 0;
    auto visit = [&](std::uint32_t v) {
        index[v] = low[v] = counter++;
        stack.push_back(v);
        on_stack[v] = true;
        frames.push_back({v, start[v]});
    };
    for (std::uint32_t root = 0; root < m; ++root) {
        if (index[root] >= 0) continue;
        visit(root);
        while (!frames.empty()) {
            const std::uint32_t v = frames.back().first;
            if (frames.back().second < start[v + 1]) {
                const std::uint32_t w = adjacency[frames.back().second++];
                if (index[w] < 0)
                    visit(w);
                else if (on_stack[w])
                    low[v] = std::min(low[v], index[w]);
                continue;
            }
            frames.pop_back();
            if (!frames.empty()) low[frames.back().first] = std::min(low[frames.back().first], low[v]);
            if (low[v] != index[v]) continue;
            const std::size_t first = result.order.size();
            std::uint32_t w;
            do {
                w = stack.back();
                stack.pop_back();
                on_stack[w] = false;
                result.order.push_back(w);
            } while (w != v);
            result.alone.resize(result.order.size(), result.order.size() - first == 1);
        }
    }
    return result;
}

// The increment form x + (exp(A) - I) x rounds x once, which keeps the
// Casimirs free of bias near the identity; but where exp(A) contracts a
// component by e^-s it leaves that component only the accuracy of x itself,
// a relative error e^s times the round-off. Beyond ln 2 (a trace that
// contracts by more than half, or real eigenvalues tau +- r with r beyond
// it) the plane path applies exp(A) itself.
constexpr double kIncrementFormLimit = 0.6931471805599453;

}  // namespace

// ---- sparse exponentials of a fixed pattern -----------------------------------

std::vector<std::vector<SparseTerm>> disjoint_blocks(const std::vector<SparseTerm> &terms) {
    // Union-find over the indices the terms name.
    std::map<std::uint32_t, std::uint32_t> parent;
    auto root = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const SparseTerm &t : terms) {
        parent.emplace(t.row, t.row);
        parent.emplace(t.col, t.col);
        parent[root(t.row)] = root(t.col);
    }
    std::map<std::uint32_t, std::size_t> block_of;  // root -> block, in order of first term
    std::vector<std::vector<SparseTerm>> blocks;
    for (const SparseTerm &t : terms) {
        const auto found = block_of.emplace(root(t.row), blocks.size());
        if (found.second) blocks.emplace_back();
        blocks[found.first->second].push_back(t);
    }
    return blocks;
}

SparseExponential::SparseExponential(std::size_t n, std::vector<SparseTerm> terms) {
    std::sort(terms.begin(), terms.end(), [](const SparseTerm &a, const SparseTerm &b) {
        return std::tie(a.row, a.col, a.parameter) < std::tie(b.row, b.col, b.parameter);
    });
    // Distinct positions (terms first .. end - 1) and the indices they touch,
    // numbered locally in order of appearance.
    struct Position {
        std::uint32_t row, col;  // local
        std::size_t first, end;
    };
    std::vector<Position> positions;
    std::vector<std::int64_t> local_of(n, -1);
    std::vector<std::uint32_t> touched;
    auto local = [&](std::uint32_t g) {
        if (local_of[g] < 0) {
            local_of[g] = static_cast<std::int64_t>(touched.size());
            touched.push_back(g);
        }
        return static_cast<std::uint32_t>(local_of[g]);
    };
    for (std::size_t q = 0; q < terms.size(); ++q) {
        if (q > 0 && terms[q].row == terms[q - 1].row && terms[q].col == terms[q - 1].col) {
            positions.back().end = q + 1;
            continue;
        }
        positions.push_back({local(terms[q].row), local(terms[q].col), q, q + 1});
    }
    const std::size_t m = touched.size();

    // Levels by Kahn's algorithm on the edges col -> row (x_col drives x_row)
    // off the diagonal: level[v] is the longest path ending at v. A cycle
    // means the pattern does not force nilpotency.
    auto diagonal = [](const Position &e) { return e.row == e.col; };
    std::vector<std::size_t> start(m + 1, 0), cursor;
    std::vector<std::uint32_t> indegree(m, 0), adjacency(positions.size()), queue;
    for (const Position &e : positions) {
        if (diagonal(e)) continue;
        ++start[e.col + 1];
        ++indegree[e.row];
    }
    for (std::size_t v = 0; v < m; ++v) start[v + 1] += start[v];
    cursor.assign(start.begin(), start.end() - 1);
    for (const Position &e : positions)
        if (!diagonal(e)) adjacency[cursor[e.col]++] = e.row;
    for (std::uint32_t v = 0; v < m; ++v)
        if (indegree[v] == 0) queue.push_back(v);
    std::vector<std::size_t> level(m, 0);
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const std::uint32_t u = queue[head];
        depth_ = std::max(depth_, level[u]);
        for (std::size_t a = start[u]; a < start[u + 1]; ++a) {
            const std::uint32_t v = adjacency[a];
            level[v] = std::max(level[v], level[u] + 1);
            if (--indegree[v] == 0) queue.push_back(v);
        }
    }
    const bool acyclic = queue.size() == m;

    // A diagonal D that commutes with the rest N (the diagonal terms of a
    // position's row and column are the same: a grading, as the scalings of
    // a graded algebra have) gives exp(tA) = exp(tD) exp(tN), N nilpotent.
    std::vector<std::int64_t> diagonal_of(m, -1);  // local index -> its diagonal position
    for (std::size_t p = 0; p < positions.size(); ++p)
        if (diagonal(positions[p])) diagonal_of[positions[p].row] = static_cast<std::int64_t>(p);
    auto same_terms = [&](const Position *a_or_none, const Position *b_or_none) {
        if (!a_or_none || !b_or_none) return a_or_none == b_or_none;
        const Position &a = *a_or_none, &b = *b_or_none;
        if (a.end - a.first != b.end - b.first) return false;
        for (std::size_t r = 0; r < a.end - a.first; ++r)
            if (terms[a.first + r].parameter != terms[b.first + r].parameter ||
                terms[a.first + r].coefficient != terms[b.first + r].coefficient)
                return false;
        return true;
    };
    auto diagonal_at = [&](std::uint32_t v) -> const Position * {
        return diagonal_of[v] < 0 ? nullptr : &positions[static_cast<std::size_t>(diagonal_of[v])];
    };
    bool commuting = true, any_diagonal = false;
    for (const Position &e : positions) {
        any_diagonal = any_diagonal || diagonal(e);
        if (!diagonal(e)) commuting = commuting && same_terms(diagonal_at(e.row), diagonal_at(e.col));
    }

    // A diagonal that commutes takes the series' path at any size, where its
    // scalings are paired (exponential_powers); the plane's closed form
    // rounded e^-r and e^r apart, alike in every flow with the same constants.
    if (!acyclic || (any_diagonal && !commuting)) {
        path_ = m <= 2 ? ExpmPath::Plane : ExpmPath::Pade;
        depth_ = 0;
        // The plane's closed form takes any order; the Pade block is put in
        // block upper triangular form (driven_first).
        std::vector<std::uint32_t> order(m), new_of(m);
        for (std::uint32_t v = 0; v < m; ++v) order[v] = v;
        if (path_ == ExpmPath::Pade) {
            std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
            for (const Position &e : positions)
                if (!diagonal(e)) edges.push_back({e.col, e.row});
            BlockOrder block = driven_first(m, edges);
            order = std::move(block.order);
            alone_ = std::move(block.alone);
        }
        for (std::uint32_t k = 0; k < m; ++k) {
            new_of[order[k]] = k;
            moved_.push_back(touched[order[k]]);
        }
        for (const Position &e : positions) block_.push_back({new_of[e.row], new_of[e.col]});
        // One parameter couples the block (A = s C, one term a position):
        // where every flow of C is bounded (elliptic_block), exp(s C) x is
        // taken by the series on the vector instead (apply_elliptic).
        bool one_parameter = path_ == ExpmPath::Pade && m <= kMaxEllipticOrder;
        for (const Position &e : positions)
            one_parameter = one_parameter && e.end - e.first == 1 &&
                            terms[e.first].parameter == terms[positions[0].first].parameter;
        if (one_parameter) {
            std::vector<double> C(m * m, 0.0);
            for (std::size_t j = 0; j < positions.size(); ++j)
                C[block_[j].row * m + block_[j].col] = terms[positions[j].first].coefficient;
            if (elliptic_block(m, C)) {
                path_ = ExpmPath::EllipticSeries;
                elliptic_parameter_ = terms[positions[0].first].parameter;
                elliptic_norm_ = dense_norm1(m, C.data());
                // ||C^k||_1, k = 1 .. kMaxEllipticTerms + 1: bounds on the
                // terms (h C)^k / k! that follow the powers, not ||C||^k (for
                // so(3) in a dense basis, ||C^k||^(1/k) tends to its frequency
                // 4.1, where ||C||_1 is 16), and their rate, the largest
                // ||C^k||^(1/k) for k >= 2.
                elliptic_power_norms_ = power_norms(m, C, kMaxEllipticTerms + 1);
                for (int k = 2; k <= kMaxEllipticTerms + 1; ++k)
                    elliptic_rate_ = std::max(
                        elliptic_rate_, std::pow(elliptic_power_norms_[static_cast<std::size_t>(k - 1)], 1.0 / k));
                elliptic_rows_.assign(m + 1, 0);
                for (const BlockEntry &b : block_) ++elliptic_rows_[b.row + 1];
                for (std::size_t r = 0; r < m; ++r) elliptic_rows_[r + 1] += elliptic_rows_[r];
                std::vector<std::uint32_t> cursor(elliptic_rows_.begin(), elliptic_rows_.end() - 1);
                elliptic_positions_.resize(block_.size());
                for (std::uint32_t j = 0; j < block_.size(); ++j) elliptic_positions_[cursor[block_[j].row]++] = j;
                elliptic_entries_.resize(block_.size());
                elliptic_terms_.resize((kMaxEllipticTerms + 1) * m);
                for (int k = 0; k < kMaxEllipticTerms; ++k) inverse_.push_back(reciprocal(k + 1));
            }
        }
    } else {
        // The series of N: the moved indices (level >= 1) by level are in
        // topological order; each position goes with the node of its row.
        // The diagonal positions, if any, follow.
        path_ = any_diagonal ? ExpmPath::DiagonalSeries : ExpmPath::Nilpotent;
        std::vector<std::uint32_t> order;
        for (std::uint32_t v = 0; v < m; ++v)
            if (level[v] >= 1) order.push_back(v);
        std::stable_sort(order.begin(), order.end(),
                         [&](std::uint32_t u, std::uint32_t v) { return level[u] < level[v]; });
        std::vector<std::uint32_t> node_of(m, 0);
        for (std::uint32_t r = 0; r < order.size(); ++r) {
            node_of[order[r]] = r;
            moved_.push_back(touched[order[r]]);
            nodes_.push_back({touched[order[r]], 0, 0});
        }
        std::vector<Position> series, scalings;
        for (const Position &e : positions) (diagonal(e) ? scalings : series).push_back(e);
        auto fixed = [&](const Position &e) { return level[e.col] == 0; };
        std::stable_sort(series.begin(), series.end(), [&](const Position &a, const Position &b) {
            return std::make_pair(node_of[a.row], !fixed(a)) < std::make_pair(node_of[b.row], !fixed(b));
        });
        for (const Position &e : series) {
            SeriesNode &node = nodes_[node_of[e.row]];
            ++(fixed(e) ? node.fixed_columns : node.moved_columns);
            columns_.push_back(fixed(e) ? touched[e.col] : node_of[e.col]);
        }
        // The diagonal. An entry of one term c g_p whose c is an integer
        // multiple k of the smallest |c| of parameter p (|k| <=
        // kMaxMultiple: the weights of a graded algebra) takes its
        // exp(t c g_p) - 1 from one expm1 of that parameter, by powers; any
        // other takes its own expm1.
        std::vector<std::int64_t> group_of;  // by parameter
        for (std::size_t d = 0; d < scalings.size(); ++d) {
            const Position &e = scalings[d];
            const SparseTerm &term = terms[e.first];
            scalings_.push_back({touched[e.row], static_cast<std::uint32_t>(series.size() + d), -1, 0});
            if (e.end - e.first != 1 || term.coefficient == 0.0) continue;
            if (group_of.size() <= term.parameter) group_of.resize(term.parameter + 1, -1);
            if (group_of[term.parameter] < 0) {
                group_of[term.parameter] = static_cast<std::int64_t>(power_groups_.size());
                power_groups_.push_back({term.parameter, std::fabs(term.coefficient), 0});
            }
            PowerGroup &group = power_groups_[static_cast<std::size_t>(group_of[term.parameter])];
            group.base = std::min(group.base, std::fabs(term.coefficient));
            scalings_.back().group = static_cast<int>(group_of[term.parameter]);
        }
        for (std::size_t d = 0; d < scalings.size(); ++d) {
            Scaling &scaling = scalings_[d];
            if (scaling.group < 0) continue;
            PowerGroup &group = power_groups_[static_cast<std::size_t>(scaling.group)];
            const double c = terms[scalings[d].first].coefficient, k = c / group.base;
            if (k != std::nearbyint(k) || std::fabs(k) > kMaxMultiple || k * group.base != c) {
                scaling.group = -1;
                continue;
            }
            scaling.multiple = static_cast<int>(k);
            group.largest = std::max(group.largest, std::abs(scaling.multiple));
        }
        powers_.assign(power_groups_.size() * (2 * kMaxMultiple + 1), Exponential{0.0, 0.0});
        scaled_values_.resize(scalings_.size());
        lanes_ = depth_ <= 1 ? 1 : depth_ <= 2 ? 2 : depth_ <= 4 ? 4 : depth_ <= 8 ? 8 : depth_;
        for (std::size_t k = 0; k < lanes_; ++k) inverse_.push_back(reciprocal(static_cast<int>(k + 1)));
        coefficients_.resize(nodes_.size() * lanes_);
        accumulator_.resize(lanes_);
        positions = series;
        positions.insert(positions.end(), scalings.begin(), scalings.end());
    }
    for (std::uint32_t j = 0; j < positions.size(); ++j) {
        first_terms_.push_back(terms[positions[j].first]);
        for (std::size_t q = positions[j].first + 1; q < positions[j].end; ++q)
            further_terms_.push_back({j, terms[q].parameter, terms[q].coefficient});
    }
    // Per parameter, the widest of its coefficients that a shortened s_p
    // still multiplies exactly.
    for (const SparseTerm &term : terms) {
        if (shortening_.size() <= term.parameter) shortening_.resize(term.parameter + 1, 0);
        shortening_[term.parameter] = std::max(shortening_[term.parameter], shortening_bits(term.coefficient));
    }
    times_.resize(shortening_.size());
    scaled_.resize(positions.size());
    increment_.resize(moved_.size());
    shear_ = path_ == ExpmPath::Nilpotent && depth_ == 1 && further_terms_.empty();
    single_shear_ = shear_ && nodes_.size() == 1 && first_terms_.size() == 1;
    // A rotation: t A = [[0, b], [-b, 0]] with b = c s_p, one term a position.
    rotation_ = path_ == ExpmPath::Plane && moved_.size() == 2 && first_terms_.size() == 2 &&
                further_terms_.empty() && block_[0].row != block_[0].col &&
                block_[1].row != block_[1].col &&
                first_terms_[0].parameter == first_terms_[1].parameter &&
                first_terms_[1].coefficient == -first_terms_[0].coefficient;
    if (rotation_) {
        // b is the entry at (0, 1) of the block.
        const std::size_t upper = block_[0].row == 0 ? 0 : 1;
        rotation_parameter_ = first_terms_[upper].parameter;
        rotation_coefficient_ = first_terms_[upper].coefficient;
    }
}

// z e^a where e^a overflows or is subnormal: 0 for z = 0 (the exact flow of
// 0), else m e^r 2^(k + e) with z = m 2^e (m in [1/2, 1): a subnormal z
// loses nothing before the one rounding, in ldexp) and a = k ln 2 + r,
// |r| <= ln 2 / 2, ln 2 in Cody and Waite's two parts (k ln2_hi is exact for
// the |k| < 2^21 reached here), so a tiny z scaled past e^709, or a huge one
// past e^-708, is the double nearest its product. Beyond |a| = 1500 no
// nonzero double z gives a finite nonzero product: an overflow, or 0.
double scaled_beyond_range(double z, double a) {
    if (a != a) return z + a;  // NaN, as z e^NaN (no integer exponent of it)
    if (z == 0.0) return z;
    if (a > 1500.0) return z * std::numeric_limits<double>::infinity();
    if (a < -1500.0) return z * 0.0;
    constexpr double kInverseLn2 = 1.4426950408889634, kLn2High = 6.93147180369123816490e-01,
                     kLn2Low = 1.90821492927058770002e-10;
    const double k = std::nearbyint(a * kInverseLn2);
    const double r = (a - k * kLn2High) - k * kLn2Low;
    int exponent = 0;
    const double m = std::frexp(z, &exponent);
    return std::ldexp(m * std::exp(r), static_cast<int>(k) + exponent);
}

void fail_flow_overflow(std::size_t component) {
    fail(LPI_ERR_NONFINITE, "the exact flow overflows (component " + std::to_string(component) + ")");
}

void SparseExponential::fail_nonfinite() const {
    std::size_t v = 0;
    while (v + 1 < moved_.size() && std::isfinite(increment_[v])) ++v;
    fail_flow_overflow(moved_[v]);
}

void SparseExponential::check_norm(double norm, double t) const {
    // Each squaring doubles the relative error of the computed exponential
    // (for a rotation: its departure from orthogonality, which the Casimirs
    // see), so beyond kMaxSquarings the flow is refused rather than returned
    // with a Casimir error above about 2^kMaxSquarings unit round-offs.
    if (!std::isfinite(norm))
        fail(LPI_ERR_NONFINITE, "the matrix t A of the exact flow overflows (t = " +
                                    number_text(t) + ")");
    if (norm > std::ldexp(kPadeTheta13, kMaxSquarings)) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "the step is too large for the exact flow: ||t A||_1 = %.3g needs more "
                      "than 2^%d squarings in the matrix exponential; reduce dt",
                      norm, kMaxSquarings);
        fail(LPI_ERR_INVALID, text);
    }
}

void SparseExponential::widen_shortening(const std::vector<int> &bits) {
    if (shortening_.size() < bits.size()) shortening_.resize(bits.size(), 0);
    for (std::size_t p = 0; p < bits.size(); ++p) shortening_[p] = std::max(shortening_[p], bits[p]);
    times_.resize(shortening_.size());
}

void SparseExponential::shorten_times(const double *g, double t) {
    for (std::size_t p = 0; p < times_.size(); ++p) times_[p] = shortened(t * g[p], shortening_[p]);
}

// Exact products c s_p where one term makes a position (the usual case); the
// sum of several rounds.
void SparseExponential::scale_entries() {
    const SparseTerm *first = first_terms_.data();
    const double *s = times_.data();
    double *scaled = scaled_.data();
    for (std::size_t j = 0; j < first_terms_.size(); ++j) scaled[j] = first[j].coefficient * s[first[j].parameter];
    for (const Term &q : further_terms_) scaled[q.position] += q.coefficient * s[q.parameter];
}

// One pass over the nodes in topological order, each node's Taylor
// coefficients from those of the nodes it reads: c_v[k] for all k at once,
// in `Lanes` lanes that the compiler unrolls (0: lanes_ at run time).
// Lanes beyond a node's level hold exact zeros. A node's component is read
// (into c_v[0]) before it is written, and written as x + increment, rounded
// once. Returns false, x restored, when a new value is not finite.
template <std::size_t Lanes>
bool SparseExponential::sweep(double *x) {
    const std::size_t lanes = Lanes ? Lanes : lanes_;
    double fixed_width[Lanes ? Lanes : 1];
    double *acc = Lanes ? fixed_width : accumulator_.data();
    const double *a = scaled_.data();
    const std::uint32_t *column = columns_.data();
    const Reciprocal *inverse = inverse_.data();
    double *coefficients = coefficients_.data();
    bool finite = true;
    for (std::size_t v = 0; v < nodes_.size(); ++v) {
        const SeriesNode &node = nodes_[v];
        for (std::size_t k = 0; k < lanes; ++k) acc[k] = 0.0;
        for (std::uint32_t i = 0; i < node.fixed_columns; ++i, ++a, ++column)
            acc[0] += *a * x[*column];
        for (std::uint32_t i = 0; i < node.moved_columns; ++i, ++a, ++column) {
            const double *c = coefficients + static_cast<std::size_t>(*column) * lanes;
            for (std::size_t k = 0; k < lanes; ++k) acc[k] += *a * c[k];
        }
        // c_v[k + 1] = acc[k] / (k + 1); the increment sums them in order of k.
        double *own = coefficients + v * lanes;
        own[0] = x[node.global];
        double total = 0.0;
        for (std::size_t k = 0; k < lanes; ++k) {
            const double term = divided(acc[k], k + 1, inverse[k]);
            total += term;
            if (k + 1 < lanes) own[k + 1] = term;
        }
        // The new value, checked itself: x + a finite increment may overflow.
        const double next = own[0] + total;
        increment_[v] = next;  // only to name a non-finite component
        finite &= std::isfinite(next);
        x[node.global] = next;
    }
    if (finite) return true;
    for (std::size_t v = 0; v < nodes_.size(); ++v) x[nodes_[v].global] = coefficients[v * lanes];
    return false;
}

// Depth 1 (every moved index reads fixed ones only: a shear, as the kick of
// a pendulum): x_v += sum_j (t A)_vj x_j, the entries formed as read, one
// term a position. The same sums, in the same order, as sweep<1>.
inline bool SparseExponential::shear(double *x) {
    const SparseTerm *term = first_terms_.data();
    const std::uint32_t *column = columns_.data();
    const double *s = times_.data();
    bool finite = true;
    for (std::size_t v = 0; v < nodes_.size(); ++v) {
        double sum = 0.0;
        for (std::uint32_t i = 0; i < nodes_[v].fixed_columns; ++i, ++term, ++column)
            sum += (term->coefficient * s[term->parameter]) * x[*column];
        increment_[v] = x[nodes_[v].global] + sum;  // the new value, written once all are finite
        finite &= std::isfinite(increment_[v]);
    }
    if (!finite) return false;
    for (std::size_t v = 0; v < nodes_.size(); ++v) x[nodes_[v].global] = increment_[v];
    return true;
}

// About 15 instructions where shorten_times and shear() took about 80
// (callgrind): e(2)'s kick went from 2.6x the pendulum's hand-written kick to
// 1.45x (bench_piece_flows).
inline bool SparseExponential::single_shear(const double *g, double t, double *x) {
    const SparseTerm &term = first_terms_[0];
    const double s = shortened(t * g[term.parameter], shortening_[term.parameter]);
    const std::uint32_t v = nodes_[0].global;
    const double next = x[v] + (0.0 + (term.coefficient * s) * x[columns_[0]]);
    increment_[0] = next;
    if (!std::isfinite(next)) return false;
    x[v] = next;
    return true;
}

void SparseExponential::apply(const double *g, double t, double *x) {
    if (single_shear_) {
        if (!single_shear(g, t, x)) fail_nonfinite();
        return;
    }
    shorten_times(g, t);
    if (shear_) {
        if (!shear(x)) fail_nonfinite();
        return;
    }
    if (rotation_ && rotate(t, x)) return;
    scale_entries();
    switch (path_) {
        case ExpmPath::Plane: apply_plane(t, x); return;
        case ExpmPath::Pade: apply_pade(t, x); return;
        case ExpmPath::EllipticSeries: apply_elliptic(t, x); return;
        case ExpmPath::Nilpotent:
            if (!sweep(x)) fail_nonfinite();
            return;
        case ExpmPath::DiagonalSeries:
            if (!sweep(x)) fail_nonfinite();
            apply_scalings(x);
            return;
    }
}

bool SparseExponential::sweep(double *x) {
    switch (lanes_) {
        case 1: return sweep<1>(x);
        case 2: return sweep<2>(x);
        case 4: return sweep<4>(x);
        case 8: return sweep<8>(x);
        default: return sweep<0>(x);
    }
}

// x_i <- exp(d_i) x_i after the series of N, one expm1 for each run of
// equal diagonal terms (exponential_powers, scaled_by_exponential). When a
// result is not finite, x goes back to what it was before the series too.
void SparseExponential::apply_scalings(double *x) {
#if LPI_FMA_DISPATCH
    if (cpu_has_fma()) return scale_fma(x);
#endif
    scale_baseline(x);
}

void SparseExponential::scale_baseline(double *x) { scale(x); }
#if LPI_FMA_DISPATCH
void SparseExponential::scale_fma(double *x) { scale(x); }
#endif

inline void SparseExponential::scale(double *x) {
    // Group by group: M_k = exp(k s) for s = base s_p, exact (the cut of
    // s_p covers base). From t (base g_p) instead, the diagonal ran for
    // another time than the series of the same parameter, up to 2^-45 of it
    // apart: no flow of the algebra (a Casimir moved 1e-14 a flow, always
    // the same way, with M = [[a, 1, 0], [0, a, 0], [0, 0, 2a]], a = 255/128).
    for (std::size_t q = 0; q < power_groups_.size(); ++q) {
        const PowerGroup &group = power_groups_[q];
        Exponential *M = powers_.data() + q * (2 * kMaxMultiple + 1) + kMaxMultiple;
        exponential_powers(group.base * times_[group.parameter], group.largest, M);
    }
    std::size_t failed = scalings_.size();
    for (std::size_t d = 0; d < scalings_.size(); ++d) {
        const Scaling &scaling = scalings_[d];
        Exponential factor;
        double exponent;
        if (scaling.group < 0) {
            exponent = scaled_[scaling.position];
            factor = exponential_of(exponent);
        } else {
            const PowerGroup &group = power_groups_[static_cast<std::size_t>(scaling.group)];
            exponent = scaling.multiple * (group.base * times_[group.parameter]);
            factor = powers_[static_cast<std::size_t>(scaling.group * (2 * kMaxMultiple + 1) +
                                                      kMaxMultiple + scaling.multiple)];
        }
        scaled_values_[d] = scaled_by_exponential(x[scaling.global], factor, exponent);
        if (failed == scalings_.size() && !std::isfinite(scaled_values_[d])) failed = d;
    }
    if (failed < scalings_.size()) {
        for (std::size_t v = 0; v < nodes_.size(); ++v) x[nodes_[v].global] = coefficients_[v * lanes_];
        fail_flow_overflow(scalings_[failed].global);
    }
    for (std::size_t d = 0; d < scalings_.size(); ++d) x[scalings_[d].global] = scaled_values_[d];
}

// exp(A) of a traceless A with complex eigenvalues (a rotation of so(3) or
// e(2), an elliptic flow of sl(2)): M = [[m00, m01], [m10, m11]], det M = 1,
// as three shears, M = U(a) L(m10) U(c) with U(a) = [[1, a], [0, 1]], L the
// lower one, a = (m00 - 1) / m10, c = (m11 - 1) / m10. Formed as x + (M - I)
// x from a rounded M, the map's determinant was off 1 by the same amount in
// every flow whose angle is the same (a linear Hamiltonian: a spin in a
// field), and the Casimir drifted with one sign (so(3), H = x1, t = 0.7: 59
// standard errors over 6e4 random states). Shears keep the determinant 1
// whatever their rounded coefficients: what is left is a symmetric traceless
// error, which averages out over the directions of x. Past a quarter turn
// (m00 + m11 < 0) the shears of -M are applied and x negated. A rotation
// [[0, b], [-b, 0]] takes a = c = tan(b / 2) (or -cot(b / 2)) and m10 = -sin b
// from the half angle's sine and cosine.
SparseExponential::Shears SparseExponential::rotation_shears(double b) {
    const double sine = std::sin(0.5 * b), cosine = std::cos(0.5 * b);
    const bool turned = std::fabs(cosine) < std::fabs(sine);
    const double outer = turned ? -cosine / sine : sine / cosine;
    return {outer, turned ? 2.0 * sine * cosine : -2.0 * sine * cosine, outer, turned};
}

SparseExponential::Shears SparseExponential::elliptic_shears(const double A[4]) {
    if (A[0] == 0.0 && A[2] == -A[1]) return rotation_shears(A[1]);
    // M = C I + S N, N = [[p, b], [c, -p]], N^2 = -r^2 I, C = cos r, S =
    // sin r / r, in half angles h = r / 2 (no difference of nearly equal
    // values, where (2 + m00 - 1) / m10, near a half turn, had lost every
    // digit: 3.8e-2 wrong at r = pi): (m00 - 1) / m10 = (p cos h - r sin
    // h) / (c cos h) and, for -M, (m00 + 1) / m10 = (r cos h + p sin h) /
    // (c sin h); m10 = 2 sin h cos h c / r.
    const double p = A[0], c = A[2], r = std::sqrt(-(p * p + A[1] * c));
    const double sine = std::sin(0.5 * r), cosine = std::cos(0.5 * r);
    const bool turned = std::fabs(cosine) < std::fabs(sine);
    return {turned ? (r * cosine + p * sine) / (c * sine) : (p * cosine - r * sine) / (c * cosine),
            (turned ? -2.0 : 2.0) * sine * cosine * c / r,
            turned ? (r * cosine - p * sine) / (c * sine) : (-p * cosine - r * sine) / (c * cosine),
            turned};
}

void SparseExponential::apply_shears(const Shears &M, double x0, double x1, double *x) {
    double y0 = x0 + M.last * x1;
    const double y1 = x1 + M.lower * y0;
    y0 = y0 + M.first * y1;
    const double z0 = M.turned ? -y0 : y0, z1 = M.turned ? -y1 : y1;
    increment_[0] = z0 - x0;  // only to name a non-finite component
    increment_[1] = z1 - x1;
    if (!std::isfinite(z0) || !std::isfinite(z1)) fail_nonfinite();
    x[moved_[0]] = z0;
    x[moved_[1]] = z1;
}

// The rotation's flow without forming t A: the operations apply_plane takes
// for it (the same bits), in less than half its instructions. false, nothing
// done, where b^2 underflows (apply_plane's delta is then 0, not < 0, and it
// takes another path).
bool SparseExponential::rotate(double t, double *x) {
    const double b = rotation_coefficient_ * times_[rotation_parameter_];
    if (!(b * b > 0.0)) return false;
    check_norm(std::fabs(b), t);
    apply_shears(rotation_shears(b), x[moved_[0]], x[moved_[1]], x);
    return true;
}

void SparseExponential::apply_plane(double t, double *x) {
    double A[4] = {0.0, 0.0, 0.0, 0.0};
    for (std::size_t j = 0; j < block_.size(); ++j) A[block_[j].row * 2 + block_[j].col] = scaled_[j];
    check_norm(std::max(std::fabs(A[0]) + std::fabs(A[2]), std::fabs(A[1]) + std::fabs(A[3])), t);
    const double x0 = x[moved_[0]];
    if (moved_.size() == 1) {  // x0 e^a, as the diagonal scalings take it
        const double y0 = scaled_by_exponential(x0, exponential_of(A[0]), A[0]);
        increment_[0] = y0 - x0;  // only to name a non-finite component
        if (!std::isfinite(y0)) fail_nonfinite();
        x[moved_[0]] = y0;
        return;
    }
    const double x1 = x[moved_[1]];
    const double tau = 0.5 * (A[0] + A[3]), p = 0.5 * (A[0] - A[3]);
    const double delta = p * p + A[1] * A[2];
    if (tau == 0.0 && delta < 0.0) {
        apply_shears(elliptic_shears(A), x0, x1, x);
        return;
    }
    const bool apart = delta > 0.0 && std::sqrt(delta) > kIncrementFormLimit;
    if (!apart && tau >= -kIncrementFormLimit) {
        double W[4];
        plane_expm1(A[0], A[1], A[2], A[3], W);
        // x += (exp(tA) - I) x, rounded once.
        const double y0 = x0 + (W[0] * x0 + W[1] * x1), y1 = x1 + (W[2] * x0 + W[3] * x1);
        if (std::isfinite(y0) && std::isfinite(y1)) {
            x[moved_[0]] = y0;
            x[moved_[1]] = y1;
            return;
        }
        // Not representable this way: W holds e^tau, which may overflow
        // (tau near ln DBL_MAX) where the flow of a small x does not. Below,
        // e^tau is applied last; a flow that does overflow is refused there.
    }
    double y0 = x0, y1 = x1;
    if (apart) {
        plane_hyperbolic_apply(A[0], A[1], A[2], A[3], y0, y1);
    } else {  // e^tau (C x + S N x), C and S as plane_expm1 forms them
        double W[4];
        plane_expm1(A[0] - tau, A[1], A[2], A[3] - tau, W);  // traceless: C - 1 +- S p, S b, S c
        y0 = times_exponential((x0 + W[0] * x0) + W[1] * x1, tau);
        y1 = times_exponential(W[2] * x0 + (x1 + W[3] * x1), tau);
    }
    increment_[0] = y0 - x0;  // only to name a non-finite component
    increment_[1] = y1 - x1;
    if (!std::isfinite(y0) || !std::isfinite(y1)) fail_nonfinite();
    x[moved_[0]] = y0;
    x[moved_[1]] = y1;
}

void SparseExponential::apply_pade(double t, double *x) {
    const std::size_t m = moved_.size();
    dense_.assign(square_entries(m, "exponential's matrix"), 0.0);
    for (std::size_t j = 0; j < block_.size(); ++j) dense_[block_[j].row * m + block_[j].col] = scaled_[j];
    check_norm(dense_norm1(m, dense_.data()), t);
    exp_.resize(dense_.size());
    expm1_dense(m, dense_.data(), exp_.data(), pade_scratch_);
    // x += (exp(tA) - I) x: the increment carries its own small rounding
    // errors, and x is rounded once (as on the other paths). A row whose
    // diagonal contracts by more than half (exp - 1 below -1/2) takes exp(tA)
    // itself instead, as the scalings do: x + increment would keep of a
    // contracted component only the accuracy of x (scaling and squaring
    // keeps a triangular block's diagonal to its relative accuracy, in the
    // block upper triangular order of driven_first). x is
    // left untouched when the exact flow is not representable.
    // An index that is a component of its own (driven_first) has e^(tA_rr)
    // as its diagonal entry of exp(tA), exactly: taken from expm1 and exp
    // themselves, not from 2^s squarings, each of which doubled its error.
    for (std::size_t r = 0; r < m; ++r)
        if (alone_[r]) exp_[r * m + r] = std::expm1(dense_[r * m + r]);
    bool contracted = false;
    for (std::size_t r = 0; r < m; ++r) contracted |= exp_[r * m + r] < -0.5;
    if (contracted) {
        direct_.resize(dense_.size());
        expm_dense(m, dense_.data(), direct_.data(), pade_scratch_);
        for (std::size_t r = 0; r < m; ++r)
            if (alone_[r]) direct_[r * m + r] = std::exp(dense_[r * m + r]);
    }
    scaled_values_.resize(m);
    bool finite = true;
    for (std::size_t r = 0; r < m; ++r) {
        const bool direct = exp_[r * m + r] < -0.5;
        const double *row = (direct ? direct_.data() : exp_.data()) + r * m;
        double s = 0.0;
        for (std::size_t c = 0; c < m; ++c) s += row[c] * x[moved_[c]];
        scaled_values_[r] = direct ? s : x[moved_[r]] + s;
        increment_[r] = scaled_values_[r];  // only to name a non-finite component
        finite &= std::isfinite(scaled_values_[r]);
    }
    if (!finite) fail_nonfinite();
    for (std::size_t r = 0; r < m; ++r) x[moved_[r]] = scaled_values_[r];
}

// exp(s C) x for a block whose flows are all bounded (elliptic_block), on
// the vector itself, as the nilpotent sweep: every rounding is of a value
// that depends on the state. The Pade path rounds exp(t A) once a flow, a
// constant wherever g is (a linear piece), and the Casimirs moved with one
// sign (su(3), H = 0.7 x0, one flow of 1: -3.65e-17 of their terms, 81
// standard errors over 2e4 random states; so(3) in a dense basis, 158).
// Here 2^j substeps h = s 2^-j (exact: still a flow of the algebra, and c h
// exact wherever c s is) with ||h C||_1 <= 1/2, each the series sum_k
// (h C)^k x / k! to the term that leaves a remainder below 2^-70 of x (the
// truncation is a constant map too: it must be far below round-off), the
// 1/k as hi + lo (divided), the increment summed from its smallest terms
// and added to x once: x + increment, one rounding a substep.
void SparseExponential::apply_elliptic(double t, double *x) {
    const double s = times_[elliptic_parameter_];
    double norm = std::fabs(s) * elliptic_norm_;  // ||t A||_1
    check_norm(norm, t);
    // Halvings until |h| rate <= 1/2 (rate >= ||C^k||^(1/k), k >= 2).
    int halvings = 0;
    double h = std::fabs(s);
    while (h * elliptic_rate_ > 0.5 && halvings <= kMaxEllipticHalvings) h *= 0.5, ++halvings;
    if (halvings > kMaxEllipticHalvings) return apply_pade(t, x);
    // Terms k = 1..K: ||(h C)^k / k!||_1 <= b_k = |h|^k ||C^k||_1 / k!, K
    // the first with b_(K+1) + .. + b_(kMaxEllipticTerms+1) below 2^-70 (the
    // terms beyond, below (1/2)^k / k!, add less than 1e-35).
    double bounds[kMaxEllipticTerms + 2], power = 1.0;
    for (int k = 1; k <= kMaxEllipticTerms + 1; ++k)
        power *= h / k, bounds[k] = power * elliptic_power_norms_[static_cast<std::size_t>(k - 1)];
    int K = kMaxEllipticTerms;
    for (double rest = bounds[K + 1]; K > 0 && rest + bounds[K] <= 0x1p-70;) rest += bounds[K], --K;
    const std::size_t m = moved_.size();
    for (std::size_t j = 0; j < scaled_.size(); ++j) elliptic_entries_[j] = std::ldexp(scaled_[j], -halvings);
    double *terms = elliptic_terms_.data();
    for (std::size_t r = 0; r < m; ++r) terms[r] = x[moved_[r]];
    const double *a = elliptic_entries_.data();
    const std::uint32_t *position = elliptic_positions_.data(), *row = elliptic_rows_.data();
    for (int step = 0; step < (1 << halvings); ++step) {
        for (int k = 1; k <= K; ++k) {
            const double *previous = terms + static_cast<std::size_t>(k - 1) * m;
            double *next = terms + static_cast<std::size_t>(k) * m;
            for (std::size_t r = 0; r < m; ++r) {
                double acc = 0.0;
                for (std::uint32_t q = row[r]; q < row[r + 1]; ++q)
                    acc += a[position[q]] * previous[block_[position[q]].col];
                next[r] = divided(acc, static_cast<std::size_t>(k), inverse_[static_cast<std::size_t>(k - 1)]);
            }
        }
        for (std::size_t r = 0; r < m; ++r) {
            double increment = 0.0;
            for (int k = K; k >= 1; --k) increment += terms[static_cast<std::size_t>(k) * m + r];
            terms[r] = terms[r] + increment;
        }
    }
    bool finite = true;
    for (std::size_t r = 0; r < m; ++r) finite &= std::isfinite(terms[r]);
    // A term of a state near DBL_MAX may overflow (||h C||_1 may exceed 1:
    // the substeps follow the powers' rate) where the flow itself does not:
    // Pade then takes the flow from x, still untouched, or names what overflows.
    if (!finite) return apply_pade(t, x);
    for (std::size_t r = 0; r < m; ++r) x[moved_[r]] = terms[r];
}

}  // namespace lpi
