// The compiled flows of the moment algebra's linear pieces
// (src/models/compiled_flows.hpp) against the general plan: for every abelian
// index set, a moments system (compiled flow where there is one) and a
// generic system declared with the same structure constants (always the
// general SparseExponential) take the same flow, and must agree to the bit;
// which index sets have a compiled flow; and a flow that overflows is refused
// with x unchanged.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

// Before cmocka.h (through lpi_test.h), whose fail() macro would rewrite lpi::fail.
#include "core/error.hpp"
#include "lpi_test.h"

#include "core/cpu_features.hpp"
#include "models/compiled_flows.hpp"
#include "models/moments_algebra.hpp"

// `call` returns LPI_OK, or the test fails with the handle's message.
#define EXPECT_OK(sys, call)                                                                   \
    do {                                                                                       \
        const int status_ = (call);                                                            \
        if (status_ != LPI_OK) fail_msg("%s: %s", #call, lpi_last_error(sys));               \
    } while (0)

namespace {

// H = sum_p (alpha_p x_p + beta_p x_p^2 / 2), alpha and beta from user.
struct Quadratic {
    double alpha[8], beta[8];
};
int quadratic_gradient(size_t n, const double *x, double *g, void *user) {
    const Quadratic *q = static_cast<const Quadratic *>(user);
    for (size_t p = 0; p < n; ++p) g[p] = q->alpha[p] + q->beta[p] * x[p];
    return 0;
}
// A gradient of 1 in each index that records (in user) whether it was ever
// handed a non-finite coordinate.
int watching_gradient(size_t n, const double *x, double *g, void *user) {
    for (size_t p = 0; p < n; ++p) {
        if (!std::isfinite(x[p])) *static_cast<int *>(user) = 1;
        g[p] = 1.0;
    }
    return 0;
}
int quadratic_energy(size_t n, const double *x, double *h, void *user) {
    const Quadratic *q = static_cast<const Quadratic *>(user);
    *h = 0.0;
    for (size_t p = 0; p < n; ++p) *h += q->alpha[p] * x[p] + 0.5 * q->beta[p] * x[p] * x[p];
    return 0;
}

bool abelian(unsigned mask) {
    for (const lpi::Bracket &b : lpi::MomentAlgebra::brackets)
        if ((mask >> b.i & 1u) && (mask >> b.j & 1u)) return false;
    return true;
}

lpi_system *moments_generic_twin() {
    constexpr lpi::BracketColumns<lpi::MomentAlgebra> b;
    lpi_system *sys = nullptr;
    EXPECT_OK(NULL, lpi_generic_create(&sys, 8, b.count, b.i, b.j, b.k, b.c));
    return sys;
}

// One Lie-Trotter step of the single piece on `indices` from x, in a
// moments system and in its generic twin.
void flow_both(const std::vector<int32_t> &indices, Quadratic &h, const double *x, double dt,
               double *moments_out, double *generic_out) {
    lpi_system *moments = nullptr, *generic = moments_generic_twin();
    EXPECT_OK(NULL, lpi_moments_create(&moments));
    for (lpi_system *sys : {moments, generic}) {
        EXPECT_OK(sys, lpi_add_piece(sys, indices.size(), indices.data(), quadratic_gradient,
                                         quadratic_energy, &h));
        EXPECT_OK(sys, lpi_set_method(sys, "lie-trotter"));
        EXPECT_OK(sys, lpi_set_state(sys, x, 8));
        EXPECT_OK(sys, lpi_step(sys, dt, 1));
    }
    EXPECT_OK(moments, lpi_get_state(moments, moments_out, 8));
    EXPECT_OK(generic, lpi_get_state(generic, generic_out, 8));
    lpi_destroy(moments);
    lpi_destroy(generic);
}

void test_compiled_flows_match_the_general_plan(void **) {
    std::mt19937_64 rng(18);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    int abelian_sets = 0, compiled = 0;
    for (unsigned mask = 1; mask < 256; ++mask) {
        if (!abelian(mask)) continue;
        ++abelian_sets;
        if (lpi::moment_piece_flow(mask)) ++compiled;
        std::vector<int32_t> indices;
        for (int32_t j = 0; j < 8; ++j)
            if (mask >> j & 1u) indices.push_back(j);
        if (mask % 3 == 0) std::swap(indices.front(), indices.back());  // any order of the set
        // Draws 3 .. 8 put zeros of either sign among the moments and the
        // gradients' terms: the sums of products may then be zeros of
        // either sign, which must reach no result in either plan.
        for (int draw = 0; draw < 9; ++draw) {
            const auto value = [&] {
                const double v = u(rng);
                if (draw < 3 || std::fabs(v) > 0.75) return v;
                return v < 0 ? -0.0 : 0.0;
            };
            Quadratic h;
            for (int p = 0; p < 8; ++p) h.alpha[p] = value(), h.beta[p] = value();
            double x[8], a[8], b[8];
            for (double &v : x) v = value();
            flow_both(indices, h, x, draw < 3 ? 0.37 * (draw + 1) : (draw % 2 ? -0.37 : 0.37) * (draw - 2), a, b);
            for (int q = 0; q < 8; ++q)
                if (std::memcmp(&a[q], &b[q], sizeof(double)) != 0)
                    fail_msg("index set 0x%02x, draw %d: component %d is %.17g compiled, %.17g "
                             "general", mask, draw, q, a[q], b[q]);
        }
    }
    // Far contractions (the scalings of <qp> by e^{-4 x 5}): both take the
    // exponential itself there (scaled_by_exponential), still the same bits.
    for (const std::vector<int32_t> &indices : {std::vector<int32_t>{1}, std::vector<int32_t>{1, 5}}) {
        Quadratic h = {};
        h.alpha[0] = 1.0;
        const double x[8] = {1.0, 0.2, 0.5, 2.5, 0.6, 0.6, 0.3, 0.8};
        double a[8], b[8];
        flow_both(indices, h, x, 5.0, a, b);
        for (int q = 0; q < 8; ++q)
            if (std::memcmp(&a[q], &b[q], sizeof(double)) != 0)
                fail_msg("squeeze on %zu indices, t = 5: component %d is %.17g compiled, %.17g "
                         "general", indices.size(), q, a[q], b[q]);
        assert_true(std::fabs(a[7] - 0.8 * std::exp(-20.0)) < 4 * 2.2e-16 * 0.8 * std::exp(-20.0));
    }
    std::printf("moment algebra: %d abelian index sets, %d with a compiled flow, all bit for bit "
                "equal to the general plan\n", abelian_sets, compiled);
    // The paper's pieces V(x1, x4) and T(x3, x8) (0-based {0, 3}, {2, 7})
    // and every set of fourth moments are nilpotent; <qp> scales q and p
    // ({1}, {1, 5}: a diagonal, by weight, that commutes with the rest).
    // Every abelian set is compiled; a set that is not abelian has no flow.
    assert_non_null(lpi::moment_piece_flow(0x09));
    assert_non_null(lpi::moment_piece_flow(0x84));
    for (unsigned quartics = 1; quartics < 32; ++quartics)
        assert_non_null(lpi::moment_piece_flow(quartics << 3));
    assert_non_null(lpi::moment_piece_flow(0x02));
    assert_non_null(lpi::moment_piece_flow(0x22));
    assert_null(lpi::moment_piece_flow(0x03));  // {x0, x1} is not abelian
    assert_int_equal(compiled, abelian_sets);
    assert_int_equal(abelian_sets, 37);
}

// The flows compiled for the baseline and for FMA (chosen at run time) give
// the same bits: fma rounds once, as an instruction or in libm. Near the
// identity and far from it (each takes its own instantiation), with the
// gradient's terms of either sign.
void test_baseline_and_fma_flows_agree(void **) {
    static constexpr lpi::compiled::Table<lpi::MomentAlgebra> table;
    if (!lpi::cpu_has_fma()) LPI_SKIP("this processor has no FMA: only the baseline flows run here");
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    int flows = 0;
    for (unsigned mask = 1; mask < 256; ++mask) {
        if (!table.flows[mask]) continue;
        assert_non_null(table.fma_flows[mask]);
        for (int draw = 0; draw < 200; ++draw) {
            double g[8], x[8], a[8], b[8];
            for (double &v : g) v = u(rng);
            for (double &v : x) v = u(rng);
            const double t = draw % 2 ? 0.01 * u(rng) : 4.0 * u(rng);
            std::memcpy(a, x, sizeof x);
            std::memcpy(b, x, sizeof x);
            assert_int_equal(table.flows[mask](g, t, a), table.fma_flows[mask](g, t, b));
            if (std::memcmp(a, b, sizeof a) != 0)
                fail_msg("index set 0x%02x, t = %g: the baseline and FMA flows differ", mask, t);
            ++flows;
        }
    }
    std::printf("%d flows of the baseline and FMA instantiations, bit for bit equal\n", flows);
}

// A compiled flow that overflows is refused as the general one is: x
// unchanged to the bit, LPI_ERR_NONFINITE naming the piece and a component.
void test_compiled_flow_refuses_overflow(void **) {
    lpi_system *sys = nullptr;
    EXPECT_OK(NULL, lpi_moments_create(&sys));
    Quadratic h = {};
    h.alpha[0] = 1e300;
    const int32_t indices[2] = {0, 3};
    EXPECT_OK(sys, lpi_add_piece(sys, 2, indices, quadratic_gradient, quadratic_energy, &h));
    EXPECT_OK(sys, lpi_set_method(sys, "lie-trotter"));
    const double x[8] = {1.0, 0.2, 0.5, 2.5, 0.6, 0.6, 0.3, 0.8};
    EXPECT_OK(sys, lpi_set_state(sys, x, 8));
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1e10, 1), LPI_ERR_NONFINITE, "exact flow overflows (component");
    assert_non_null(std::strstr(lpi_last_error(sys), "piece 0"));
    double after[8];
    EXPECT_OK(sys, lpi_get_state(sys, after, 8));
    assert_memory_equal(after, x, sizeof x);
    lpi_destroy(sys);

    // Every increment finite, x2 + its increment not (-1e308 - 1e308): the
    // new value is what is checked, and the next piece never sees it (it
    // was written, and the next piece's callback was handed -inf).
    EXPECT_OK(NULL, lpi_moments_create(&sys));
    Quadratic steep = {};
    steep.alpha[0] = 1e-300, steep.alpha[1] = 1e300;  // x2' = -2a x1 - 4b x4 = -1e308
    EXPECT_OK(sys, lpi_add_piece(sys, 2, indices, quadratic_gradient, quadratic_energy, &steep));
    int saw_nonfinite = 0;
    const int32_t kinetic[2] = {2, 7};
    EXPECT_OK(sys, lpi_add_piece(sys, 2, kinetic, watching_gradient, quadratic_energy, &saw_nonfinite));
    EXPECT_OK(sys, lpi_set_method(sys, "lie-trotter"));
    const double edge[8] = {1.0, -1e308, 0.5, 2.5e7, 0.0, 0.6, 0.3, 0.8};
    EXPECT_OK(sys, lpi_set_state(sys, edge, 8));
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1.0, 1), LPI_ERR_NONFINITE, "exact flow overflows (component 1)");
    assert_false(saw_nonfinite);
    lpi_destroy(sys);

    // A scaling near the identity (<qp> grows x1 by e^0.2) past the largest
    // double: the compiled flow tests y there only where some |y| exceeds
    // half the largest double, the general plan every new value.
    Quadratic squeeze = {};
    squeeze.alpha[0] = 0.1;
    const int32_t qp = 1;
    const double big[8] = {1.7e308, 0.2, 0.5, 2.5, 0.6, 0.6, 0.3, 0.8};
    for (int generic = 0; generic < 2; ++generic) {
        sys = nullptr;
        if (generic) sys = moments_generic_twin();
        else EXPECT_OK(NULL, lpi_moments_create(&sys));
        EXPECT_OK(sys, lpi_add_piece(sys, 1, &qp, quadratic_gradient, quadratic_energy, &squeeze));
        EXPECT_OK(sys, lpi_set_method(sys, "lie-trotter"));
        EXPECT_OK(sys, lpi_set_state(sys, big, 8));
        LPI_ASSERT_FAILS(sys, lpi_step(sys, 1.0, 1), LPI_ERR_NONFINITE, "exact flow overflows (component 0)");
        EXPECT_OK(sys, lpi_get_state(sys, after, 8));
        assert_memory_equal(after, big, sizeof big);
        lpi_destroy(sys);
    }
}

