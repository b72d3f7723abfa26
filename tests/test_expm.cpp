// White-box tests of the matrix exponential (src/models/expm.hpp) against
// independent computations: a finite long-double series for nilpotent A,
// closed-form rotations (2x2 and Rodrigues' formula) for skew A, and a
// long-double Taylor series with scaling and squaring for general A.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

// Before cmocka.h (through lpi_test.h), whose fail() macro would rewrite lpi::fail.
#include "core/error.hpp"
#include "lpi_test.h"

#include "models/expm.hpp"

namespace {

using LongMatrix = std::vector<long double>;

LongMatrix long_multiply(std::size_t n, const LongMatrix &A, const LongMatrix &B) {
    LongMatrix C(n * n, 0.0L);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 0; k < n; ++k)
            for (std::size_t j = 0; j < n; ++j) C[i * n + j] += A[i * n + k] * B[k * n + j];
    return C;
}

// exp(A) - I in long double: Taylor on A / 2^s (norm <= 1/4, 40 terms), then
// (I + W)^2 - I = W^2 + 2W, s times. Independent of the Pade code.
LongMatrix reference_expm1(std::size_t n, const std::vector<double> &A) {
    long double norm = 0.0L;
    for (std::size_t j = 0; j < n; ++j) {
        long double s = 0.0L;
        for (std::size_t i = 0; i < n; ++i) s += std::fabs(static_cast<long double>(A[i * n + j]));
        norm = std::max(norm, s);
    }
    int squarings = 0;
    while (norm > 0.25L) {
        norm /= 2;
        ++squarings;
    }
    LongMatrix X(n * n), term(n * n), W(n * n, 0.0L);
    for (std::size_t e = 0; e < n * n; ++e) X[e] = std::ldexp(static_cast<long double>(A[e]), -squarings);
    term = X;
    for (int k = 1; k <= 40; ++k) {
        for (std::size_t e = 0; e < n * n; ++e) W[e] += term[e];
        term = long_multiply(n, term, X);
        for (long double &t : term) t /= (k + 1);
    }
    for (int s = 0; s < squarings; ++s) {
        LongMatrix W2 = long_multiply(n, W, W);
        for (std::size_t e = 0; e < n * n; ++e) W[e] = W2[e] + 2 * W[e];
    }
    return W;
}

double relative_error(std::size_t n, const std::vector<double> &E, const LongMatrix &reference,
                      bool add_identity) {
    long double diff = 0.0L, size = 0.0L;
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
            const long double r = reference[i * n + j] + (add_identity && i == j ? 1.0L : 0.0L);
            diff = std::max(diff, std::fabs(E[i * n + j] - r));
            size = std::max(size, std::fabs(r));
        }
    return static_cast<double>(diff / size);
}

std::vector<double> random_matrix(std::size_t n, double norm, std::mt19937_64 &rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> A(n * n);
    for (double &a : A) a = u(rng);
    double current = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        double s = 0.0;
        for (std::size_t i = 0; i < n; ++i) s += std::fabs(A[i * n + j]);
        current = std::max(current, s);
    }
    for (double &a : A) a *= norm / current;
    return A;
}

// The terms of A (its nonzeros, each its own parameter, g = its value).
std::vector<lpi::SparseTerm> terms_of(std::size_t n, const std::vector<double> &A,
                                      std::vector<double> *g) {
    std::vector<lpi::SparseTerm> terms;
    g->clear();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j)
            if (A[i * n + j] != 0.0) {
                terms.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j),
                                 static_cast<std::uint32_t>(g->size()), 1.0});
                g->push_back(A[i * n + j]);
            }
    return terms;
}

// y = E x for the sparse path, to compare against a dense exponential.
std::vector<double> apply_sparse(std::size_t n, const std::vector<double> &A, const std::vector<double> &x,
                                 lpi::ExpmPath *path, long *depth) {
    std::vector<double> g;
    lpi::SparseExponential exponential(n, terms_of(n, A, &g));
    std::vector<double> y = x;
    exponential.apply(g.data(), 1.0, y.data());
    *path = exponential.path();
    *depth = exponential.depth();
    return y;
}

double vector_error(const std::vector<double> &y, const std::vector<long double> &reference) {
    long double diff = 0.0L, size = 0.0L;
    for (std::size_t i = 0; i < y.size(); ++i) {
        diff = std::max(diff, std::fabs(y[i] - reference[i]));
        size = std::max(size, std::fabs(reference[i]));
    }
    return static_cast<double>(diff / size);
}

std::vector<long double> long_apply(std::size_t n, const LongMatrix &E, const std::vector<double> &x,
                                    bool add_identity) {
    std::vector<long double> y(n, 0.0L);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) y[i] += E[i * n + j] * x[j];
        if (add_identity) y[i] += x[i];
    }
    return y;
}

void test_general_matrices(void **) {
    // Norms below and above each theta_m of Higham 2005 (degrees 3..13) and
    // far beyond (scaling and squaring).
    std::mt19937_64 rng(7);
    const double norms[] = {1e-8, 0.01, 0.2, 0.9, 2.0, 5.0, 12.0, 40.0};
    for (double norm : norms) {
        for (std::size_t n : {1u, 2u, 5u, 8u}) {
            const std::vector<double> A = random_matrix(n, norm, rng);
            const LongMatrix W = reference_expm1(n, A);
            std::vector<double> E(n * n), W1(n * n);
            lpi::expm_dense(n, A.data(), E.data());
            lpi::expm1_dense(n, A.data(), W1.data());
            const double e = relative_error(n, E, W, true);
            const double e1 = relative_error(n, W1, W, false);
            std::printf("expm general n=%zu ||A||_1=%g: exp rel. error %.2e, exp-I rel. error %.2e\n",
                            n, norm, e, e1);
            // exp(A) of a random matrix is conditioned like ||A||; allow that.
            const double tolerance = 64 * 2.2e-16 * std::max(1.0, norm);
            assert_true(e < tolerance);
            assert_true(e1 < tolerance);
        }
    }
}

