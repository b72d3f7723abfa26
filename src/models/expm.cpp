#include "expm.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <limits>

#include "../core/error.hpp"

namespace lpi {

namespace {

using Matrix = std::vector<double>;  // n x n, row-major

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
// (the common scaling does not matter: r_m = q_m^{-1} p_m).
std::vector<double> pade_coefficients(int m) {
    std::vector<double> b(m + 1);
    long double c = 1.0L;
    for (int k = 0; k <= m; ++k) {
        b[k] = static_cast<double>(c);
        c = c * (m - k) / ((2.0L * m - k) * (k + 1));
    }
    return b;
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

// U and V of r_m = (V - U)^{-1} (V + U) for m <= 9 (p_m = V + U, q_m = V - U).
void pade_low(std::size_t n, const double *A, int m, double *U, double *V) {
    const std::vector<double> b = pade_coefficients(m);
    const std::size_t nn = n * n;
    Matrix power(nn, 0.0), A2(nn), tmp(nn), odd(nn, 0.0);
    for (std::size_t i = 0; i < n; ++i) power[i * n + i] = 1.0;  // A^0
    multiply(n, A, A, A2.data());
    std::fill(V, V + nn, 0.0);
    for (int k = 0; k <= m; k += 2) {  // even powers A^k feed V and (times A) U
        for (std::size_t e = 0; e < nn; ++e) {
            V[e] += b[k] * power[e];
            odd[e] += b[k + 1] * power[e];
        }
        if (k + 2 <= m) {
            multiply(n, power.data(), A2.data(), tmp.data());
            power.swap(tmp);
        }
    }
    multiply(n, A, odd.data(), U);
}

// The degree-13 evaluation of Higham 2005, eq. (2.11): six products.
void pade13(std::size_t n, const double *A, double *U, double *V) {
    const std::vector<double> b = pade_coefficients(13);
    const std::size_t nn = n * n;
    Matrix A2(nn), A4(nn), A6(nn), inner(nn), tmp(nn);
    multiply(n, A, A, A2.data());
    multiply(n, A2.data(), A2.data(), A4.data());
    multiply(n, A4.data(), A2.data(), A6.data());
    for (std::size_t e = 0; e < nn; ++e) inner[e] = b[13] * A6[e] + b[11] * A4[e] + b[9] * A2[e];
    multiply(n, A6.data(), inner.data(), tmp.data());
    for (std::size_t e = 0; e < nn; ++e)
        tmp[e] += b[7] * A6[e] + b[5] * A4[e] + b[3] * A2[e];
    for (std::size_t i = 0; i < n; ++i) tmp[i * n + i] += b[1];
    multiply(n, A, tmp.data(), U);
    for (std::size_t e = 0; e < nn; ++e) inner[e] = b[12] * A6[e] + b[10] * A4[e] + b[8] * A2[e];
    multiply(n, A6.data(), inner.data(), V);
    for (std::size_t e = 0; e < nn; ++e) V[e] += b[6] * A6[e] + b[4] * A4[e] + b[2] * A2[e];
    for (std::size_t i = 0; i < n; ++i) V[i * n + i] += b[0];
}

// U, V of the Pade approximant chosen for A (Higham 2005, Algorithm 2.3) and
// the number of squarings s: exp(A) ~ r(A / 2^s)^(2^s), r = (V - U)^{-1} (V + U).
// Returns false for a non-finite A.
bool pade_terms(std::size_t n, const double *A, Matrix &U, Matrix &V, int &squarings) {
    const std::size_t nn = n * n;
    const double norm = norm1(n, A);
    if (!std::isfinite(norm)) return false;
    U.resize(nn);
    V.resize(nn);
    squarings = 0;
    for (const Degree &d : kDegrees) {
        if (d.m < 13 && norm <= d.theta) {
            pade_low(n, A, d.m, U.data(), V.data());
            return true;
        }
    }
    // Scale A by 2^-s so that ||A / 2^s||_1 <= theta_13 (exact: a power of 2).
    if (norm > kDegrees[4].theta)
        squarings = std::max(0, static_cast<int>(std::ceil(std::log2(norm / kDegrees[4].theta))));
    Matrix scaled(A, A + nn);
    for (double &a : scaled) a = std::ldexp(a, -squarings);
    pade13(n, scaled.data(), U.data(), V.data());
    return true;
}

}  // namespace

void expm_dense(std::size_t n, const double *A, double *E) {
    if (n == 0) return;
    const std::size_t nn = n * n;
    Matrix U, V, Q(nn);
    int squarings = 0;
    if (!pade_terms(n, A, U, V, squarings)) {
        std::fill(E, E + nn, std::numeric_limits<double>::quiet_NaN());
        return;
    }
    for (std::size_t e = 0; e < nn; ++e) {
        Q[e] = V[e] - U[e];
        E[e] = V[e] + U[e];
    }
    solve(n, Q.data(), E);
    for (int s = 0; s < squarings; ++s) {
        multiply(n, E, E, Q.data());
        std::copy(Q.begin(), Q.end(), E);
    }
}

void expm1_dense(std::size_t n, const double *A, double *W) {
    if (n == 0) return;
    const std::size_t nn = n * n;
    Matrix U, V, Q(nn);
    int squarings = 0;
    if (!pade_terms(n, A, U, V, squarings)) {
        std::fill(W, W + nn, std::numeric_limits<double>::quiet_NaN());
        return;
    }
    // r - I = (V - U)^{-1} (V + U) - I = (V - U)^{-1} (2U): no cancellation, so
    // the result is accurate relative to ||A|| even when exp(A) is close to I.
    for (std::size_t e = 0; e < nn; ++e) {
        Q[e] = V[e] - U[e];
        W[e] = 2.0 * U[e];
    }
    solve(n, Q.data(), W);
    // (I + W)^2 - I = W W + 2 W.
    for (int s = 0; s < squarings; ++s) {
        multiply(n, W, W, Q.data());
        for (std::size_t e = 0; e < nn; ++e) W[e] = Q[e] + 2.0 * W[e];
    }
}

std::size_t square_entries(std::size_t n, const char *what) {
    if (n != 0 && n > std::numeric_limits<std::size_t>::max() / sizeof(double) / n)
        fail(LPI_ERR_NO_MEMORY, std::string("the ") + what + " of " + std::to_string(n) + " x " +
                                    std::to_string(n) + " doubles is larger than memory can "
                                    "address");
    return n * n;
}

void ExpmWorkspace::check_finite(std::size_t m) const {
    // x is left untouched when the exact flow is not representable.
    for (std::size_t v = 0; v < m; ++v)
        if (!std::isfinite(increment_[v]))
            fail(LPI_ERR_NONFINITE, "the exact flow overflows (component " +
                                        std::to_string(active_[v]) + ")");
}

long ExpmWorkspace::topological_depth() {
    // Kahn's algorithm on edges col -> row (x_col drives x_row). A cycle
    // (a self-loop included) means the pattern does not force nilpotency.
    const std::size_t m = active_.size();
    start_.assign(m + 1, 0);
    indegree_.assign(m, 0);
    for (const SparseEntry &e : local_) {
        ++start_[e.col + 1];
        ++indegree_[e.row];
    }
    for (std::size_t v = 0; v < m; ++v) start_[v + 1] += start_[v];
    adjacency_.resize(local_.size());
    cursor_.assign(start_.begin(), start_.end() - 1);
    for (const SparseEntry &e : local_) adjacency_[cursor_[e.col]++] = e.row;
    queue_.clear();
    for (std::size_t v = 0; v < m; ++v)
        if (indegree_[v] == 0) queue_.push_back(static_cast<std::uint32_t>(v));
    depth_.assign(m, 0);
    long deepest = 0;
    for (std::size_t head = 0; head < queue_.size(); ++head) {
        const std::uint32_t u = queue_[head];
        deepest = std::max(deepest, depth_[u]);
        for (std::size_t a = start_[u]; a < start_[u + 1]; ++a) {
            const std::uint32_t v = adjacency_[a];
            depth_[v] = std::max(depth_[v], depth_[u] + 1);
            if (--indegree_[v] == 0) queue_.push_back(v);
        }
    }
    return queue_.size() == m ? deepest : -1;
}

ExpmPath ExpmWorkspace::apply(std::size_t n, const std::vector<SparseEntry> &entries, double t,
                              double *x) {
    if (local_of_.size() < n) local_of_.resize(n, -1);
    active_.clear();
    local_.clear();
    auto local = [&](std::uint32_t g) {
        if (local_of_[g] < 0) {
            local_of_[g] = static_cast<std::int64_t>(active_.size());
            active_.push_back(g);
        }
        return static_cast<std::uint32_t>(local_of_[g]);
    };
    for (const SparseEntry &e : entries) {
        const double v = t * e.value;
        if (v == 0.0) continue;
        local_.push_back({local(e.row), local(e.col), v});
    }
    for (std::uint32_t g : active_) local_of_[g] = -1;  // ready for the next call
    const std::size_t m = active_.size();

    last_depth_ = topological_depth();
    if (last_depth_ >= 0) {
        // Finite series: term_k = (tA)^k x / k!, exactly zero beyond depth.
        term_.resize(m);
        next_.resize(m);
        increment_.assign(m, 0.0);
        for (std::size_t v = 0; v < m; ++v) term_[v] = x[active_[v]];
        for (long k = 1; k <= last_depth_; ++k) {
            std::fill(next_.begin(), next_.end(), 0.0);
            for (const SparseEntry &e : local_) next_[e.row] += e.value * term_[e.col];
            const double inverse_k = 1.0 / static_cast<double>(k);
            for (std::size_t v = 0; v < m; ++v) {
                next_[v] *= inverse_k;
                increment_[v] += next_[v];
            }
            term_.swap(next_);
        }
        // One rounding on x: the increment is summed first.
        check_finite(m);
        for (std::size_t v = 0; v < m; ++v) x[active_[v]] += increment_[v];
        return ExpmPath::Nilpotent;
    }

    dense_.assign(square_entries(m, "exponential's matrix"), 0.0);
    for (const SparseEntry &e : local_) dense_[e.row * m + e.col] += e.value;
    // Each squaring doubles the relative error of the computed exponential
    // (for a rotation: its departure from orthogonality, which the Casimirs
    // see), so beyond kMaxSquarings the flow is refused rather than returned
    // with a Casimir error above about 2^kMaxSquarings unit round-offs.
    const double norm = norm1(m, dense_.data());
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
    exp_.resize(dense_.size());
    expm1_dense(m, dense_.data(), exp_.data());
    // x += (exp(tA) - I) x: the increment carries its own small rounding
    // errors, and x is rounded once (as in the nilpotent branch).
    term_.resize(m);
    for (std::size_t v = 0; v < m; ++v) term_[v] = x[active_[v]];
    increment_.assign(m, 0.0);
    for (std::size_t r = 0; r < m; ++r) {
        double s = 0.0;
        for (std::size_t c = 0; c < m; ++c) s += exp_[r * m + c] * term_[c];
        increment_[r] = s;
    }
    check_finite(m);
    for (std::size_t r = 0; r < m; ++r) x[active_[r]] += increment_[r];
    return ExpmPath::Pade;
}

}  // namespace lpi
