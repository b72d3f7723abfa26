#include "expm.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <tuple>

#include "../core/error.hpp"

namespace lpi {

namespace {

// C = A B.
void multiply(std::size_t n, const double *A, const double *B, double *C) {
    std::fill(C, C + n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 0; k < n; ++k) {
            const double a = A[i * n + k];
            if (a == 0.0) continue;
            for (std::size_t j = 0; j < n; ++j) C[i * n + j] += a * B[k * n + j];
        }
}

double norm1(std::size_t n, const double *A) {
    double best = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        double s = 0.0;
        for (std::size_t i = 0; i < n; ++i) s += std::fabs(A[i * n + j]);
        best = std::max(best, s);
    }
    return best;
}

// Solves Q X = B in place (B becomes X) by LU with partial pivoting. Q is
// overwritten. Q = q_m(A) is well conditioned for ||A||_1 <= theta_m
// (Higham 2005, section 2), so no refinement is needed.
void solve(std::size_t n, double *Q, double *B) {
    for (std::size_t c = 0; c < n; ++c) {
        std::size_t pivot = c;
        for (std::size_t r = c + 1; r < n; ++r)
            if (std::fabs(Q[r * n + c]) > std::fabs(Q[pivot * n + c])) pivot = r;
        if (Q[pivot * n + c] == 0.0)
            fail(LPI_ERR_INTERNAL, "singular Pade denominator in the matrix exponential");
        if (pivot != c) {
            std::swap_ranges(Q + c * n, Q + (c + 1) * n, Q + pivot * n);
            std::swap_ranges(B + c * n, B + (c + 1) * n, B + pivot * n);
        }
        for (std::size_t r = c + 1; r < n; ++r) {
            const double f = Q[r * n + c] / Q[c * n + c];
            if (f == 0.0) continue;
            for (std::size_t j = c; j < n; ++j) Q[r * n + j] -= f * Q[c * n + j];
            for (std::size_t j = 0; j < n; ++j) B[r * n + j] -= f * B[c * n + j];
        }
    }
    for (std::size_t c = n; c-- > 0;) {
        for (std::size_t j = 0; j < n; ++j) {
            double s = B[c * n + j];
            for (std::size_t k = c + 1; k < n; ++k) s -= Q[c * n + k] * B[k * n + j];
            B[c * n + j] = s / Q[c * n + c];
        }
    }
}

// Coefficients b_0..b_m of the [m/m] Pade approximant of e^x,
// b_k = (2m-k)! m! / ((2m)! k! (m-k)!), from the ratio of consecutive terms
// (the common scaling does not matter: r_m = q_m^{-1} p_m). Computed once.
const double *pade_coefficients(int m) {
    static const auto table = [] {
        std::array<std::array<double, 14>, 14> b{};
        for (int degree = 1; degree <= 13; ++degree) {
            long double c = 1.0L;
            for (int k = 0; k <= degree; ++k) {
                b[degree][k] = static_cast<double>(c);
                c = c * (degree - k) / ((2.0L * degree - k) * (k + 1));
            }
        }
        return b;
    }();
    return table[m].data();
}

// theta_m of Higham 2005, Table 2.3: the largest ||A||_1 for which the
// degree-m approximant has backward error below the unit round-off.
struct Degree {
    int m;
    double theta;
};
constexpr Degree kDegrees[] = {{3, 1.495585217958292e-2},
                               {5, 2.539398330063230e-1},
                               {7, 9.504178996162932e-1},
                               {9, 2.097847961257068e0},
                               {13, 5.371920351148152e0}};

// Scratch matrices of the Pade evaluation, carved from one buffer that is
// kept between calls (a flow allocates nothing once warm).
struct PadeScratch {
    double *U, *V, *Q, *A2, *A4, *A6, *inner, *tmp;
    PadeScratch(std::size_t n, std::vector<double> &buffer) {
        const std::size_t nn = n * n;
        buffer.resize(8 * nn);
        double *next = buffer.data();
        for (double **m : {&U, &V, &Q, &A2, &A4, &A6, &inner, &tmp}) {
            *m = next;
            next += nn;
        }
    }
};

// U and V of r_m = (V - U)^{-1} (V + U) for m <= 9 (p_m = V + U, q_m = V - U).
void pade_low(std::size_t n, const double *A, int m, PadeScratch &s) {
    const double *b = pade_coefficients(m);
    const std::size_t nn = n * n;
    double *power = s.A4, *odd = s.A6;
    std::fill(power, power + nn, 0.0);
    for (std::size_t i = 0; i < n; ++i) power[i * n + i] = 1.0;  // A^0
    std::fill(odd, odd + nn, 0.0);
    multiply(n, A, A, s.A2);
    std::fill(s.V, s.V + nn, 0.0);
    for (int k = 0; k <= m; k += 2) {  // even powers A^k feed V and (times A) U
        for (std::size_t e = 0; e < nn; ++e) {
            s.V[e] += b[k] * power[e];
            odd[e] += b[k + 1] * power[e];
        }
        if (k + 2 <= m) {
            multiply(n, power, s.A2, s.tmp);
            std::swap(power, s.tmp);
        }
    }
    multiply(n, A, odd, s.U);
}

// The degree-13 evaluation of Higham 2005, eq. (2.11): six products.
void pade13(std::size_t n, const double *A, PadeScratch &s) {
    const double *b = pade_coefficients(13);
    const std::size_t nn = n * n;
    multiply(n, A, A, s.A2);
    multiply(n, s.A2, s.A2, s.A4);
    multiply(n, s.A4, s.A2, s.A6);
    for (std::size_t e = 0; e < nn; ++e)
        s.inner[e] = b[13] * s.A6[e] + b[11] * s.A4[e] + b[9] * s.A2[e];
    multiply(n, s.A6, s.inner, s.tmp);
    for (std::size_t e = 0; e < nn; ++e)
        s.tmp[e] += b[7] * s.A6[e] + b[5] * s.A4[e] + b[3] * s.A2[e];
    for (std::size_t i = 0; i < n; ++i) s.tmp[i * n + i] += b[1];
    multiply(n, A, s.tmp, s.U);
    for (std::size_t e = 0; e < nn; ++e)
        s.inner[e] = b[12] * s.A6[e] + b[10] * s.A4[e] + b[8] * s.A2[e];
    multiply(n, s.A6, s.inner, s.V);
    for (std::size_t e = 0; e < nn; ++e) s.V[e] += b[6] * s.A6[e] + b[4] * s.A4[e] + b[2] * s.A2[e];
    for (std::size_t i = 0; i < n; ++i) s.V[i * n + i] += b[0];
}

// s.U, s.V of the Pade approximant chosen for A (Higham 2005, Algorithm 2.3)
// and the number of squarings: exp(A) ~ r(A / 2^s)^(2^s),
// r = (V - U)^{-1} (V + U). Returns false for a non-finite A.
bool pade_terms(std::size_t n, const double *A, PadeScratch &s, int &squarings) {
    const double norm = norm1(n, A);
    if (!std::isfinite(norm)) return false;
    squarings = 0;
    for (const Degree &d : kDegrees) {
        if (d.m < 13 && norm <= d.theta) {
            pade_low(n, A, d.m, s);
            return true;
        }
    }
    // Scale A by 2^-s so that ||A / 2^s||_1 <= theta_13 (exact: a power of 2).
    if (norm > kDegrees[4].theta)
        squarings = std::max(0, static_cast<int>(std::ceil(std::log2(norm / kDegrees[4].theta))));
    double *scaled = s.Q;  // free until the solve
    for (std::size_t e = 0; e < n * n; ++e) scaled[e] = std::ldexp(A[e], -squarings);
    pade13(n, scaled, s);
    return true;
}

// W = exp(A) - I (see expm1_dense) with the scratch kept in `buffer`.
void expm1_with(std::size_t n, const double *A, double *W, std::vector<double> &buffer) {
    if (n == 0) return;
    const std::size_t nn = n * n;
    PadeScratch s(n, buffer);
    int squarings = 0;
    if (!pade_terms(n, A, s, squarings)) {
        std::fill(W, W + nn, std::numeric_limits<double>::quiet_NaN());
        return;
    }
    // r - I = (V - U)^{-1} (V + U) - I = (V - U)^{-1} (2U): no cancellation, so
    // the result is accurate relative to ||A|| even when exp(A) is close to I.
    for (std::size_t e = 0; e < nn; ++e) {
        s.Q[e] = s.V[e] - s.U[e];
        W[e] = 2.0 * s.U[e];
    }
    solve(n, s.Q, W);
    // (I + W)^2 - I = W W + 2 W.
    for (int k = 0; k < squarings; ++k) {
        multiply(n, W, W, s.Q);
        for (std::size_t e = 0; e < nn; ++e) W[e] = s.Q[e] + 2.0 * W[e];
    }
}

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

}  // namespace