void test_skew_matrices(void **) {
    // 2x2 rotation generators: exp = [[c, s], [-s, c]].
    for (double theta : {1e-3, 0.3, 2.0, 7.5, 100.0}) {
        const std::vector<double> A = {0.0, theta, -theta, 0.0};
        std::vector<double> E(4);
        lpi::expm_dense(2, A.data(), E.data());
        const LongMatrix exact = {std::cos(static_cast<long double>(theta)), std::sin(static_cast<long double>(theta)),
                                  -std::sin(static_cast<long double>(theta)), std::cos(static_cast<long double>(theta))};
        const double e = relative_error(2, E, exact, false);
        std::printf("expm skew 2x2 theta=%g: rel. error %.2e\n", theta, e);
        assert_true(e < 16 * 2.2e-16 * std::max(1.0, theta));
    }
    // 3x3 skew K(w): exp = I + sin(t)/t K + (1 - cos t)/t^2 K^2 (Rodrigues).
    std::mt19937_64 rng(11);
    std::normal_distribution<double> g;
    for (double theta : {0.05, 1.0, 3.0, 40.0}) {
        double w[3] = {g(rng), g(rng), g(rng)};
        const double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        for (double &c : w) c *= theta / len;
        const std::vector<double> K = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
        LongMatrix KL(K.begin(), K.end());
        const LongMatrix K2 = long_multiply(3, KL, KL);
        const long double t = theta;
        LongMatrix exact(9);
        for (int e = 0; e < 9; ++e)
            exact[e] = (e % 4 == 0 ? 1.0L : 0.0L) + std::sin(t) / t * KL[e] + (1 - std::cos(t)) / (t * t) * K2[e];
        std::vector<double> E(9);
        lpi::expm_dense(3, K.data(), E.data());
        const double err = relative_error(3, E, exact, false);
        // The sparse path (a cycle, so Pade) on a vector.
        lpi::ExpmPath path;
        long depth;
        const std::vector<double> x = {0.3, -1.1, 0.7};
        const std::vector<double> y = apply_sparse(3, K, x, &path, &depth);
        assert_int_equal(static_cast<int>(path), static_cast<int>(lpi::ExpmPath::Pade));
        const double ey = vector_error(y, long_apply(3, exact, x, false));
        std::printf("expm skew 3x3 |w|=%g: rel. error %.2e, applied %.2e\n", theta, err, ey);
        assert_true(err < 16 * 2.2e-16 * std::max(1.0, theta));
        assert_true(ey < 16 * 2.2e-16 * std::max(1.0, theta));
    }
}

void test_nilpotent_matrices(void **) {
    // Strictly lower triangular under a permutation: nilpotent, detected from
    // the pattern; reference = finite long-double series sum_{k<n} A^k / k!.
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    const std::size_t n = 7;
    const std::size_t perm[n] = {4, 0, 6, 2, 5, 1, 3};
    std::vector<double> A(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < i; ++j) A[perm[i] * n + perm[j]] = u(rng);
    LongMatrix AL(A.begin(), A.end()), power(n * n, 0.0L), exact(n * n, 0.0L);
    for (std::size_t i = 0; i < n; ++i) power[i * n + i] = 1.0L;
    long double factorial = 1.0L;
    for (std::size_t k = 0; k < n; ++k) {
        if (k > 0) factorial *= k;
        for (std::size_t e = 0; e < n * n; ++e) exact[e] += power[e] / factorial;
        power = long_multiply(n, power, AL);
    }
    for (long double p : power) assert_true(p == 0.0L);  // A^n = 0
    std::vector<double> E(n * n);
    lpi::expm_dense(n, A.data(), E.data());
    const double e = relative_error(n, E, exact, false);
    lpi::ExpmPath path;
    long depth;
    const std::vector<double> x = {1.0, -0.5, 0.25, 2.0, -1.5, 0.75, 0.1};
    const std::vector<double> y = apply_sparse(n, A, x, &path, &depth);
    assert_int_equal(static_cast<int>(path), static_cast<int>(lpi::ExpmPath::Nilpotent));
    assert_int_equal(depth, static_cast<long>(n - 1));
    const double ey = vector_error(y, long_apply(n, exact, x, false));
    std::printf("expm nilpotent n=7 (depth 6): Pade rel. error %.2e, finite series %.2e\n", e, ey);
    assert_true(e < 1e-13);
    assert_true(ey < 1e-14);

    // A self-loop (diagonal entry) is not nilpotent: the Pade path.
    A[perm[3] * n + perm[3]] = 0.5;
    apply_sparse(n, A, x, &path, &depth);
    assert_int_equal(static_cast<int>(path), static_cast<int>(lpi::ExpmPath::Pade));
    assert_int_equal(depth, -1);
    // The pattern decides the path, not the values of a call: a cycle whose
    // entry is zero in this call is the closed-form 2x2 path, exact here.
    const std::vector<lpi::SparseTerm> cycle = {{0, 1, 0, 2.0}, {1, 0, 1, 1.0}};
    lpi::SparseExponential exponential(2, cycle);
    assert_int_equal(static_cast<int>(exponential.path()), static_cast<int>(lpi::ExpmPath::Plane));
    assert_int_equal(exponential.depth(), -1);
    const double g[2] = {1.0, 0.0};
    double z[2] = {3.0, 5.0};
    exponential.apply(g, 0.5, z);
    assert_true(z[0] == 3.0 + 0.5 * 2.0 * 5.0 && z[1] == 5.0);
}

