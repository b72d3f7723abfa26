/* Stiff and extreme cases: what must hold at any step size and scale.
 * Poisson methods keep every Casimir to round-off and never turn finite
 * input into NaN; a method that blows up (rk4 beyond its stability limit,
 * implicit midpoint not converging, a generic flow beyond what scaling and
 * squaring can do, an exact flow that overflows) returns its status with the
 * state rolled back bit for bit. The full matrix is `lpi stress`. */
#include <float.h>

#include "lpi_test.h"

static const double kPi = 3.14159265358979323846;

static int is_poisson(int m) { return lpi_method_is_poisson(m) == 1; }

static int all_finite(const double *x, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* Every Poisson method, steps from 1e-8 to 1e3 periods: status OK, finite
 * state, Casimirs to round-off (relative drift <= 1e-15 per exact flow, at
 * any angle: generic so(3)'s rotations take their shears from sin and cos,
 * with no scaling and squaring to grow the error with ||tA||). */
static void check_poisson_methods(lpi_system *sys, const double *x0, double period,
                                  int64_t steps, double floor) {
    const double factors[] = {1e-8, 1e-3, 0.1, 1.0, 1e3};
    const size_t n = lpi_dim(sys), nc = lpi_casimir_count(sys);
    double c0[64], c[64], x[4096];
    assert_true(nc <= 64 && n <= 4096);
    for (int m = 0; m < lpi_method_count(); ++m) {
        if (!is_poisson(m)) continue;
        for (size_t f = 0; f < sizeof factors / sizeof factors[0]; ++f) {
            assert_int_equal(lpi_set_method(sys, lpi_method_name(m)), LPI_OK);
            assert_int_equal(lpi_set_state(sys, x0, n), LPI_OK);
            assert_int_equal(lpi_casimirs(sys, c0, nc), LPI_OK);
            double scale = 0;
            for (size_t q = 0; q < nc; ++q) scale = fmax(scale, fabs(c0[q]));
            const int status = lpi_step(sys, factors[f] * period, steps);
            if (status != LPI_OK)
                fail_msg("%s at dt = %g periods: %s (%s)", lpi_method_name(m), factors[f],
                         lpi_status_name(status), lpi_last_error(sys));
            assert_int_equal(lpi_get_state(sys, x, n), LPI_OK);
            assert_true(all_finite(x, n));
            assert_int_equal(lpi_casimirs(sys, c, nc), LPI_OK);
            size_t flows = 0;
            assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
            double drift = 0;
            for (size_t q = 0; q < nc; ++q) drift = fmax(drift, fabs(c[q] - c0[q]) / scale);
            const double tolerance = floor + 1e-15 * (double)flows * (double)steps;
            if (!(drift <= tolerance))
                fail_msg("%s at dt = %g periods: Casimir drift %.2e > %.2e", lpi_method_name(m),
                         factors[f], drift, tolerance);
        }
    }
}

static void test_rigid_body_every_step_size(void **state) {
    (void)state;
    struct { double I[3], m[3]; } bodies[] = {
        {{1.0, 1e4, 1e8}, {1.0, 1.0, 1.0}},                 /* inertia ratio 1e8 */
        {{2.0 * (1.0 + 1e-12), 2.0, 3.0}, {1.0, 0.5, -0.3}}, /* nearly symmetric */
        {{1.0, 2.0, 3.0}, {1e-10, 1.0, 1e-10}},             /* unstable middle axis */
        {{1.0, 2.0, 3.0}, {1.0, 0.0, 1.7320508075688772}},  /* separatrix */
    };
    for (size_t b = 0; b < sizeof bodies / sizeof bodies[0]; ++b) {
        lpi_system *sys = NULL;
        assert_int_equal(lpi_rigid_body_create(&sys, bodies[b].I[0], bodies[b].I[1], bodies[b].I[2]),
                         LPI_OK);
        const double *m = bodies[b].m;
        const double norm = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        const double period = 2 * kPi * fmin(bodies[b].I[0], fmin(bodies[b].I[1], bodies[b].I[2])) / norm;
        check_poisson_methods(sys, m, period, 50, 1e-15);
        lpi_destroy(sys);
    }
}

/* Absurd steps: the rotation angle reaches 1e300 (reduced exactly by sin);
 * only a flow time dt * weight that overflows fails, and then cleanly. */
static void test_rigid_body_absurd_steps(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    double x[3];
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 1e300, 1), LPI_OK);
    assert_int_equal(lpi_get_state(sys, x, 3), LPI_OK);
    assert_true(all_finite(x, 3));
    assert_true(fabs((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / 1.34 - 1) < 1e-15);
    assert_int_equal(lpi_set_method(sys, "yoshida-8"), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1.5e308, 1), LPI_ERR_OVERFLOW, "lpi_step");
    lpi_destroy(sys);
}

