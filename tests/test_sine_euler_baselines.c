/* The sine-Euler matrix-form baselines: isomp (isospectral midpoint) and
 * rk4-matrix converge at their orders against a fine splitting run;
 * rk4-matrix and direct-eq5 agree with rk4 on the modes to round-off (RK4 is
 * the same map in any linear coordinates, and eq. 5 is the same field however
 * it is summed); isomp keeps the spectrum to its iteration tolerance where
 * rk4-matrix drifts; non-convergence is reported and rolled back; other
 * systems refuse these methods. */
#include <float.h>

#include "lpi_test.h"

/* What this build has (set in main): sine-Euler needs FFTW; isomp and
 * rk4-matrix need BLAS/LAPACK, direct-eq5 does not. */
static int have_fftw, have_blas;

static void require_fftw(void) {
    if (!have_fftw) LPI_SKIP("built without FFTW: no sine-Euler system");
}
static void require_blas(void) {
    require_fftw();
    if (!have_blas) LPI_SKIP("built without BLAS/LAPACK: no isomp, no rk4-matrix");
}

/* A reproducible Hermitian field, w_0 = 0.3, amplitude ~ 2/(1 + |m|^2). */
static void random_field(int N, unsigned seed, double *w) {
    lpi_test_random_field(N, 0xD1B54A32D192ED03ull ^ seed, 2.0, w);
    w[0] = 0.3;
}

static lpi_system *sine_euler(int N, const double *w) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_sine_euler_create(&sys, N), LPI_OK);
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * (size_t)N * N), LPI_OK);
    return sys;
}

static double max_abs_diff(const double *a, const double *b, size_t n) {
    double d = 0;
    for (size_t i = 0; i < n; ++i) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

static double max_abs(const double *a, size_t n) {
    double d = 0;
    for (size_t i = 0; i < n; ++i) d = fmax(d, fabs(a[i]));
    return d;
}

/* The modes after `steps` steps of `method` over time T from w0. */
static void run(int N, const double *w0, const char *method, double T, int64_t steps, double *out) {
    lpi_system *sys = sine_euler(N, w0);
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    const int status = lpi_step(sys, T / (double)steps, steps);
    if (status != LPI_OK) fail_msg("%s: %s", method, lpi_last_error(sys));
    assert_int_equal(lpi_sine_euler_get_modes(sys, out, 2 * (size_t)N * N), LPI_OK);
    lpi_destroy(sys);
}

static int method_index(const char *name) {
    for (int i = 0; i < lpi_method_count(); ++i)
        if (strcmp(lpi_method_name(i), name) == 0) return i;
    fail_msg("method %s not registered", name);
    return -1;
}

/* ---- registry and applicability --------------------------------------------- */

static void test_registry_rows(void **state) {
    (void)state;
    const struct { const char *name; int order; } rows[] = {
        {"isomp", 2}, {"rk4-matrix", 4}, {"direct-eq5", 4}};
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
        const int k = method_index(rows[i].name);
        assert_int_equal(lpi_method_order(k), rows[i].order);
        assert_int_equal(lpi_method_stages(k), 1);
        /* Baselines: isomp keeps the Casimirs only to its iteration tolerance. */
        assert_int_equal(lpi_method_is_poisson(k), 0);
        assert_non_null(strstr(lpi_method_reference(k), "sine-Euler"));
    }
    assert_non_null(strstr(lpi_method_reference(method_index("isomp")), "Modin"));
}

static void test_unsupported_elsewhere(void **state) {
    (void)state;
    const char *methods[] = {"isomp", "rk4-matrix", "direct-eq5"};
    lpi_system *systems[2] = {NULL, NULL};
    assert_int_equal(lpi_rigid_body_create(&systems[0], 1.0, 2.0, 3.0), LPI_OK);
    assert_int_equal(lpi_pendulum_create(&systems[1]), LPI_OK);
    const double x[3] = {1.0, 0.5, -0.3};
    for (int s = 0; s < 2; ++s) {
        lpi_system *sys = systems[s];
        assert_int_equal(lpi_set_state(sys, x, 3), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "triple-jump-4"), LPI_OK);
        for (size_t i = 0; i < sizeof methods / sizeof methods[0]; ++i) {
            LPI_ASSERT_FAILS(sys, lpi_set_method(sys, methods[i]), LPI_ERR_UNSUPPORTED,
                             "lpi_set_method");
            assert_non_null(strstr(lpi_last_error(sys), "sine-Euler systems only"));
            assert_non_null(strstr(lpi_last_error(sys), methods[i]));
        }
        /* The method in use is untouched: still triple-jump-4 (2 pieces: 6 flows). */
        size_t flows = 0;
        assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
        assert_int_equal(flows, 6);
        lpi_destroy(sys);
    }
}

