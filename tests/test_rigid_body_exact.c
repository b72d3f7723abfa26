/* The exact free rigid body against a tight RK4 integration written here, in
 * every case: both sides of the separatrix, on it, symmetric bodies, steady
 * rotations, every ordering of the inertias. */
#include "lpi_test.h"

static double exact_error(const double I[3], const double m0[3], double t, int64_t rk4_steps) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, I[0], I[1], I[2]), LPI_OK);
    assert_int_equal(lpi_set_state(sys, m0, 3), LPI_OK);
    double exact[3], reference[3] = {m0[0], m0[1], m0[2]};
    assert_int_equal(lpi_rigid_body_exact(sys, t, exact), LPI_OK);
    lpi_test_rk4(lpi_test_rigid_body_field, I, 3, reference, t, rk4_steps);
    lpi_destroy(sys);
    return lpi_test_distance(exact, reference, 3);
}

static void test_all_cases_match_rk4(void **state) {
    (void)state;
    const double inertias[][3] = {{1, 2, 3}, {3, 2, 1}, {2, 1, 3}, {1, 3, 2}, {2, 3, 1},
                                  {3, 1, 2}, {1, 1, 2}, {2, 2, 1}, {1, 2, 2}, {1, 1, 1},
                                  {1, 1e3, 1e-2}};
    const double s3 = sqrt(3.0);
    const double states[][3] = {
        {1, 0.5, -0.3}, {0.1, 1, 0.1}, {-0.3, 0.2, 1}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1},
        {1, 0, s3},        /* on the separatrix of I = (1,2,3) */
        {1, 1e-6, s3},     /* just beside it */
        {1, -1e-6, s3 * (1 + 1e-9)},
    };
    double worst = 0.0;
    for (size_t i = 0; i < sizeof inertias / sizeof inertias[0]; ++i) {
        for (size_t j = 0; j < sizeof states / sizeof states[0]; ++j) {
            /* The stiff body (rates ~200) is compared over a shorter time, where
             * RK4 is tight before its own round-off (~u sqrt(steps)) shows. */
            const int stiff = inertias[i][2] < 0.1;
            const double e = exact_error(inertias[i], states[j], stiff ? 1.0 : 7.0,
                                         stiff ? 1000000 : 70000);
            if (e > worst) worst = e;
            if (e > 1e-11)
                fail_msg("I = (%g, %g, %g), m0 = (%g, %g, %g): |exact - rk4| = %.3e", inertias[i][0],
                         inertias[i][1], inertias[i][2], states[j][0], states[j][1], states[j][2], e);
        }
    }
    print_message("worst |exact - rk4| over %zu cases at t = 7: %.2e\n",
                  sizeof inertias / sizeof inertias[0] * (sizeof states / sizeof states[0]), worst);
}

static void test_long_time_and_backwards(void **state) {
    (void)state;
    const double I[3] = {1, 2, 3}, m0[3] = {1, 0.5, -0.3};
    assert_true(exact_error(I, m0, 200.0, 2000000) < 1e-10);
    assert_true(exact_error(I, m0, -20.0, 200000) < 1e-11);
}

static void test_bad_input(void **state) {
    (void)state;
    lpi_system *body = NULL, *pendulum = NULL;
    double out[3];
    assert_int_equal(lpi_rigid_body_create(&body, 1, 2, 3), LPI_OK);
    assert_int_equal(lpi_pendulum_create(&pendulum), LPI_OK);
    LPI_ASSERT_FAILS(NULL, lpi_rigid_body_exact(NULL, 1.0, out), LPI_ERR_NULL, "lpi_rigid_body_exact");
    LPI_ASSERT_FAILS(body, lpi_rigid_body_exact(body, 1.0, NULL), LPI_ERR_NULL, "lpi_rigid_body_exact");
    LPI_ASSERT_FAILS(body, lpi_rigid_body_exact(body, NAN, out), LPI_ERR_NONFINITE, "lpi_rigid_body_exact");
    LPI_ASSERT_FAILS(pendulum, lpi_rigid_body_exact(pendulum, 1.0, out), LPI_ERR_UNSUPPORTED,
                     "lpi_rigid_body_exact");
    lpi_destroy(body);
    lpi_destroy(pendulum);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_all_cases_match_rk4),
        cmocka_unit_test(test_long_time_and_backwards),
        cmocka_unit_test(test_bad_input),
    };
    return lpi_run_tests(tests);
}