void test_sparse_nilpotent_scales_with_nonzeros(void **) {
    // Three layers of n/3 indices, each index driving two in the next layer:
    // depth 2. A dense exponential of this size (n = 300000) could not even be
    // stored; the series touches only the nonzeros.
    const std::uint32_t layer = 100000, n = 3 * layer;
    struct Entry {
        std::uint32_t row, col;
        double value;
    };
    std::vector<Entry> entries;
    for (std::uint32_t i = 0; i < 2 * layer; ++i) {
        const std::uint32_t base = (i / layer + 1) * layer, offset = i % layer;
        entries.push_back({base + offset, i, 0.5});
        entries.push_back({base + (offset + 1) % layer, i, -0.25});
    }
    // One parameter: A = g C with g = 1.
    std::vector<lpi::SparseTerm> terms;
    for (const Entry &e : entries) terms.push_back({e.row, e.col, 0, e.value});
    std::vector<double> x(n), y(n);
    for (std::uint32_t i = 0; i < n; ++i) x[i] = std::sin(0.001 * i) + 1.0;
    y = x;
    const double t = 0.7, g = 1.0;
    lpi::SparseExponential exponential(n, terms);
    assert_int_equal(static_cast<int>(exponential.path()), static_cast<int>(lpi::ExpmPath::Nilpotent));
    assert_int_equal(exponential.depth(), 2);
    exponential.apply(&g, t, y.data());
    // Reference: x + t A x + t^2 A^2 x / 2 with plain loops.
    std::vector<double> Ax(n, 0.0), AAx(n, 0.0);
    for (const auto &e : entries) Ax[e.row] += e.value * x[e.col];
    for (const auto &e : entries) AAx[e.row] += e.value * Ax[e.col];
    double worst = 0.0;
    for (std::uint32_t i = 0; i < n; ++i)
        worst = std::max(worst, std::fabs(y[i] - (x[i] + t * Ax[i] + 0.5 * t * t * AAx[i])));
    assert_true(worst < 1e-14);
}

// The closed form of 1x1 and 2x2 blocks against the long-double Taylor
// reference: rotation generators (with and without a trace), elliptic,
// hyperbolic and parabolic (delta = 0, a Jordan block) planes, a self-loop.
// An index the pattern does not touch is left alone.
void test_plane_closed_form(void **) {
    const std::vector<std::vector<double>> planes = {
        {0.0, 0.3, -0.3, 0.0},      // rotation by 0.3
        {0.0, -2.5, 2.5, 0.0},      // rotation by -2.5
        {0.2, 1.1, -1.1, 0.2},      // rotation times e^0.2
        {0.4, 1.5, -0.7, -0.1},     // elliptic, p != 0
        {0.3, 0.8, 0.9, -0.5},      // hyperbolic
        {1.0, 1.0, -1.0, -1.0},     // parabolic: N^2 = 0
        {1e-9, 3e-9, -2e-9, 4e-9},  // near the identity
        {0.0, 7.0, -7.0, 0.0},      // rotation past 2 pi
    };
    const std::vector<double> x = {0.7, -1.3, 2.0};
    for (const std::vector<double> &plane : planes) {
        // Embedded in n = 3 on indices {2, 0}: index 1 is untouched.
        const std::uint32_t index[2] = {2, 0};
        std::vector<lpi::SparseTerm> terms;
        std::vector<double> g;
        for (std::uint32_t r = 0; r < 2; ++r)
            for (std::uint32_t c = 0; c < 2; ++c)
                if (plane[r * 2 + c] != 0.0) {
                    terms.push_back({index[r], index[c], static_cast<std::uint32_t>(g.size()), 1.0});
                    g.push_back(plane[r * 2 + c]);
                }
        lpi::SparseExponential exponential(3, terms);
        assert_int_equal(static_cast<int>(exponential.path()), static_cast<int>(lpi::ExpmPath::Plane));
        std::vector<double> y = x;
        exponential.apply(g.data(), 1.0, y.data());
        const LongMatrix W = reference_expm1(2, plane);
        const std::vector<double> local = {x[2], x[0]};
        const std::vector<long double> exact = long_apply(2, W, local, true);
        const double error = vector_error({y[2], y[0]}, exact);
        double norm = 0.0;
        for (double a : plane) norm = std::max(norm, std::fabs(a));
        std::printf("plane [[%g, %g], [%g, %g]]: closed form rel. error %.2e\n", plane[0], plane[1],
                    plane[2], plane[3], error);
        assert_true(error < 16 * 2.2e-16 * std::max(1.0, norm));
        assert_true(y[1] == x[1]);
    }
    // A self-loop alone (x' = a x, exp = e^a): a diagonal, the series' path.
    const std::vector<lpi::SparseTerm> loop = {{1, 1, 0, -0.75}};
    lpi::SparseExponential exponential(2, loop);
    assert_int_equal(static_cast<int>(exponential.path()), static_cast<int>(lpi::ExpmPath::DiagonalSeries));
    double z[2] = {4.0, 3.0};
    const double g = 2.0;
    exponential.apply(&g, 0.5, z);
    assert_true(z[0] == 4.0);
    assert_true(std::fabs(z[1] - 3.0 * std::exp(-0.75)) < 4 * 2.2e-16 * 3.0);
}