/* direct-eq5 is O(N^4): refused beyond N = 31, with the reason. */
static void test_direct_eq5_size_limit(void **state) {
    (void)state;
    require_fftw();
    lpi_system *sys = NULL;
    assert_int_equal(lpi_sine_euler_create(&sys, 31), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "direct-eq5"), LPI_OK);
    lpi_destroy(sys);
    assert_int_equal(lpi_sine_euler_create(&sys, 33), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "direct-eq5"), LPI_ERR_UNSUPPORTED, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "N <= 31"));
    assert_non_null(strstr(lpi_last_error(sys), "N = 33"));
    assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK); /* the O(N^3) field scales */
    lpi_destroy(sys);
}

/* ---- agreement to round-off ---------------------------------------------------- */

/* RK4 commutes with the linear map modes -> W, so rk4 (on the modes, O(N^3)
 * matrix-form field), rk4-matrix (on W, BLAS) and direct-eq5 (on the modes,
 * eq. 5 summed term by term) are one map up to round-off. N = 9 is composite. */
static void test_rk4_forms_agree(void **state) {
    (void)state;
    require_blas();
    const int sizes[] = {7, 9, 11};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        const int N = sizes[s];
        const size_t n = 2 * (size_t)N * N;
        double *w0 = malloc(sizeof(double) * n), *a = malloc(sizeof(double) * n),
               *b = malloc(sizeof(double) * n), *c = malloc(sizeof(double) * n);
        random_field(N, 11 + N, w0);
        run(N, w0, "rk4", 1.0, 20, a);
        run(N, w0, "direct-eq5", 1.0, 20, b);
        run(N, w0, "rk4-matrix", 1.0, 20, c);
        const double scale = max_abs(a, n), moved = max_abs_diff(a, w0, n);
        const double d_direct = max_abs_diff(a, b, n) / scale, d_matrix = max_abs_diff(a, c, n) / scale;
        print_message("N = %2d: |rk4 - direct-eq5| %.2e, |rk4 - rk4-matrix| %.2e (relative; "
                      "the state moved %.2e)\n", N, d_direct, d_matrix, moved / scale);
        assert_true(moved / scale > 1e-2); /* the run does something */
        if (d_direct > 1e-13 || d_matrix > 1e-13)
            fail_msg("N = %d: rk4 forms differ by %.3e (direct-eq5), %.3e (rk4-matrix)", N,
                     d_direct, d_matrix);
        free(w0), free(a), free(b), free(c);
    }
}

/* ---- orders --------------------------------------------------------------------- */

static void check_order(int N, const char *method, int order, const int64_t steps[4]) {
    const size_t n = 2 * (size_t)N * N;
    const double T = 1.0;
    double *w0 = malloc(sizeof(double) * n), *ref = malloc(sizeof(double) * n),
           *x = malloc(sizeof(double) * n);
    random_field(N, 5, w0);
    /* Reference: kahan-li-8 with dt = 1/128. Its distance to the run with
     * dt = 1/64 bounds its error from above (by 2^8 x, for order 8). */
    run(N, w0, "kahan-li-8", T, 128, ref);
    run(N, w0, "kahan-li-8", T, 64, x);
    const double ref_error = max_abs_diff(ref, x, n);
    double dts[4], errors[4];
    for (int i = 0; i < 4; ++i) {
        run(N, w0, method, T, steps[i], x);
        dts[i] = T / (double)steps[i];
        errors[i] = max_abs_diff(x, ref, n);
        if (errors[i] < 1000 * ref_error)
            fail_msg("%s: error %.2e is not far above the reference's %.2e", method, errors[i],
                     ref_error);
    }
    const double p = lpi_fit_order(dts, errors, 4);
    print_message("N = %d %-10s order %d measured %6.3f (errors %.2e .. %.2e; reference %.1e)\n", N,
                  method, order, p, errors[0], errors[3], ref_error);
    if (fabs(p - order) > 0.2) fail_msg("%s: measured order %.3f, nominal %d", method, p, order);
    free(w0), free(ref), free(x);
}

