/* Measured convergence orders of the splitting methods on the rigid body and
 * the pendulum, against an RK4 reference written here, independent of the
 * library, with a step small enough that its error is ~1e-15. */
#include "lpi_test.h"

static const double kInertia[3] = {1.0, 2.0, 3.0};

static void pendulum_field(const double *x, double *dx, const void *ctx) {
    (void)ctx; /* J(x) grad H with H = x3^2/2 + x2 */
    dx[0] = -x[1] * x[2];
    dx[1] = x[0] * x[2];
    dx[2] = -x[0];
}

/* Fits the order over steps T/16 ... T/256 and checks it within 0.2. */
static void check_order(lpi_system *sys, const char *method, int expected, const double *x0,
                        double T, const double *reference) {
    double steps[5], errors[5];
    for (int i = 0; i < 5; ++i) {
        const int64_t n = 16 << i;
        steps[i] = T / (double)n;
        errors[i] = lpi_test_error(sys, method, x0, T, n, reference);
        assert_true(errors[i] > 1e-11); /* round-off must not dominate the fit */
    }
    const double order = lpi_fit_order(steps, errors, 5);
    print_message("%-12s measured order %.3f (errors %.2e ... %.2e)\n", method, order, errors[0],
                  errors[4]);
    if (fabs(order - expected) > 0.2)
        fail_msg("%s: measured order %.3f, expected %d", method, order, expected);
}

static void test_rigid_body_orders(void **state) {
    (void)state;
    const double m0[3] = {1.0, 0.5, -0.3}, T = 2.0;
    double reference[3] = {m0[0], m0[1], m0[2]};
    lpi_test_rk4(lpi_test_rigid_body_field, kInertia, 3, reference, T, 200000);
    const char *splits[] = {"casimir-shift", "axes"};
    for (int s = 0; s < 2; ++s) {
        lpi_system *sys = NULL;
        assert_int_equal(lpi_rigid_body_create(&sys, kInertia[0], kInertia[1], kInertia[2]), LPI_OK);
        assert_int_equal(lpi_set_split(sys, splits[s]), LPI_OK);
        print_message("rigid body, split %s\n", splits[s]);
        check_order(sys, "lie-trotter", 1, m0, T, reference);
        check_order(sys, "lie-trotter-adjoint", 1, m0, T, reference);
        check_order(sys, "leapfrog", 2, m0, T, reference);
        lpi_destroy(sys);
    }
}

static void test_pendulum_orders(void **state) {
    (void)state;
    const double x0[3] = {sin(2.0), -cos(2.0), 0.3}, T = 2.0;
    double reference[3] = {x0[0], x0[1], x0[2]};
    lpi_test_rk4(pendulum_field, NULL, 3, reference, T, 200000);
    lpi_system *sys = NULL;
    assert_int_equal(lpi_pendulum_create(&sys), LPI_OK);
    check_order(sys, "lie-trotter", 1, x0, T, reference);
    check_order(sys, "lie-trotter-adjoint", 1, x0, T, reference);
    check_order(sys, "leapfrog", 2, x0, T, reference);
    lpi_destroy(sys);
}

/* The library's own RK4 baseline agrees with the independent one. */
static void test_rk4_baseline_matches_reference(void **state) {
    (void)state;
    const double m0[3] = {1.0, 0.5, -0.3}, T = 2.0;
    double reference[3] = {m0[0], m0[1], m0[2]};
    lpi_test_rk4(lpi_test_rigid_body_field, kInertia, 3, reference, T, 200);
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    assert_true(lpi_test_error(sys, "rk4", m0, T, 200, reference) < 1e-14);
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rigid_body_orders),
        cmocka_unit_test(test_pendulum_orders),
        cmocka_unit_test(test_rk4_baseline_matches_reference),
    };
    return lpi_run_tests(tests);
}