// A rotation, t A = [[0, b], [-b, 0]] from one parameter, is applied without
// forming t A (SparseExponential::rotate): the same bits as the plane's
// general closed form, which takes it where b comes from two parameters
// equal in value, and the same refusals. Includes half turns and more (the
// shears of -M), a b whose square underflows (the general path, whose delta
// is then 0), and a b that is not a number.
void test_rotation_takes_the_plane_bits(void **) {
    std::mt19937_64 random(20261130);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    const double coefficients[] = {1.0, -1.0, 0.75, 3.0, 0.3};
    const double scales[] = {1e-170, 1e-3, 0.4, 1.5, 3.0, 7.0};
    int rotations = 0;
    for (double c : coefficients) {
        // Entries listed lower first: the plan finds the upper one itself.
        const std::vector<lpi::SparseTerm> one = {{3, 1, 0, -c}, {1, 3, 0, c}};
        const std::vector<lpi::SparseTerm> two = {{3, 1, 1, -c}, {1, 3, 0, c}};
        lpi::SparseExponential rotation(4, one), plane(4, two);
        assert_int_equal(static_cast<int>(rotation.path()), static_cast<int>(lpi::ExpmPath::Plane));
        for (double scale : scales)
            for (int sample = 0; sample < 200; ++sample) {
                const double g = scale * uniform(random), t = uniform(random);
                const double g_twice[2] = {g, g};
                std::vector<double> x = {uniform(random), uniform(random), uniform(random),
                                         uniform(random)};
                std::vector<double> y = x;
                rotation.apply(&g, t, x.data());
                plane.apply(g_twice, t, y.data());
                for (std::size_t i = 0; i < x.size(); ++i)
                    if (std::memcmp(&x[i], &y[i], sizeof(double)) != 0)
                        fail_msg("c = %g, g = %.17g, t = %.17g: component %zu %.17g, general "
                                 "plane %.17g", c, g, t, i, x[i], y[i]);
                ++rotations;
            }
        // Refusals: the same status and message, x untouched.
        const std::vector<double> edge = {1.5e308, 1.5e308, 1.5e308, 1.5e308};
        // Too large a step, an infinite one (the message names t), not a
        // number, and 1.5e308 (cos + sin) > DBL_MAX.
        const double refused[] = {1e11, INFINITY, std::nan(""), 0.5 / std::fabs(c)};
        for (const double g : refused) {
            const double g_twice[2] = {g, g};
            std::string first, second;
            int status[2] = {LPI_OK, LPI_OK};
            for (int which = 0; which < 2; ++which) {
                std::vector<double> x = edge;
                try {
                    if (which == 0)
                        rotation.apply(&g, 1.0, x.data());
                    else
                        plane.apply(g_twice, 1.0, x.data());
                } catch (const lpi::Error &e) {
                    status[which] = e.status();
                    (which == 0 ? first : second) = e.what();
                }
                for (std::size_t i = 0; i < x.size(); ++i)
                    if (!(x[i] == edge[i]))
                        fail_msg("c = %g, g = %g, %s: x[%zu] = %g", c, g, which ? "plane" : "rotation", i, x[i]);
            }
            assert_int_not_equal(status[0], LPI_OK);
            assert_int_equal(status[0], status[1]);
            assert_string_equal(first.c_str(), second.c_str());
        }
    }
    std::printf("rotations: %d flows with the general plane's bits\n", rotations);
}

// Every path refuses, x unchanged bit for bit: a flow whose result is not
// finite (LPI_ERR_NONFINITE, naming the component), and off the nilpotent
// path a step beyond kMaxSquarings squarings (LPI_ERR_INVALID).
void expect_refusal(lpi::SparseExponential &exponential, const double *g, double t,
                    std::vector<double> x, int status, const char *words) {
    const std::vector<double> before = x;
    try {
        exponential.apply(g, t, x.data());
        fail_msg("apply did not refuse (%s)", words);
    } catch (const lpi::Error &e) {
        assert_int_equal(e.status(), status);
        if (!std::strstr(e.what(), words)) fail_msg("message '%s' does not say '%s'", e.what(), words);
    }
    for (std::size_t i = 0; i < x.size(); ++i) assert_true(x[i] == before[i]);
}

void test_refusals_leave_x_unchanged(void **) {
    const std::vector<double> x = {0.5, -2.0, 1.5, 3.0};
    // Nilpotent chain 0 -> 1 -> 2: node 1 is written before node 2 overflows.
    const std::vector<lpi::SparseTerm> chain = {{1, 0, 0, 1.0}, {2, 1, 1, 1.0}};
    lpi::SparseExponential series(4, chain);
    assert_int_equal(static_cast<int>(series.path()), static_cast<int>(lpi::ExpmPath::Nilpotent));
    const double huge[2] = {1.0, 1e300};
    expect_refusal(series, huge, 1e10, x, LPI_ERR_NONFINITE, "component 2");
    // A shear (depth 1: nodes 1 and 2 read the fixed 0 and 3 only), whose
    // second node overflows.
    const std::vector<lpi::SparseTerm> shear_terms = {{1, 0, 0, 1.0}, {2, 3, 1, 1.0}};
    lpi::SparseExponential shear(4, shear_terms);
    assert_int_equal(shear.depth(), 1);
    expect_refusal(shear, huge, 1e10, x, LPI_ERR_NONFINITE, "component 2");
    // A kick: one node of one term.
    const std::vector<lpi::SparseTerm> kick_terms = {{2, 3, 0, 1.0}};
    lpi::SparseExponential kick(4, kick_terms);
    assert_int_equal(kick.depth(), 1);
    expect_refusal(kick, &huge[1], 1e10, x, LPI_ERR_NONFINITE, "component 2");
    // A rotation generator beyond 2^32 squarings, and a hyperbolic plane whose
    // exponential overflows.
    const std::vector<lpi::SparseTerm> plane = {{0, 3, 0, 1.0}, {3, 0, 1, 1.0}};
    lpi::SparseExponential closed(4, plane);
    const double rotation[2] = {1e11, -1e11}, hyperbolic[2] = {800.0, 800.0};
    expect_refusal(closed, rotation, 1.0, x, LPI_ERR_INVALID, "squarings");
    expect_refusal(closed, hyperbolic, 1.0, x, LPI_ERR_NONFINITE, "overflows");
    // The Pade path (a 3-cycle) alike.
    const std::vector<lpi::SparseTerm> cycle = {{1, 0, 0, 1.0}, {2, 1, 0, 1.0}, {0, 2, 0, 1.0}};
    lpi::SparseExponential pade(4, cycle);
    assert_int_equal(static_cast<int>(pade.path()), static_cast<int>(lpi::ExpmPath::Pade));
    const double large = 1e11;
    expect_refusal(pade, &large, 1.0, x, LPI_ERR_INVALID, "squarings");

    // Every increment finite, a new value not (1.5e308 + 1.5e308): the new
    // values are what is checked; each path wrote inf.
    const std::vector<double> edge = {1.5e308, 1.5e308, 1.5e308, 1.5e308};
    const double one[2] = {1.0, 1.0};
    expect_refusal(series, one, 1.0, edge, LPI_ERR_NONFINITE, "component 1");
    expect_refusal(shear, one, 1.0, edge, LPI_ERR_NONFINITE, "component 1");
    expect_refusal(kick, one, 1.0, edge, LPI_ERR_NONFINITE, "component 2");
    const double turn[2] = {0.5, -0.5};  // a rotation by 0.5: 1.5e308 (cos + sin) > DBL_MAX
    expect_refusal(closed, turn, 1.0, edge, LPI_ERR_NONFINITE, "component 0");
    const double small = 0.5;
    expect_refusal(pade, &small, 1.0, edge, LPI_ERR_NONFINITE, "overflows");
}