static void test_orders(void **state) {
    (void)state;
    require_blas();
    const int64_t isomp_steps[4] = {16, 24, 32, 48};
    const int64_t rk4_steps[4] = {16, 24, 32, 48};
    check_order(11, "isomp", 2, isomp_steps);
    check_order(11, "rk4-matrix", 4, rk4_steps);
    check_order(9, "isomp", 2, isomp_steps);
}

/* ---- invariants ----------------------------------------------------------------- */

/* Spectrum drift of W (the Casimirs) relative to its largest eigenvalue. */
static double spectrum_drift(int N, const double *w0, const char *method, double tolerance,
                             double dt, int64_t steps) {
    lpi_system *sys = sine_euler(N, w0);
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    assert_int_equal(lpi_set_implicit_options(sys, tolerance, 100), LPI_OK);
    double before[32], after[32];
    assert_int_equal(lpi_casimirs(sys, before, (size_t)N), LPI_OK);
    assert_int_equal(lpi_step(sys, dt, steps), LPI_OK);
    assert_int_equal(lpi_casimirs(sys, after, (size_t)N), LPI_OK);
    lpi_destroy(sys);
    return max_abs_diff(before, after, (size_t)N) / max_abs(before, (size_t)N);
}

/* rk4 and the midpoint rule on the modes combine the field's values with real
 * coefficients, so a field that is exactly Hermitian keeps a Hermitian state
 * Hermitian to the bit; one that is only Hermitian to round-off lets the
 * non-Hermitian part grow. After many steps every mode is still the exact
 * conjugate of its mirror and w_0 is still real. */
static void test_modes_stay_exactly_hermitian(void **state) {
    (void)state;
    require_fftw();
    const int N = 9;
    const size_t n = (size_t)N * N;
    double w[2 * 81], out[2 * 81];
    random_field(N, 11, w);
    /* direct-eq5 sums each mode's rate on its own: its pairs must still be
     * exact conjugates (they drifted apart at the flow's instability rate). */
    const char *methods[] = {"rk4", "implicit-midpoint", "direct-eq5"};
    for (int k = 0; k < 3; ++k) {
        run(N, w, methods[k], 20.0, 2000, out);
        assert_true(out[1] == 0.0);
        size_t broken = 0;
        for (int a = 0; a < N; ++a)
            for (int b = 0; b < N; ++b) {
                const size_t m = (size_t)a * N + b, minus = (size_t)((N - a) % N) * N + (N - b) % N;
                broken += out[2 * m] != out[2 * minus] || out[2 * m + 1] != -out[2 * minus + 1];
            }
        printf("%-18s 2000 steps, N = %d: %zu of %zu modes not the exact conjugate of their mirror\n",
               methods[k], N, broken, n);
        assert_int_equal(broken, 0);
        assert_true(max_abs_diff(out, w, 2 * n) > 1e-3); /* the field did move */
    }
}

static int keep_going(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys, (void)step, (void)t, (void)user;
    return 0;
}
static int stop_at_twenty(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys, (void)t, (void)user;
    return step == 20;
}

/* Observing changes no bit of a baseline's trajectory, and a stop leaves the
 * state of a call of that many steps: the matrix methods keep W across the
 * observations (isomp's first-step guess too), instead of a run per stretch. */
