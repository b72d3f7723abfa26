/* The non-Poisson baselines a user would otherwise pick: RK4 and the implicit
 * midpoint rule. Their accuracy is measured in test_compositions; here: their
 * failure modes (non-convergence rolled back), their settings, and that the
 * registry says honestly which methods are Poisson maps. */
#include "lpi_test.h"

static lpi_system *rigid_body(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    return sys;
}

static int method_index(const char *name) {
    for (int i = 0; i < lpi_method_count(); ++i)
        if (strcmp(lpi_method_name(i), name) == 0) return i;
    fail_msg("method %s not registered", name);
    return -1;
}

static void test_poisson_flags(void **state) {
    (void)state;
    assert_int_equal(lpi_method_is_poisson(method_index("leapfrog")), 1);
    assert_int_equal(lpi_method_is_poisson(method_index("kahan-li-8")), 1);
    assert_int_equal(lpi_method_is_poisson(method_index("rk4")), 0);
    assert_int_equal(lpi_method_is_poisson(method_index("implicit-midpoint")), 0);
    assert_int_equal(lpi_method_is_poisson(-1), -1);
    assert_int_equal(lpi_method_is_poisson(lpi_method_count()), -1);
}

/* A step far beyond the fixed-point iteration's reach (h * |omega| >> 2)
 * fails with LPI_ERR_NO_CONVERGENCE and leaves the state as it was. */
static void test_midpoint_non_convergence_rolls_back(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK); /* some history to keep */
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 50.0, 5), LPI_ERR_NO_CONVERGENCE, "lpi_step");
    /* One step named, one roll-back said (the message said both twice,
     * counting from 0 and from 1). */
    const char *message = lpi_last_error(sys);
    assert_non_null(strstr(message, "in step 1 of this call (t = 0.2 .. 50.2); state rolled back"));
    assert_null(strstr(strstr(message, "rolled back") + 1, "rolled back"));
    assert_null(strstr(message, "step 0"));
    /* With a tiny iteration limit even a modest step does not converge... */
    assert_int_equal(lpi_set_implicit_options(sys, 1e-15, 2), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.1, 100), LPI_ERR_NO_CONVERGENCE, "lpi_step");
    /* ...and a loose tolerance makes it converge, less accurately. */
    assert_int_equal(lpi_set_implicit_options(sys, 1e-3, 2), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 100), LPI_OK);
    /* The settings survive a change of method. */
    assert_int_equal(lpi_set_method(sys, "leapfrog"), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 10), LPI_OK);
    lpi_destroy(sys);
    /* A step whose result overflows is rolled back with what the last call
     * measured: flows per step as before (the snapshot compares them; the
     * non-finite path kept the failed call's average, 2 where it was 13). */
    sys = rigid_body();
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.3, 10), LPI_OK);
    size_t flows = 0;
    assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
    assert_true(flows > 5);
    const double huge[3] = {1.2e308, 0.0, 0.0};
    assert_int_equal(lpi_set_state(sys, huge, 3), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.3, 1), LPI_ERR_NONFINITE, "lpi_step");
    lpi_destroy(sys);
}

/* The implicit midpoint rule conserves every quadratic invariant in exact
 * arithmetic; for the rigid body both |m|^2 and H are quadratic, so both stay
 * at the level of the iteration tolerance: a check that the solve is tight. */
static void test_midpoint_keeps_quadratic_invariants(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    double c0, c, h0, h;
    assert_int_equal(lpi_casimirs(sys, &c0, 1), LPI_OK);
    assert_int_equal(lpi_energy(sys, &h0), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.05, 20000), LPI_OK);
    assert_int_equal(lpi_casimirs(sys, &c, 1), LPI_OK);
    assert_int_equal(lpi_energy(sys, &h), LPI_OK);
    print_message("implicit midpoint, 20000 steps: |m|^2 drift %.2e, energy drift %.2e\n",
                  fabs(c / c0 - 1), fabs(h / h0 - 1));
    assert_true(fabs(c / c0 - 1) < 1e-10);
    assert_true(fabs(h / h0 - 1) < 1e-10);
    lpi_destroy(sys);
}

/* The rigid body's field is quadratic: the state scaled by s with the step
 * scaled by 1/s is the same motion, scaled. The iteration's stopping test is
 * relative, so a small state converges as far as one of size 1 (with the
 * test's old absolute floor, tolerance * max(1, max|x|), a state of 1e-10
 * stopped 4e-4 off). */