// Deep nilpotent patterns (depth above the unrolled widths: lanes at run
// time) and positions summing several parameters, against the long-double
// finite series of the matrix they make.
void test_deep_series_and_summed_terms(void **) {
    const std::size_t n = 13;  // a chain 0 -> 1 -> ... -> 12 with shortcuts
    std::vector<lpi::SparseTerm> terms;
    std::vector<double> A(n * n, 0.0);
    const double g[3] = {0.6, -0.35, 0.2};
    for (std::uint32_t i = 1; i < n; ++i) {
        terms.push_back({i, i - 1, 0, 1.0 + 0.1 * i});
        terms.push_back({i, i - 1, 1, 0.5});  // the same position, another parameter
        A[i * n + i - 1] = (1.0 + 0.1 * i) * g[0] + 0.5 * g[1];
        if (i >= 3) {
            terms.push_back({i, i - 3, 2, -1.0});
            A[i * n + i - 3] = -g[2];
        }
    }
    lpi::SparseExponential exponential(n, terms);
    assert_int_equal(static_cast<int>(exponential.path()), static_cast<int>(lpi::ExpmPath::Nilpotent));
    assert_int_equal(exponential.depth(), static_cast<long>(n - 1));
    std::vector<double> x(n), y;
    for (std::size_t i = 0; i < n; ++i) x[i] = std::cos(1.0 + i);
    y = x;
    const double t = 0.9;
    exponential.apply(g, t, y.data());
    LongMatrix tA(n * n), power(n * n, 0.0L), exact(n * n, 0.0L);
    for (std::size_t e = 0; e < n * n; ++e) tA[e] = t * static_cast<long double>(A[e]);
    for (std::size_t i = 0; i < n; ++i) power[i * n + i] = 1.0L;
    long double factorial = 1.0L;
    for (std::size_t k = 0; k < n; ++k) {
        if (k > 0) factorial *= k;
        for (std::size_t e = 0; e < n * n; ++e) exact[e] += power[e] / factorial;
        power = long_multiply(n, power, tA);
    }
    const double error = vector_error(y, long_apply(n, exact, x, false));
    std::printf("nilpotent chain n=13 (depth 12, summed terms): rel. error %.2e\n", error);
    assert_true(error < 1e-14);
}

// A diagonal D that commutes with an acyclic rest N (each entry of N joins
// two indices with the same diagonal terms: a grading) is exp(tD) after the
// series of N; against the long-double exponential of the dense t A. A
// diagonal that does not commute goes to the Pade path.
void test_diagonal_series(void **) {
    const std::size_t n = 8;
    // Weights 2, -2, none, 4, 2, -2, -4, 6 (parameter 0: exponentials by
    // powers of one expm1) and N within a weight (parameter 1): 0 -> 4
    // (weight 2) and 1 -> 5 (weight -2).
    const std::vector<lpi::SparseTerm> terms = {
        {0, 0, 0, 2.0}, {1, 1, 0, -2.0}, {3, 3, 0, 4.0}, {4, 4, 0, 2.0}, {5, 5, 0, -2.0},
        {6, 6, 0, -4.0}, {7, 7, 0, 6.0}, {4, 0, 1, 1.5}, {5, 1, 1, -0.7}};
    lpi::SparseExponential exponential(n, terms);
    assert_int_equal(static_cast<int>(exponential.path()),
                     static_cast<int>(lpi::ExpmPath::DiagonalSeries));
    const double g[2] = {0.45, -1.3}, t = 0.8;
    std::vector<double> A(n * n, 0.0);
    for (const lpi::SparseTerm &term : terms)
        A[term.row * n + term.col] += t * term.coefficient * g[term.parameter];
    const std::vector<double> x = {0.9, -1.7, 0.25, 1.1, -0.4, 2.3, -0.6, 1.3};
    std::vector<double> y = x;
    exponential.apply(g, t, y.data());
    const double error = vector_error(y, long_apply(n, reference_expm1(n, A), x, true));
    std::printf("diagonal series (weights -4 .. 6 and N within them): rel. error %.2e\n", error);
    assert_true(error < 4 * 2.2e-16);
    assert_true(y[2] == x[2]);

    // The same N with a diagonal that differs across an entry of N: not
    // commuting, the general Pade path.
    std::vector<lpi::SparseTerm> skewed = terms;
    skewed[3].coefficient = 3.0;  // weight of index 4 no longer that of index 0
    lpi::SparseExponential pade(n, skewed);
    assert_int_equal(static_cast<int>(pade.path()), static_cast<int>(lpi::ExpmPath::Pade));

    // An overflowing scaling is refused with x unchanged, the series of N
    // undone.
    const double huge[2] = {1e3, 1e200};
    double z[n];
    std::copy(x.begin(), x.end(), z);
    try {
        exponential.apply(huge, 1.0, z);
        fail_msg("an overflowing scaling was not refused");
    } catch (const lpi::Error &e) {
        assert_int_equal(e.status(), LPI_ERR_NONFINITE);
        assert_non_null(std::strstr(e.what(), "component"));
    }
    for (std::size_t i = 0; i < n; ++i) assert_true(z[i] == x[i]);
}