static void test_observing_changes_nothing(void **state) {
    (void)state;
    require_fftw();
    const int N = 9;
    const size_t n = 2 * (size_t)N * N;
    double w[2 * 81], plain[2 * 81], observed[2 * 81];
    random_field(N, 5, w);
    const char *methods[] = {"rk4", "direct-eq5", "rk4-matrix", "isomp"};
    for (int k = 0; k < 4; ++k) {
        if (k >= 2 && !have_blas) {
            printf("%s: not checked (built without BLAS/LAPACK)\n", methods[k]);
            continue;
        }
        run(N, w, methods[k], 3.0, 30, plain);
        lpi_system *sys = sine_euler(N, w);
        assert_int_equal(lpi_set_method(sys, methods[k]), LPI_OK);
        assert_int_equal(lpi_set_observer(sys, 1, keep_going, NULL), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.1, 30), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(sys, observed, n), LPI_OK);
        printf("%-10s observed every step: %.1e from the unobserved run\n", methods[k],
               max_abs_diff(observed, plain, n));
        assert_memory_equal(observed, plain, sizeof plain);
        lpi_destroy(sys);

        run(N, w, methods[k], 2.0, 20, plain);
        sys = sine_euler(N, w);
        assert_int_equal(lpi_set_method(sys, methods[k]), LPI_OK);
        assert_int_equal(lpi_set_observer(sys, 10, stop_at_twenty, NULL), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.1, 1000), LPI_STOPPED);
        assert_int_equal(lpi_sine_euler_get_modes(sys, observed, n), LPI_OK);
        assert_memory_equal(observed, plain, sizeof plain);
        lpi_destroy(sys);
    }
}

/* The Casimir spectrum of a state whose matrix W overflows is refused as an
 * overflow before LAPACK sees it. */
static void test_spectrum_of_overflowing_matrix(void **state) {
    (void)state;
    require_blas();
    const int N = 5;
    const size_t n = (size_t)N * N;
    double w[2 * 25] = {0};
    /* Modes (a, 0), a != 0, real and equal: Hermitian, and W_00 is their sum. */
    for (int a = 1; a < N; ++a) w[2 * a * N] = 0.45 * DBL_MAX;
    lpi_system *sys = sine_euler(N, w);
    double c[5];
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, c, n / N), LPI_ERR_OVERFLOW, "lpi_casimirs");
    assert_non_null(strstr(lpi_last_error(sys), "matrix W of this state overflows"));
    lpi_destroy(sys);
}

static void test_isomp_isospectral(void **state) {
    (void)state;
    require_blas();
    const int N = 13;
    double w0[2 * 13 * 13];
    random_field(N, 17, w0);
    const double dt = 0.05;
    const int64_t steps = 200;
    const double tight = spectrum_drift(N, w0, "isomp", 1e-14, dt, steps);
    const double loose = spectrum_drift(N, w0, "isomp", 1e-8, dt, steps);
    const double rk4 = spectrum_drift(N, w0, "rk4-matrix", 1e-14, dt, steps);
    print_message("spectrum drift over %lld steps of %.2f: isomp (tol 1e-14) %.2e, isomp (tol "
                  "1e-8) %.2e, rk4-matrix %.2e\n", (long long)steps, dt, tight, loose, rk4);
    assert_true(tight < 1e-12);  /* to the tolerance, up to round-off over the run */
    assert_true(loose < 1e-6);   /* steps * tolerance */
    assert_true(loose > tight);  /* and it is the tolerance that sets it */
    assert_true(rk4 > 1e-8);
    assert_true(rk4 > 1e4 * tight);
}

/* ---- failure modes --------------------------------------------------------------- */

static void test_isomp_non_convergence_rolls_back(void **state) {
    (void)state;
    require_blas();
    const int N = 7;
    double w0[2 * 7 * 7];
    random_field(N, 23, w0);
    lpi_system *sys = sine_euler(N, w0);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK); /* some history to keep */
    assert_int_equal(lpi_set_method(sys, "isomp"), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    /* A step far beyond the iteration's reach (h |B| >> 1). */
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 100.0, 3), LPI_ERR_NO_CONVERGENCE, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "isomp"));
    assert_non_null(strstr(lpi_last_error(sys), "rolled back"));
    /* A fair step with too small an iteration budget. */
    assert_int_equal(lpi_set_implicit_options(sys, 1e-13, 2), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.05, 5), LPI_ERR_NO_CONVERGENCE, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "did not converge in 2 iterations"));
    /* The budget restored, it steps again; a looser tolerance needs fewer iterations. */
    size_t tight = 0, loose = 0;
    assert_int_equal(lpi_set_implicit_options(sys, 1e-13, 100), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.05, 5), LPI_OK);
    assert_int_equal(lpi_flows_per_step(sys, &tight), LPI_OK);
    assert_int_equal(lpi_set_implicit_options(sys, 1e-6, 100), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.05, 5), LPI_OK);
    assert_int_equal(lpi_flows_per_step(sys, &loose), LPI_OK);
    print_message("isomp iterations per step at dt = 0.05: %zu (tol 1e-13), %zu (tol 1e-6)\n", tight,
                  loose);
    assert_true(loose < tight);
    lpi_destroy(sys);
}