void expm_dense(std::size_t n, const double *A, double *E) {
    if (n == 0) return;
    const std::size_t nn = n * n;
    std::vector<double> buffer;
    PadeScratch s(n, buffer);
    int squarings = 0;
    if (!pade_terms(n, A, s, squarings)) {
        std::fill(E, E + nn, std::numeric_limits<double>::quiet_NaN());
        return;
    }
    for (std::size_t e = 0; e < nn; ++e) {
        s.Q[e] = s.V[e] - s.U[e];
        E[e] = s.V[e] + s.U[e];
    }
    solve(n, s.Q, E);
    for (int k = 0; k < squarings; ++k) {
        multiply(n, E, E, s.Q);
        std::copy(s.Q, s.Q + nn, E);
    }
}

void expm1_dense(std::size_t n, const double *A, double *W) {
    std::vector<double> buffer;
    expm1_with(n, A, W, buffer);
}

std::size_t square_entries(std::size_t n, const char *what) {
    if (n != 0 && n > std::numeric_limits<std::size_t>::max() / sizeof(double) / n)
        fail(LPI_ERR_NO_MEMORY, std::string("the ") + what + " of " + std::to_string(n) + " x " +
                                    std::to_string(n) + " doubles is larger than memory can "
                                    "address");
    return n * n;
}