static void test_midpoint_on_small_states(void **state) {
    (void)state;
    const double m[3] = {1.0, 0.5, -0.3}, dt = 0.1;
    double unit[3], scaled[3];
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    assert_int_equal(lpi_step(sys, dt, 1), LPI_OK);
    assert_int_equal(lpi_get_state(sys, unit, 3), LPI_OK);
    for (double s = 1e-4; s >= 1e-100; s *= 1e-8) {
        const double small[3] = {s * m[0], s * m[1], s * m[2]};
        assert_int_equal(lpi_set_state(sys, small, 3), LPI_OK);
        assert_int_equal(lpi_step(sys, dt / s, 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, scaled, 3), LPI_OK);
        double worst = 0.0;
        for (int i = 0; i < 3; ++i) worst = fmax(worst, fabs(scaled[i] / s - unit[i]) / fabs(unit[i] - m[i]));
        if (worst > 1e-9) fail_msg("state scaled by %g: off by %.2e of the step's increment", s, worst);
    }
    lpi_destroy(sys);
}

static void test_implicit_options_bad_input(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    LPI_ASSERT_FAILS(NULL, lpi_set_implicit_options(NULL, 1e-12, 10), LPI_ERR_NULL,
                     "lpi_set_implicit_options");
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, 0.0, 10), LPI_ERR_INVALID,
                     "lpi_set_implicit_options");
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, -1e-12, 10), LPI_ERR_INVALID,
                     "lpi_set_implicit_options");
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, NAN, 10), LPI_ERR_NONFINITE,
                     "lpi_set_implicit_options");
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, INFINITY, 10), LPI_ERR_INVALID,
                     "lpi_set_implicit_options");
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, 1e-12, 0), LPI_ERR_INVALID,
                     "lpi_set_implicit_options");
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, 1e-12, -5), LPI_ERR_INVALID,
                     "lpi_set_implicit_options");
    lpi_destroy(sys);
}

/* so(3) by structure constants whose one piece counts its gradient calls:
 * one a vector-field evaluation. */
static const double kInertia1 = 1.0;
static int counting_gradient(size_t n, const double *x, double *g, void *user) {
    ++*(long *)user;
    return lpi_test_axis_gradient(n, x, g, (void *)&kInertia1);
}
static int axis_energy(size_t n, const double *x, double *h, void *user) {
    (void)user;
    return lpi_test_axis_energy(n, x, h, (void *)&kInertia1);
}

static int quiet_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys, (void)step, (void)t, (void)user;
    return 0;
}

/* lpi_flows_per_step counts implicit-midpoint's evaluations as they are
 * made, over the whole call: the starting guess's and one an iteration (it
 * left out the guess's, and counted the last stretch between observations). */
static void test_midpoint_counts_its_evaluations(void **state) {
    (void)state;
    static const int32_t i[] = {0, 1, 2}, j[] = {1, 2, 0}, k[] = {2, 0, 1};
    static const double c[] = {1, 1, 1};
    lpi_system *sys = NULL;
    long calls = 0;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    const int32_t axis = 0;
    assert_int_equal(lpi_add_piece(sys, 1, &axis, counting_gradient, axis_energy, &calls), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    for (int run = 0; run < 3; ++run) {
        const int loose = run == 1;
        /* The last run is observed every 3 steps: still the whole call's count. */
        if (run == 2) assert_int_equal(lpi_set_observer(sys, 3, quiet_observer, NULL), LPI_OK);
        assert_int_equal(lpi_set_implicit_options(sys, loose ? 1e-3 : 1e-13, 100), LPI_OK);
        calls = 0;
        assert_int_equal(lpi_step(sys, 0.1, 10), LPI_OK);
        size_t flows = 0;
        assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
        assert_int_equal(flows, (calls + 9) / 10); /* per step, rounded up */
    }
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poisson_flags),
        cmocka_unit_test(test_midpoint_non_convergence_rolls_back),
        cmocka_unit_test(test_midpoint_keeps_quadratic_invariants),
        cmocka_unit_test(test_midpoint_on_small_states),
        cmocka_unit_test(test_implicit_options_bad_input),
        cmocka_unit_test(test_midpoint_counts_its_evaluations),
    };
    return lpi_run_tests(tests);
}