// Depth 1 (a shear: every moved index reads fixed ones only) is the sum
// x_v + sum_j (c_j s_pj) x_j, rounded as written, with s_p = t g_p shortened
// so that every c_j s_p is exact (see shortening_bits); with two terms at one
// position (the general sweep) it agrees to round-off.
void test_shear(void **) {
    const std::vector<lpi::SparseTerm> terms = {
        {1, 0, 0, 0.75}, {1, 3, 1, -1.25}, {2, 0, 1, 2.5}, {4, 3, 0, -0.5}, {4, 0, 1, 0.3}};
    lpi::SparseExponential shear(5, terms);
    assert_int_equal(static_cast<int>(shear.path()), static_cast<int>(lpi::ExpmPath::Nilpotent));
    assert_int_equal(shear.depth(), 1);
    const double g[2] = {0.7, -1.9}, t = 0.3;
    std::vector<double> x = {1.1, -0.4, 2.2, 0.9, -3.3}, y = x;
    shear.apply(g, t, y.data());
    std::vector<double> expected = x;
    // Parameter 0: 0.75 (binary 0.11) and -0.5, two bits; parameter 1: -1.25
    // and 2.5 (binary 101), three (0.3 has too many to be made exact).
    assert_int_equal(lpi::shortening_bits(0.75), 2);
    assert_int_equal(lpi::shortening_bits(-0.5), 0);
    assert_int_equal(lpi::shortening_bits(2.5), 3);
    assert_int_equal(lpi::shortening_bits(0.3), -1);
    const double s0 = lpi::shortened(t * g[0], 2), s1 = lpi::shortened(t * g[1], 3);
    assert_true(s0 != t * g[0] || s1 != t * g[1]);  // the shortening is exercised
    expected[1] = x[1] + ((0.75 * s0) * x[0] + (-1.25 * s1) * x[3]);
    expected[2] = x[2] + (2.5 * s1) * x[0];
    expected[4] = x[4] + ((0.3 * s1) * x[0] + (-0.5 * s0) * x[3]);
    for (std::size_t i = 0; i < x.size(); ++i) assert_true(y[i] == expected[i]);

    std::vector<lpi::SparseTerm> summed = terms;
    summed.push_back({2, 0, 0, 1.5});  // a second term at (2, 0)
    lpi::SparseExponential general(5, summed);
    assert_int_equal(general.depth(), 1);
    std::vector<double> z = x;
    general.apply(g, t, z.data());
    const double exact2 = x[2] + (2.5L * s1 + 1.5L * s0) * x[0];  // the flow for times s_p
    assert_true(std::fabs(z[2] - exact2) <= 4 * 2.2e-16 * std::fabs(exact2));
    assert_true(z[1] == y[1] && z[4] == y[4]);

    // A kick (one node, one term: applied without the loops) takes the bits
    // of the same term among others, zeros of either sign included.
    const std::vector<lpi::SparseTerm> kick_terms = {{2, 0, 1, 2.5}};
    lpi::SparseExponential kick(5, kick_terms);
    assert_int_equal(kick.depth(), 1);
    const double zeros[][2] = {{0.0, 0.0}, {-0.0, 0.0}, {0.0, -0.0}, {-0.0, -0.0}, {1.1, -0.0}, {-0.0, 2.2}};
    for (const auto &pair : zeros)
        for (double sign : {1.0, -1.0}) {
            std::vector<double> a = x, b = x;
            a[0] = b[0] = pair[0];
            a[2] = b[2] = pair[1];
            kick.apply(g, sign * t, a.data());
            shear.apply(g, sign * t, b.data());
            assert_true(std::memcmp(&a[2], &b[2], sizeof(double)) == 0);
            a[2] = b[2];
            for (std::size_t i = 0; i < x.size(); ++i)
                if (i != 1 && i != 4) assert_true(std::memcmp(&a[i], &b[i], sizeof(double)) == 0);
        }
}

// A component the flow contracts keeps its relative accuracy, however far:
// the eigencomponents of a hyperbolic plane, a contracting trace, a decaying
// 1x1 block, the scalings of the DiagonalSeries path and a contracted index
// of the Pade path that nothing grown feeds, each against its
// closed form in long double, component by component (a normwise error
// would let the small components go). Exponents are exact in double, so
// the reference is exact too.
void expect_components(const std::vector<double> &y, const std::vector<long double> &exact,
                       const char *what, double s) {
    double worst = 0.0;
    for (std::size_t i = 0; i < y.size(); ++i)
        worst = std::max(worst, static_cast<double>(std::fabs(y[i] - exact[i]) / std::fabs(exact[i])));
    std::printf("%s, s = %g: worst component rel. error %.2e\n", what, s, worst);
    assert_true(worst < 8 * 2.2e-16);
}