static void test_pendulum_near_separatrix(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_pendulum_create(&sys), LPI_OK);
    const double x0[3] = {0.0, -1.0, sqrt(4.0 - 2e-10)};
    check_poisson_methods(sys, x0, 2 * kPi, 50, 1e-15);
    lpi_destroy(sys);
}

static lpi_system *sine_euler(int N, unsigned seed) {
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, N) != LPI_OK) return NULL;
    const size_t n = 2 * (size_t)N * N;
    double w[2 * 49];
    assert_true(n <= sizeof w / sizeof w[0]);
    memset(w, 0, sizeof w);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int ma = (N - a) % N, mb = (N - b) % N;
            if (a * N + b >= ma * N + mb) continue;
            seed = seed * 1664525u + 1013904223u;
            const double re = (double)(seed >> 8) / 16777216.0 - 0.5;
            seed = seed * 1664525u + 1013904223u;
            const double im = (double)(seed >> 8) / 16777216.0 - 0.5;
            w[2 * (a * N + b)] = re, w[2 * (a * N + b) + 1] = im;
            w[2 * (ma * N + mb)] = re, w[2 * (ma * N + mb) + 1] = -im;
        }
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, n), LPI_OK);
    return sys;
}

static void test_sine_euler_every_step_size(void **state) {
    (void)state;
    for (int N = 3; N <= 7; N += 4) {
        lpi_system *sys = sine_euler(N, 99);
        if (!sys) LPI_SKIP("built without FFTW: no sine-Euler system");
        double x0[2 * 49];
        const size_t n = lpi_dim(sys);
        assert_int_equal(lpi_get_state(sys, x0, n), LPI_OK);
        double c[7];
        if (lpi_casimirs(sys, c, lpi_casimir_count(sys)) == LPI_ERR_UNSUPPORTED) {
            lpi_destroy(sys);
            LPI_SKIP("built without LAPACK: no Casimir spectrum to check");
        }
        check_poisson_methods(sys, x0, 1.0, 10, 1e-15 * N);
        lpi_destroy(sys);
    }
}

/* rk4 beyond its stability limit and implicit midpoint beyond the reach of
 * its iteration: their statuses, the state bit for bit as before the call. */
static void test_baselines_fail_cleanly(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 7), LPI_OK); /* a history to keep */
    assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1e3, 100), LPI_ERR_NONFINITE, "lpi_step");
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1e3, 100), LPI_ERR_NO_CONVERGENCE, "lpi_step");
    lpi_destroy(sys);
}

/* The same on sine-Euler. */
static void test_sine_euler_baselines_fail_cleanly(void **state) {
    (void)state;
    lpi_system *se = sine_euler(7, 5);
    if (!se) LPI_SKIP("built without FFTW: no sine-Euler system");
    assert_int_equal(lpi_step(se, 0.05, 3), LPI_OK);
    assert_int_equal(lpi_set_method(se, "rk4"), LPI_OK);
    LPI_ASSERT_FAILS(se, lpi_step(se, 1e3, 20), LPI_ERR_NONFINITE, "lpi_step");
    assert_int_equal(lpi_set_method(se, "implicit-midpoint"), LPI_OK);
    LPI_ASSERT_FAILS(se, lpi_step(se, 1e3, 20), LPI_ERR_NO_CONVERGENCE, "lpi_step");
    lpi_destroy(se);
}