// ---- sparse exponentials of a fixed pattern -----------------------------------

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

    // Levels by Kahn's algorithm on edges col -> row (x_col drives x_row):
    // level[v] is the longest path ending at v. A cycle (a self-loop
    // included) means the pattern does not force nilpotency.
    std::vector<std::size_t> start(m + 1, 0), cursor;
    std::vector<std::uint32_t> indegree(m, 0), adjacency(positions.size()), queue;
    for (const Position &e : positions) {
        ++start[e.col + 1];
        ++indegree[e.row];
    }
    for (std::size_t v = 0; v < m; ++v) start[v + 1] += start[v];
    cursor.assign(start.begin(), start.end() - 1);
    for (const Position &e : positions) adjacency[cursor[e.col]++] = e.row;
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

    if (queue.size() != m) {
        path_ = m <= 2 ? ExpmPath::Plane : ExpmPath::Pade;
        moved_ = std::move(touched);
        for (const Position &e : positions) block_.push_back({e.row, e.col});
    } else {
        // Nilpotent: the moved indices (level >= 1) by level are in
        // topological order; each position goes with the node of its row.
        path_ = ExpmPath::Nilpotent;
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
        auto fixed = [&](const Position &e) { return level[e.col] == 0; };
        std::stable_sort(positions.begin(), positions.end(),
                         [&](const Position &a, const Position &b) {
                             return std::make_pair(node_of[a.row], !fixed(a)) <
                                    std::make_pair(node_of[b.row], !fixed(b));
                         });
        for (const Position &e : positions) {
            SeriesNode &node = nodes_[node_of[e.row]];
            ++(fixed(e) ? node.fixed_columns : node.moved_columns);
            columns_.push_back(fixed(e) ? touched[e.col] : node_of[e.col]);
        }
        lanes_ = depth_ <= 1 ? 1 : depth_ <= 2 ? 2 : depth_ <= 4 ? 4 : depth_ <= 8 ? 8 : depth_;
        for (std::size_t k = 0; k < lanes_; ++k) inverse_.push_back(1.0 / static_cast<double>(k + 1));
        coefficients_.resize(nodes_.size() * lanes_);
        accumulator_.resize(lanes_);
    }
    for (std::uint32_t j = 0; j < positions.size(); ++j) {
        first_terms_.push_back(terms[positions[j].first]);
        for (std::size_t q = positions[j].first + 1; q < positions[j].end; ++q)
            further_terms_.push_back({j, terms[q].parameter, terms[q].coefficient});
    }
    scaled_.resize(positions.size());
    increment_.resize(moved_.size());
}

void SparseExponential::fail_nonfinite() const {
    std::size_t v = 0;
    while (v + 1 < moved_.size() && std::isfinite(increment_[v])) ++v;
    fail(LPI_ERR_NONFINITE, "the exact flow overflows (component " + std::to_string(moved_[v]) + ")");
}

void SparseExponential::check_norm(double norm, double t) const {
    // Each squaring doubles the relative error of the computed exponential
    // (for a rotation: its departure from orthogonality, which the Casimirs
    // see), so beyond kMaxSquarings the flow is refused rather than returned
    // with a Casimir error above about 2^kMaxSquarings unit round-offs.
    if (!std::isfinite(norm))
        fail(LPI_ERR_NONFINITE, "the matrix t A of the exact flow overflows (t = " +
                                    std::to_string(t) + ")");
    if (norm > std::ldexp(kDegrees[4].theta, kMaxSquarings)) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "the step is too large for the exact flow: ||t A||_1 = %.3g needs more "
                      "than 2^%d squarings in the matrix exponential; reduce dt",
                      norm, kMaxSquarings);
        fail(LPI_ERR_INVALID, text);
    }
}

