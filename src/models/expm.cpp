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
                               {13, kPadeTheta13}};

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


}  // namespace

void expm_dense(std::size_t n, const double *A, double *E) {
    std::vector<double> buffer;
    expm_dense(n, A, E, buffer);
}

void expm_dense(std::size_t n, const double *A, double *E, std::vector<double> &buffer) {
    if (n == 0) return;
    const std::size_t nn = n * n;
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

void expm1_dense(std::size_t n, const double *A, double *W, std::vector<double> &buffer) {
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

void expm1_dense(std::size_t n, const double *A, double *W) {
    std::vector<double> buffer;
    expm1_dense(n, A, W, buffer);
}

double dense_norm1(std::size_t n, const double *A) { return norm1(n, A); }

bool elliptic_block(std::size_t m, const std::vector<double> &C) {
    const double norm = norm1(m, C.data());
    if (!(norm > 0.0) || !std::isfinite(norm)) return false;
    int exponent = 0;
    std::frexp(norm, &exponent);  // norm in [2^(exponent-1), 2^exponent)
    std::vector<double> E(m * m), square(m * m), scratch;
    for (double sign : {1.0, -1.0}) {
        // tau = 2^-exponent, exactly: ||tau C||_1 in [1/2, 1).
        std::vector<double> A(C);
        for (double &a : A) a = std::ldexp(sign * a, -exponent);
        expm_dense(m, A.data(), E.data(), scratch);
        for (int k = 0;; ++k) {
            // 2^20 times the growth a polynomial of degree m - 1 in tau
            // allows (a nilpotent part; or near it, a nearly parabolic
            // block, bounded only by about 1/delta), capped at 2^900.
            const double allowed = std::ldexp(1.0, std::min(20 + k * static_cast<int>(m - 1), 900));
            const double grown = norm1(m, E.data());
            if (!(grown <= allowed)) return false;  // or not finite
            if (k == 42) break;
            multiply(m, E.data(), E.data(), square.data());
            std::swap(E, square);
        }
    }
    return true;
}

std::vector<double> power_norms(std::size_t m, const std::vector<double> &C, int count) {
    std::vector<double> norms, power(C), product(m * m);
    norms.push_back(norm1(m, C.data()));
    for (int k = 2; k <= count; ++k) {
        multiply(m, power.data(), C.data(), product.data());
        power.swap(product);
        norms.push_back(norm1(m, power.data()));
    }
    return norms;
}

std::size_t square_entries(std::size_t n, const char *what) {
    if (n != 0 && n > std::numeric_limits<std::size_t>::max() / sizeof(double) / n)
        fail(LPI_ERR_NO_MEMORY, std::string("the ") + what + " of " + std::to_string(n) + " x " +
                                    std::to_string(n) + " doubles is larger than memory can "
                                    "address");
    return n * n;
}

}  // namespace lpi