/* so(3) with every structure constant times `scale`. */
static const double kInertia[3] = {1.0, 2.0, 3.0};
static int norm2_casimir(size_t dim, const double *x, double *out, void *user) {
    (void)user;
    *out = 0;
    for (size_t q = 0; q < dim; ++q) *out += x[q] * x[q];
    return 0;
}
static lpi_system *generic_so3(double scale) {
    static const int32_t i[] = {0, 0, 1}, j[] = {1, 2, 2}, k[] = {2, 1, 0};
    const double c[] = {-scale, scale, -scale};
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    for (int32_t a = 0; a < 3; ++a)
        assert_int_equal(lpi_add_piece(sys, 1, &a, lpi_test_axis_gradient, lpi_test_axis_energy, (void *)&kInertia[a]),
                         LPI_OK);
    assert_int_equal(lpi_add_casimir(sys, norm2_casimir, NULL), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    return sys;
}

/* Large and tiny structure constants: exact at steps up to a period (the
 * Pade path's error grows like 2^squarings, so the bound is per ||tA||);
 * a flow needing more than 2^32 squarings is refused, not returned as garbage. */
static void test_generic_extreme_constants(void **state) {
    (void)state;
    const double scales[] = {1e100, 1e-100};
    for (int s = 0; s < 2; ++s) {
        lpi_system *sys = generic_so3(scales[s]);
        const double m[3] = {1.0, 0.5, -0.3};
        check_poisson_methods(sys, m, 2 * kPi / scales[s], 20, 1e-15);
        lpi_destroy(sys);
    }
    lpi_system *sys = generic_so3(1e100);
    assert_int_equal(lpi_step(sys, 1e-101, 3), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1.0, 1), LPI_ERR_INVALID, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "squarings"));
    assert_non_null(strstr(lpi_last_error(sys), "piece 0"));
    lpi_destroy(sys);
}

/* Moments: I and K are never NaN from a finite state; a value that is not
 * representable is LPI_ERR_NONFINITE naming it; squeezed entries
 * 1e-150..1e150 give their exact invariants. */
static void moments_state(lpi_system *sys, double squeeze, double size) {
    const double l2 = squeeze * squeeze;
    const double x[8] = {size * l2, 0.0, size / l2, 3 * size * size * l2 * l2, 0.0, size * size,
                         0.0, 3 * size * size / (l2 * l2)};
    assert_int_equal(lpi_set_state(sys, x, 8), LPI_OK);
}
static int p_h(double u, double *out, void *user) {
    (void)user;
    *out = 0.02 * u + 0.01 * u * u;
    return 0;
}
static int p_dh(double u, double *out, void *user) {
    (void)user;
    *out = 0.02 + 0.02 * u;
    return 0;
}

static void test_moments_extreme_entries(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    double c[2];
    assert_int_equal(lpi_moments_create(&sys), LPI_OK);
    moments_state(sys, pow(10.0, 37.5), 1.0);
    assert_int_equal(lpi_casimirs(sys, c, 2), LPI_OK);
    assert_true(fabs(c[0] - 12) < 1e-13 && fabs(c[1] - 8) < 1e-13);
    moments_state(sys, 1.0, 1e60); /* K = 8e360 overflows, its terms do too */
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, c, 2), LPI_ERR_OVERFLOW, "lpi_casimirs");
    assert_non_null(strstr(lpi_last_error(sys), "Casimir 1 (K"));
    moments_state(sys, 1.0, 1e50); /* I = 1.2e201, K = 8e300: still representable */
    assert_int_equal(lpi_casimirs(sys, c, 2), LPI_OK);
    assert_true(fabs(c[0] / 12e200 - 1) < 1e-14 && fabs(c[1] / 8e300 - 1) < 1e-14);
    moments_state(sys, 1.0, 1e75);
    /* The product piece's exact flow overflows at this scale: NONFINITE
     * (not blamed on the callbacks), state unchanged. */
    assert_int_equal(lpi_moments_add_product_piece(sys, p_h, p_dh, NULL), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1.0, 1), LPI_ERR_NONFINITE, "lpi_step");
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rigid_body_every_step_size),
        cmocka_unit_test(test_rigid_body_absurd_steps),
        cmocka_unit_test(test_pendulum_near_separatrix),
        cmocka_unit_test(test_sine_euler_every_step_size),
        cmocka_unit_test(test_baselines_fail_cleanly),
        cmocka_unit_test(test_sine_euler_baselines_fail_cleanly),
        cmocka_unit_test(test_generic_extreme_constants),
        cmocka_unit_test(test_moments_extreme_entries),
    };
    return lpi_run_tests(tests);
}