void SparseExponential::scale_entries(const double *g, double t) {
    const SparseTerm *first = first_terms_.data();
    double *scaled = scaled_.data();
    const std::size_t count = first_terms_.size();
    if (further_terms_.empty()) {  // the usual case: one term a position
        for (std::size_t j = 0; j < count; ++j)
            scaled[j] = t * (first[j].coefficient * g[first[j].parameter]);
        return;
    }
    for (std::size_t j = 0; j < count; ++j)
        scaled[j] = first[j].coefficient * g[first[j].parameter];
    for (const Term &q : further_terms_) scaled[q.position] += q.coefficient * g[q.parameter];
    for (std::size_t j = 0; j < count; ++j) scaled[j] *= t;
}

// One pass over the nodes in topological order, each node's Taylor
// coefficients from those of the nodes it reads: c_v[k] for all k at once,
// in `Lanes` lanes that the compiler unrolls (0: lanes_ at run time).
// Lanes beyond a node's level hold exact zeros. A node's component is read
// (into c_v[0]) before it is written, and written as x + increment, rounded
// once. Returns false, x restored, when an increment is not finite.
template <std::size_t Lanes>
bool SparseExponential::sweep(double *x) {
    const std::size_t lanes = Lanes ? Lanes : lanes_;
    double fixed_width[Lanes ? Lanes : 1];
    double *acc = Lanes ? fixed_width : accumulator_.data();
    const double *a = scaled_.data();
    const std::uint32_t *column = columns_.data();
    const double *inverse = inverse_.data();
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
            const double term = acc[k] * inverse[k];
            total += term;
            if (k + 1 < lanes) own[k + 1] = term;
        }
        increment_[v] = total;
        finite &= std::isfinite(total);
        x[node.global] = own[0] + total;
    }
    if (finite) return true;
    for (std::size_t v = 0; v < nodes_.size(); ++v) x[nodes_[v].global] = coefficients[v * lanes];
    return false;
}

void SparseExponential::apply(const double *g, double t, double *x) {
    scale_entries(g, t);
    if (path_ == ExpmPath::Plane) {
        apply_plane(t, x);
        return;
    }
    if (path_ == ExpmPath::Pade) {
        apply_pade(t, x);
        return;
    }
    bool finite = true;
    switch (lanes_) {
        case 1: finite = sweep<1>(x); break;
        case 2: finite = sweep<2>(x); break;
        case 4: finite = sweep<4>(x); break;
        case 8: finite = sweep<8>(x); break;
        default: finite = sweep<0>(x); break;
    }
    if (!finite) fail_nonfinite();
}

void SparseExponential::apply_plane(double t, double *x) {
    double A[4] = {0.0, 0.0, 0.0, 0.0};
    for (std::size_t j = 0; j < block_.size(); ++j) A[block_[j].row * 2 + block_[j].col] = scaled_[j];
    check_norm(std::max(std::fabs(A[0]) + std::fabs(A[2]), std::fabs(A[1]) + std::fabs(A[3])), t);
    const bool pair = moved_.size() == 2;
    const double x0 = x[moved_[0]], x1 = pair ? x[moved_[1]] : 0.0;
    double W[4] = {0.0, 0.0, 0.0, 0.0};
    if (pair)
        plane_expm1(A[0], A[1], A[2], A[3], W);
    else
        W[0] = std::expm1(A[0]);
    // x += (exp(tA) - I) x, rounded once; untouched when not representable.
    increment_[0] = W[0] * x0 + W[1] * x1;
    if (pair) increment_[1] = W[2] * x0 + W[3] * x1;
    if (!std::isfinite(increment_[0]) || (pair && !std::isfinite(increment_[1]))) fail_nonfinite();
    x[moved_[0]] = x0 + increment_[0];
    if (pair) x[moved_[1]] = x1 + increment_[1];
}

void SparseExponential::apply_pade(double t, double *x) {
    const std::size_t m = moved_.size();
    dense_.assign(square_entries(m, "exponential's matrix"), 0.0);
    for (std::size_t j = 0; j < block_.size(); ++j) dense_[block_[j].row * m + block_[j].col] = scaled_[j];
    check_norm(norm1(m, dense_.data()), t);
    exp_.resize(dense_.size());
    expm1_with(m, dense_.data(), exp_.data(), pade_scratch_);
    // x += (exp(tA) - I) x: the increment carries its own small rounding
    // errors, and x is rounded once (as on the other paths). x is left
    // untouched when the exact flow is not representable.
    bool finite = true;
    for (std::size_t r = 0; r < m; ++r) {
        double s = 0.0;
        for (std::size_t c = 0; c < m; ++c) s += exp_[r * m + c] * x[moved_[c]];
        increment_[r] = s;
        finite &= std::isfinite(s);
    }
    if (!finite) fail_nonfinite();
    for (std::size_t r = 0; r < m; ++r) x[moved_[r]] += increment_[r];
}

}  // namespace lpi