void test_contracted_components_keep_relative_accuracy(void **) {
    for (const double s : {0.5, 1.0, 4.0, 10.0, 30.0}) {
        const long double grow = std::exp(static_cast<long double>(s)), shrink = 1.0L / grow;
        // diag(-s, s) (the series' path) and [[0, s], [s, 0]] (the plane's) on its
        // two eigenvectors (1, -1), (1, 1).
        const std::vector<lpi::SparseTerm> diagonal = {{0, 0, 0, -1.0}, {1, 1, 0, 1.0}};
        const std::vector<lpi::SparseTerm> boost = {{0, 1, 0, 1.0}, {1, 0, 0, 1.0}};
        lpi::SparseExponential scaling(2, diagonal), hyperbolic(2, boost);
        assert_int_equal(static_cast<int>(scaling.path()), static_cast<int>(lpi::ExpmPath::DiagonalSeries));
        std::vector<double> y = {0.7, -1.3};
        scaling.apply(&s, 1.0, y.data());
        expect_components(y, {0.7L * shrink, -1.3L * grow}, "diag(-s, s)", s);
        y = {1.5, -1.5};
        hyperbolic.apply(&s, 1.0, y.data());
        expect_components(y, {1.5L * shrink, -1.5L * shrink}, "plane [[0, s], [s, 0]], contracted", s);
        y = {1.5, 1.5};
        hyperbolic.apply(&s, 1.0, y.data());
        expect_components(y, {1.5L * grow, 1.5L * grow}, "plane [[0, s], [s, 0]], grown", s);
        // A rotation by 1 contracted by e^-s: [[-s, 1], [-1, -s]].
        const std::vector<lpi::SparseTerm> spiral = {
            {0, 0, 0, -1.0}, {1, 1, 0, -1.0}, {0, 1, 1, 1.0}, {1, 0, 1, -1.0}};
        lpi::SparseExponential inward(2, spiral);
        const double g[2] = {s, 1.0};
        y = {0.8, 0.3};
        inward.apply(g, 1.0, y.data());
        const long double c = std::cos(1.0L), sn = std::sin(1.0L);
        expect_components(y, {shrink * (c * 0.8L + sn * 0.3L), shrink * (c * 0.3L - sn * 0.8L)},
                          "plane e^-s rotation", s);
        // A decaying 1x1 block.
        const std::vector<lpi::SparseTerm> loop = {{0, 0, 0, -2.0}};
        lpi::SparseExponential decay(1, loop);
        y = {3.0};
        decay.apply(&s, 1.0, y.data());
        expect_components(y, {3.0L * shrink * shrink}, "1x1 e^-2s", s);
        // DiagonalSeries: weights -4, -1, 2, 3 of s (one group, by powers).
        const std::vector<lpi::SparseTerm> weights = {
            {0, 0, 0, -4.0}, {1, 1, 0, -1.0}, {2, 2, 0, 2.0}, {3, 3, 0, 3.0}};
        lpi::SparseExponential series(4, weights);
        assert_int_equal(static_cast<int>(series.path()),
                         static_cast<int>(lpi::ExpmPath::DiagonalSeries));
        // Pade: a contracted index that feeds a growing one,
        // [[-s, 0, 0], [1, s, 0], [0, 1, 0]], lower triangular, and its
        // feeding scaled by B: the index, a component of its own, keeps the
        // relative accuracy of its exponential however large B (the block is
        // put in upper triangular order, so pivoting makes no fill-in for
        // the squarings to multiply; e^-20 came out as -6e-7 at B = 10, and
        // its entry is exp itself, not 2^s squarings of a Pade value).
        const std::vector<lpi::SparseTerm> triangular = {
            {0, 0, 0, -1.0}, {1, 1, 0, 1.0}, {1, 0, 1, 1.0}, {2, 1, 1, 1.0}};
        lpi::SparseExponential pade(3, triangular);
        assert_int_equal(static_cast<int>(pade.path()), static_cast<int>(lpi::ExpmPath::Pade));
        for (double B : {1.0, 10.0, 1e3, 1e6}) {
            const double feeding[2] = {s, B};
            y = {0.7, 0.2, -0.4};
            pade.apply(feeding, 1.0, y.data());
            const double fed = static_cast<double>(std::fabs(y[0] - 0.7L * shrink) / (0.7L * shrink));
            std::printf("Pade, contracted index feeding a growing one, s = %g, B = %g: rel. error %.2e\n", s,
                        B, fed);
            assert_true(fed < 2 * 2.2e-16);
        }
        const double t = 0.25, h = 4.0 * s;  // t h = s exactly
        y = {1.1, -0.6, 0.9, 2.5};
        if (s <= 10.0) {  // e^{3 s} overflows nothing; e^{-4 s} is far below 1
            series.apply(&h, t, y.data());
            expect_components(y,
                              {1.1L * std::pow(shrink, 4), -0.6L * shrink, 0.9L * grow * grow,
                               2.5L * grow * grow * grow},
                              "diagonal series weights -4 .. 3", s);
        }
    }
}