/* Splits and threads do not matter to the matrix methods; switching methods
 * back and forth keeps working (plans are made and released per method). */
/* The midpoint's stopping test is relative to the state, down to the noise
 * of subnormal arithmetic: a field of 1e-158 (its products underflow) scaled
 * with the step by 1e158 (the same motion, scaled) still steps, where a test
 * relative all the way down waited for a change below the noise. */
static void test_midpoint_where_products_underflow(void **state) {
    (void)state;
    require_fftw();
    enum { N = 15 };
    double w0[2 * N * N];
    random_field(N, 5, w0);
    const double largest = max_abs(w0, 2 * N * N);
    for (int i = 0; i < 2 * N * N; ++i) w0[i] *= 1e-158 / largest;
    lpi_system *sys = sine_euler(N, w0);
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    const int status = lpi_step(sys, 0.05 * 1e158, 1);
    if (status != LPI_OK) fail_msg("a field of 1e-158: %s", lpi_last_error(sys));
    lpi_destroy(sys);
}

static void test_switching(void **state) {
    (void)state;
    require_blas();
    const int N = 11;
    const size_t n = 2 * (size_t)N * N;
    double w0[2 * 11 * 11], a[2 * 11 * 11], b[2 * 11 * 11];
    random_field(N, 29, w0);
    run(N, w0, "isomp", 0.5, 10, a);
    lpi_system *sys = sine_euler(N, w0);
    for (int k = 0; k < 3; ++k) {
        assert_int_equal(lpi_set_method(sys, "rk4-matrix"), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "isomp"), LPI_OK);
    }
    assert_int_equal(lpi_step(sys, 0.05, 4), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.05, 6), LPI_OK); /* two calls, one run */
    assert_int_equal(lpi_sine_euler_get_modes(sys, b, n), LPI_OK);
    /* Split in two calls the initial guesses differ, so agreement is to the tolerance. */
    assert_true(max_abs_diff(a, b, n) < 1e-11);
    assert_true(fabs(lpi_time(sys) - 0.5) < 1e-15);
    lpi_destroy(sys);
}

/* A build without BLAS/LAPACK: the BLAS methods name what is missing;
 * direct-eq5 (plain loops) still runs. */
static void test_without_blas(void **state) {
    (void)state;
    require_fftw();
    if (have_blas) LPI_SKIP("built with BLAS/LAPACK: the refusals without it cannot be seen");
    double w0[2 * 7 * 7], a[2 * 7 * 7], b[2 * 7 * 7];
    random_field(7, 3, w0);
    lpi_system *sys = sine_euler(7, w0);
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "isomp"), LPI_ERR_UNSUPPORTED, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "BLAS"));
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "rk4-matrix"), LPI_ERR_UNSUPPORTED, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "BLAS"));
    lpi_destroy(sys);
    run(7, w0, "rk4", 1.0, 20, a);
    run(7, w0, "direct-eq5", 1.0, 20, b);
    assert_true(max_abs_diff(a, b, 2 * 7 * 7) < 1e-13 * max_abs(a, 2 * 7 * 7));
}

int main(void) {
    lpi_system *probe = NULL;
    have_fftw = lpi_sine_euler_create(&probe, 3) == LPI_OK;
    have_blas = have_fftw && lpi_set_method(probe, "rk4-matrix") == LPI_OK;
    lpi_destroy(probe);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry_rows),
        cmocka_unit_test(test_unsupported_elsewhere),
        cmocka_unit_test(test_direct_eq5_size_limit),
        cmocka_unit_test(test_rk4_forms_agree),
        cmocka_unit_test(test_orders),
        cmocka_unit_test(test_modes_stay_exactly_hermitian),
        cmocka_unit_test(test_observing_changes_nothing),
        cmocka_unit_test(test_spectrum_of_overflowing_matrix),
        cmocka_unit_test(test_isomp_isospectral),
        cmocka_unit_test(test_isomp_non_convergence_rolls_back),
        cmocka_unit_test(test_midpoint_where_products_underflow),
        cmocka_unit_test(test_switching),
        cmocka_unit_test(test_without_blas),
    };
    return lpi_run_tests(tests);
}