// New values each finite but whose sum overflows (the flows test them all
// at once by that sum): the flow goes on, bit for bit the general plan's.
void test_compiled_flow_takes_values_near_the_largest(void **) {
    const double x[8] = {1.0, 0.9e308, 0.9e308, 2.5, 0.9e308, 0.9e308, 0.9e308, 0.9e308};
    for (const std::vector<int32_t> &indices : {std::vector<int32_t>{0, 3}, std::vector<int32_t>{1}}) {
        Quadratic h = {};
        h.alpha[0] = 1e-3;
        double a[8], b[8];
        flow_both(indices, h, x, 0.01, a, b);
        for (int q = 0; q < 8; ++q) {
            assert_true(std::isfinite(a[q]));
            if (std::memcmp(&a[q], &b[q], sizeof(double)) != 0)
                fail_msg("piece on %zu indices: component %d is %.17g compiled, %.17g general",
                         indices.size(), q, a[q], b[q]);
        }
        assert_true(a[2] != x[2] || a[0] != x[0]);  // the flow moved the state
    }
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_compiled_flows_match_the_general_plan),
        cmocka_unit_test(test_baseline_and_fma_flows_agree),
        cmocka_unit_test(test_compiled_flow_refuses_overflow),
        cmocka_unit_test(test_compiled_flow_takes_values_near_the_largest),
    };
    return lpi_run_tests(tests);
}