// A scaling past e^709 whose product is a double: exp(a) overflows, z e^a
// does not (a zero or tiny component), and the flow returns it (they were
// refused as overflows: inf times 0, inf times 1e-300). A product that does
// not fit is refused, x untouched.
void test_scalings_past_the_range_of_exp(void **) {
    const std::vector<lpi::SparseTerm> loop = {{0, 0, 0, 1.0}};
    lpi::SparseExponential grow(1, loop);
    assert_int_equal(static_cast<int>(grow.path()), static_cast<int>(lpi::ExpmPath::DiagonalSeries));
    const double a = 800.0;
    std::vector<double> y = {1e-300};
    grow.apply(&a, 1.0, y.data());
    const long double exact = 1e-300L * std::exp(800.0L);
    const double error = static_cast<double>(std::fabs(y[0] - exact) / exact);
    std::printf("1x1 diagonal, 1e-300 e^800: %.17g, rel. error %.2e\n", y[0], error);
    assert_true(error < 4 * 2.2e-16);
    y = {0.0};
    grow.apply(&a, 1.0, y.data());
    assert_true(y[0] == 0.0);
    y = {1.0};
    try {
        grow.apply(&a, 1.0, y.data());
        fail_msg("e^800 was not refused");
    } catch (const lpi::Error &e) {
        assert_int_equal(e.status(), LPI_ERR_NONFINITE);
    }
    assert_true(y[0] == 1.0);
    // DiagonalSeries, weights 1, 1, 8 and a shear: [[1, 0, 0], [1, 1, 0],
    // [0, 0, 8]] times 100 on (1, 1, 0) is (e^100, 101 e^100, 0).
    const std::vector<lpi::SparseTerm> graded = {
        {0, 0, 0, 1.0}, {1, 1, 0, 1.0}, {1, 0, 0, 1.0}, {2, 2, 0, 8.0}};
    lpi::SparseExponential series(3, graded);
    assert_int_equal(static_cast<int>(series.path()), static_cast<int>(lpi::ExpmPath::DiagonalSeries));
    const double g = 100.0;
    y = {1.0, 1.0, 0.0};
    series.apply(&g, 1.0, y.data());
    const long double e100 = std::exp(100.0L);
    assert_true(std::fabs(y[0] - e100) / e100 < 4 * 2.2e-16);
    assert_true(std::fabs(y[1] - 101.0L * e100) / (101.0L * e100) < 8 * 2.2e-16);
    assert_true(y[2] == 0.0);

    // The 2x2 plane: real eigenvalues +-720 ([[a, 0], [c, -a]], the flow of
    // sl(2)'s h), and a rotation under e^720 ([[a, b], [-b, a]]). A component
    // that is 0 in the growing direction came out NaN (inf times 0) and was
    // refused, naming the component that shrinks.
    const std::vector<lpi::SparseTerm> hyperbolic_terms = {{0, 0, 0, 1.0}, {1, 1, 0, -1.0}, {1, 0, 1, 1.0}};
    lpi::SparseExponential hyperbolic(2, hyperbolic_terms);
    assert_int_equal(static_cast<int>(hyperbolic.path()), static_cast<int>(lpi::ExpmPath::Plane));
    const double ac[2] = {720.0, 1.0};
    const long double ea = std::exp(720.0L), e_minus_a = std::exp(-720.0L);
    auto close = [](double got, long double exact, double ulps) {
        return std::fabs(got - exact) <= ulps * 2.2e-16 * std::fabs(exact);
    };
    y = {0.0, 1.0};
    hyperbolic.apply(ac, 1.0, y.data());
    assert_true(y[0] == 0.0);
    assert_true(std::fabs(y[1] - e_minus_a) <= 4.95e-324);  // subnormal: to the last one
    y = {1e-300, 0.0};
    hyperbolic.apply(ac, 1.0, y.data());
    assert_true(close(y[0], 1e-300L * ea, 4));
    assert_true(close(y[1], 1e-300L * (ea - e_minus_a) / 1440.0L, 8));
    const std::vector<lpi::SparseTerm> spiral_terms = {
        {0, 0, 0, 1.0}, {1, 1, 0, 1.0}, {0, 1, 1, 1.0}, {1, 0, 1, -1.0}};
    lpi::SparseExponential spiral(2, spiral_terms);
    assert_int_equal(static_cast<int>(spiral.path()), static_cast<int>(lpi::ExpmPath::Plane));
    y = {1e-300, 0.0};
    spiral.apply(ac, 1.0, y.data());
    assert_true(close(y[0], 1e-300L * ea * std::cos(1.0L), 8));
    assert_true(close(y[1], -1e-300L * ea * std::sin(1.0L), 8));
    // Just below ln DBL_MAX, e^tau inside exp(tA) - I overflowed where the
    // flow of a small x does not (refused at 709.5, returned at 712).
    const double near_range[2] = {709.5, 1.0};
    const long double e709 = std::exp(709.5L);
    y = {1e-300, 0.0};
    spiral.apply(near_range, 1.0, y.data());
    assert_true(close(y[0], 1e-300L * e709 * std::cos(1.0L), 8));
    assert_true(close(y[1], -1e-300L * e709 * std::sin(1.0L), 8));
    y = {1.0, 0.0};  // e^720 itself: refused, x untouched
    try {
        spiral.apply(ac, 1.0, y.data());
        fail_msg("e^720 was not refused");
    } catch (const lpi::Error &e) {
        assert_int_equal(e.status(), LPI_ERR_NONFINITE);
    }
    assert_true(y[0] == 1.0 && y[1] == 0.0);
}

// The size of an n x n matrix is counted without wrapping: a dimension whose
// bytes overflow a size_t is refused (LPI_ERR_NO_MEMORY), not allocated small.
void test_square_entries_refuse_overflow(void **) {
    assert_int_equal(lpi::square_entries(0, "matrix"), 0);
    assert_int_equal(lpi::square_entries(3, "matrix"), 9);
    const std::size_t largest = static_cast<std::size_t>(
        std::sqrt(static_cast<double>(SIZE_MAX / sizeof(double))));  // rounded down or near
    std::size_t fits = largest;
    while (fits > SIZE_MAX / sizeof(double) / fits) --fits;
    assert_int_equal(lpi::square_entries(fits, "matrix"), fits * fits);
    for (std::size_t n : {fits + 1, std::size_t{1} << 32, SIZE_MAX / 2, SIZE_MAX}) {
        try {
            lpi::square_entries(n, "matrix");
            fail_msg("square_entries(%zu) did not refuse", n);
        } catch (const lpi::Error &e) {
            assert_int_equal(e.status(), LPI_ERR_NO_MEMORY);
        }
    }
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_general_matrices),
        cmocka_unit_test(test_skew_matrices),
        cmocka_unit_test(test_nilpotent_matrices),
        cmocka_unit_test(test_sparse_nilpotent_scales_with_nonzeros),
        cmocka_unit_test(test_plane_closed_form),
        cmocka_unit_test(test_rotation_takes_the_plane_bits),
        cmocka_unit_test(test_refusals_leave_x_unchanged),
        cmocka_unit_test(test_shear),
        cmocka_unit_test(test_diagonal_series),
        cmocka_unit_test(test_contracted_components_keep_relative_accuracy),
        cmocka_unit_test(test_deep_series_and_summed_terms),
        cmocka_unit_test(test_scalings_past_the_range_of_exp),
        cmocka_unit_test(test_square_entries_refuse_overflow),
    };
    return lpi_run_tests(tests);
}
