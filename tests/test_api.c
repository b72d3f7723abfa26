/* The contract of every public function of the foundation: exact status codes
 * for bad input, a message naming the function, and an unchanged state. */
#include "lpi_test.h"

static lpi_system *rigid_body(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK); /* a nonzero time to keep */
    return sys;
}

static void test_version_and_status_names(void **state) {
    (void)state;
    char expected[64];
    snprintf(expected, sizeof expected, "%d.%d.%d", LPI_VERSION_MAJOR, LPI_VERSION_MINOR,
             LPI_VERSION_PATCH);
    assert_string_equal(lpi_version_string(), expected);
    /* One number for comparisons: the header's and the library's agree. */
    assert_int_equal(LPI_VERSION_NUMBER,
                     LPI_VERSION_MAJOR * 10000 + LPI_VERSION_MINOR * 100 + LPI_VERSION_PATCH);
    assert_int_equal(lpi_version_number(), LPI_VERSION_NUMBER);
    snprintf(expected, sizeof expected, "%d.%d.%d", lpi_version_number() / 10000,
             lpi_version_number() / 100 % 100, lpi_version_number() % 100);
    assert_string_equal(lpi_version_string(), expected);
    assert_string_equal(lpi_status_name(LPI_OK), "LPI_OK");
    assert_string_equal(lpi_status_name(LPI_ERR_NULL), "LPI_ERR_NULL");
    assert_string_equal(lpi_status_name(LPI_ERR_SIZE), "LPI_ERR_SIZE");
    assert_string_equal(lpi_status_name(LPI_ERR_NOT_ABELIAN), "LPI_ERR_NOT_ABELIAN");
    assert_string_equal(lpi_status_name(12345), "LPI_UNKNOWN_STATUS");
    assert_string_equal(lpi_status_message(12345), "unknown status code");
    /* Every code has a distinct name and a non-empty message. */
    const int codes[] = {LPI_OK, LPI_ERR_NULL, LPI_ERR_INVALID, LPI_ERR_SIZE, LPI_ERR_NONFINITE,
                         LPI_ERR_NOT_ABELIAN, LPI_ERR_UNSUPPORTED, LPI_ERR_NO_MEMORY,
                         LPI_ERR_INTERNAL, LPI_ERR_CALLBACK, LPI_ERR_NO_CONVERGENCE,
                         LPI_ERR_IO, LPI_ERR_FORMAT, LPI_ERR_BUSY, LPI_ERR_OVERFLOW,
                         LPI_STOPPED};
    const size_t count = sizeof codes / sizeof codes[0];
    for (size_t i = 0; i < count; ++i) {
        assert_true(strlen(lpi_status_message(codes[i])) > 0);
        /* Errors are negative; LPI_STOPPED, the one positive status, is not one. */
        assert_true(codes[i] == LPI_OK || codes[i] < 0 || codes[i] == LPI_STOPPED);
        for (size_t j = 0; j < i; ++j)
            assert_string_not_equal(lpi_status_name(codes[i]), lpi_status_name(codes[j]));
    }
}

static void test_method_registry(void **state) {
    (void)state;
    const int count = lpi_method_count();
    assert_true(count >= 3);
    int found_leapfrog = 0, found_lie_trotter = 0;
    for (int i = 0; i < count; ++i) {
        assert_non_null(lpi_method_name(i));
        assert_true(lpi_method_order(i) >= 1);
        if (strcmp(lpi_method_name(i), "leapfrog") == 0) {
            found_leapfrog = 1;
            assert_int_equal(lpi_method_order(i), 2);
        }
        if (strcmp(lpi_method_name(i), "lie-trotter") == 0) {
            found_lie_trotter = 1;
            assert_int_equal(lpi_method_order(i), 1);
        }
    }
    assert_true(found_leapfrog && found_lie_trotter);
    assert_null(lpi_method_name(-1));
    assert_null(lpi_method_name(count));
    assert_int_equal(lpi_method_order(-1), -1);
    assert_int_equal(lpi_method_order(count), -1);
}

static void test_create_rejects_bad_inertia(void **state) {
    (void)state;
    lpi_system *sys = (lpi_system *)0x1; /* must be reset to NULL on failure */
    const struct {
        double I[3];
        int status;
    } cases[] = {
        {{NAN, 1, 1}, LPI_ERR_NONFINITE},      {{1, INFINITY, 1}, LPI_ERR_NONFINITE},
        {{1, 1, -INFINITY}, LPI_ERR_NONFINITE}, {{0, 1, 1}, LPI_ERR_INVALID},
        {{1, -2, 1}, LPI_ERR_INVALID},          {{1, 1, -0.0}, LPI_ERR_INVALID},
        {{1, 1, 1e-320}, LPI_ERR_INVALID}, /* 1/I overflows */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        sys = (lpi_system *)0x1;
        LPI_ASSERT_FAILS(NULL, lpi_rigid_body_create(&sys, cases[i].I[0], cases[i].I[1], cases[i].I[2]),
                         cases[i].status, "lpi_rigid_body_create");
        assert_null(sys);
    }
    LPI_ASSERT_FAILS(NULL, lpi_rigid_body_create(NULL, 1, 2, 3), LPI_ERR_NULL, "lpi_rigid_body_create");
    LPI_ASSERT_FAILS(NULL, lpi_pendulum_create(NULL), LPI_ERR_NULL, "lpi_pendulum_create");
    assert_true(strstr(lpi_last_error(NULL), "out") != NULL);
}

static void test_null_handle(void **state) {
    (void)state;
    double x[3] = {0}, e;
    LPI_ASSERT_FAILS(NULL, lpi_set_method(NULL, "leapfrog"), LPI_ERR_NULL, "lpi_set_method");
    LPI_ASSERT_FAILS(NULL, lpi_set_split(NULL, "axes"), LPI_ERR_NULL, "lpi_set_split");
    LPI_ASSERT_FAILS(NULL, lpi_set_state(NULL, x, 3), LPI_ERR_NULL, "lpi_set_state");
    LPI_ASSERT_FAILS(NULL, lpi_get_state(NULL, x, 3), LPI_ERR_NULL, "lpi_get_state");
    LPI_ASSERT_FAILS(NULL, lpi_step(NULL, 0.1, 1), LPI_ERR_NULL, "lpi_step");
    LPI_ASSERT_FAILS(NULL, lpi_energy(NULL, &e), LPI_ERR_NULL, "lpi_energy");
    LPI_ASSERT_FAILS(NULL, lpi_casimirs(NULL, x, 1), LPI_ERR_NULL, "lpi_casimirs");
    assert_int_equal(lpi_dim(NULL), 0);
    assert_int_equal(lpi_casimir_count(NULL), 0);
    assert_true(isnan(lpi_time(NULL)));
    lpi_destroy(NULL);
}

static void test_bad_arguments_leave_state_unchanged(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    double x[4] = {1, 2, 3, 4}, e, c[2];
    const double nan_state[3] = {1, NAN, 0}, inf_state[3] = {INFINITY, 0, 0};

    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, NULL), LPI_ERR_NULL, "lpi_set_method");
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "no-such-method"), LPI_ERR_INVALID, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "no-such-method"));
    assert_non_null(strstr(lpi_last_error(sys), "leapfrog")); /* lists the known ones */
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, ""), LPI_ERR_INVALID, "lpi_set_method");
    LPI_ASSERT_FAILS(sys, lpi_set_split(sys, NULL), LPI_ERR_NULL, "lpi_set_split");
    LPI_ASSERT_FAILS(sys, lpi_set_split(sys, "standard-map"), LPI_ERR_INVALID, "lpi_set_split");
    assert_non_null(strstr(lpi_last_error(sys), "casimir-shift"));

    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, NULL, 3), LPI_ERR_NULL, "lpi_set_state");
    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, x, 2), LPI_ERR_SIZE, "lpi_set_state");
    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, x, 4), LPI_ERR_SIZE, "lpi_set_state");
    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, nan_state, 3), LPI_ERR_NONFINITE, "lpi_set_state");
    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, inf_state, 3), LPI_ERR_NONFINITE, "lpi_set_state");

    LPI_ASSERT_FAILS(sys, lpi_get_state(sys, NULL, 3), LPI_ERR_NULL, "lpi_get_state");
    LPI_ASSERT_FAILS(sys, lpi_get_state(sys, x, 0), LPI_ERR_SIZE, "lpi_get_state");
    LPI_ASSERT_FAILS(sys, lpi_get_state(sys, x, 4), LPI_ERR_SIZE, "lpi_get_state");

    LPI_ASSERT_FAILS(sys, lpi_step(sys, NAN, 1), LPI_ERR_NONFINITE, "lpi_step");
    LPI_ASSERT_FAILS(sys, lpi_step(sys, INFINITY, 1), LPI_ERR_NONFINITE, "lpi_step");
    LPI_ASSERT_FAILS(sys, lpi_step(sys, -INFINITY, 1), LPI_ERR_NONFINITE, "lpi_step");
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.0, 1), LPI_ERR_INVALID, "lpi_step");
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.1, -1), LPI_ERR_INVALID, "lpi_step");
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1e308, INT64_MAX), LPI_ERR_OVERFLOW, "lpi_step");

    LPI_ASSERT_FAILS(sys, lpi_energy(sys, NULL), LPI_ERR_NULL, "lpi_energy");
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, NULL, 1), LPI_ERR_NULL, "lpi_casimirs");
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, c, 0), LPI_ERR_SIZE, "lpi_casimirs");
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, c, 2), LPI_ERR_SIZE, "lpi_casimirs");

    /* Valid calls still work afterwards, and zero steps is a no-op. */
    lpi_snapshot before;
    lpi_take_snapshot(sys, &before);
    assert_int_equal(lpi_step(sys, 0.1, 0), LPI_OK);
    lpi_assert_unchanged(sys, &before);
    assert_int_equal(lpi_energy(sys, &e), LPI_OK);
    assert_true(e > 0);
    lpi_destroy(sys);
}

/* A step whose result overflows is rolled back: RK4 with an absurd step. */
static void test_nonfinite_step_is_rolled_back(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1e200, 3), LPI_ERR_NONFINITE, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "rolled back"));
    /* A long run that blows up part way is rolled back to its start too. */
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 50.0, 100000), LPI_ERR_NONFINITE, "lpi_step");
    /* The splitting methods stay finite at any step size: rotations only. */
    assert_int_equal(lpi_set_method(sys, "leapfrog"), LPI_OK);
    assert_int_equal(lpi_step(sys, 1e200, 3), LPI_OK);
    double m[3];
    assert_int_equal(lpi_get_state(sys, m, 3), LPI_OK);
    for (int i = 0; i < 3; ++i) assert_true(isfinite(m[i]));
    /* A state near DBL_MAX rotates too (the increments, up to 2 |m|, were
     * refused as non-finite from 8e307 on): |m|^2 kept to round-off. */
    const double big[3] = {8e307, 8e307, 8e307};
    assert_int_equal(lpi_set_state(sys, big, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 1e-307, 10), LPI_OK);
    assert_int_equal(lpi_get_state(sys, m, 3), LPI_OK);
    double before = 0.0, after = 0.0;
    for (int i = 0; i < 3; ++i) {
        before += (big[i] / 1e307) * (big[i] / 1e307);
        after += (m[i] / 1e307) * (m[i] / 1e307);
    }
    assert_true(fabs(after - before) <= 1e-15 * before);
    lpi_destroy(sys);
}

static void test_successful_calls(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_pendulum_create(&sys), LPI_OK);
    assert_int_equal(lpi_dim(sys), 3);
    assert_int_equal(lpi_casimir_count(sys), 1);
    assert_string_equal(lpi_last_error(sys), "");
    assert_int_equal(lpi_set_split(sys, "standard-map"), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "strang"), LPI_OK); /* alias of leapfrog */
    const double x0[3] = {0.6, -0.8, 0.25};
    assert_int_equal(lpi_set_state(sys, x0, 3), LPI_OK);
    assert_true(lpi_time(sys) == 0.0);
    double h, c;
    assert_int_equal(lpi_energy(sys, &h), LPI_OK);
    assert_true(fabs(h - (0.5 * 0.25 * 0.25 - 0.8)) < 1e-15);
    assert_int_equal(lpi_casimirs(sys, &c, 1), LPI_OK);
    assert_true(fabs(c - 1.0) < 1e-15);
    assert_int_equal(lpi_step(sys, -0.01, 100), LPI_OK); /* backwards in time */
    assert_true(fabs(lpi_time(sys) + 1.0) < 1e-12);
    assert_int_equal(lpi_step(sys, 0.01, 100), LPI_OK); /* and back: symmetric method */
    double x[3];
    assert_int_equal(lpi_get_state(sys, x, 3), LPI_OK);
    assert_true(lpi_test_distance(x, x0, 3) < 1e-13);
    lpi_destroy(sys);
}

/* Every setter has a getter: the kind, method and split read back what was
 * set, a failed setter leaves them, and a checkpoint brings them back. */
static void test_getters(void **state) {
    (void)state;
    assert_null(lpi_kind(NULL));
    assert_null(lpi_get_method(NULL));
    assert_null(lpi_get_split(NULL));
    lpi_system *sys = rigid_body();
    assert_string_equal(lpi_kind(sys), "rigid-body");
    assert_string_equal(lpi_get_method(sys), "leapfrog");
    assert_string_equal(lpi_get_split(sys), "casimir-shift");
    assert_int_equal(lpi_set_method(sys, "strang"), LPI_OK);
    assert_string_equal(lpi_get_method(sys), "leapfrog"); /* the alias's name */
    assert_int_equal(lpi_set_method(sys, "suzuki-6"), LPI_OK);
    assert_string_equal(lpi_get_method(sys), "suzuki-6");
    assert_int_equal(lpi_set_split(sys, "axes"), LPI_OK);
    assert_string_equal(lpi_get_split(sys), "axes");
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "no-such-method"), LPI_ERR_INVALID, "lpi_set_method");
    LPI_ASSERT_FAILS(sys, lpi_set_split(sys, "standard-map"), LPI_ERR_INVALID, "lpi_set_split");
    assert_string_equal(lpi_get_method(sys), "suzuki-6");
    assert_string_equal(lpi_get_split(sys), "axes");

    unsigned char buf[4096];
    size_t size = 0;
    assert_int_equal(lpi_save_buffer(sys, buf, sizeof buf, &size), LPI_OK);
    lpi_system *copy = NULL;
    assert_int_equal(lpi_load_buffer(&copy, buf, size), LPI_OK);
    assert_string_equal(lpi_kind(copy), "rigid-body");
    assert_string_equal(lpi_get_method(copy), "suzuki-6");
    assert_string_equal(lpi_get_split(copy), "axes");
    lpi_destroy(copy);

    const double gammas[3] = {0.25, 0.5, 0.25};
    assert_int_equal(lpi_set_composition(sys, 3, gammas), LPI_OK);
    assert_string_equal(lpi_get_method(sys), "custom");
    lpi_destroy(sys);

    lpi_system *other = NULL;
    assert_int_equal(lpi_pendulum_create(&other), LPI_OK);
    assert_string_equal(lpi_kind(other), "pendulum");
    assert_string_equal(lpi_get_split(other), "standard-map");
    lpi_destroy(other);
    assert_int_equal(lpi_moments_create(&other), LPI_OK);
    assert_string_equal(lpi_kind(other), "moments");
    assert_string_equal(lpi_get_split(other), "pieces");
    lpi_destroy(other);
    assert_int_equal(lpi_generic_create(&other, 1, 0, NULL, NULL, NULL, NULL), LPI_OK);
    assert_string_equal(lpi_kind(other), "generic");
    lpi_destroy(other);
    if (lpi_sine_euler_create(&other, 5) == LPI_OK) {
        assert_string_equal(lpi_kind(other), "sine-euler");
        lpi_destroy(other);
    }
}

static int zero_gradient(size_t n, const double *x, double *g, void *user) {
    (void)x, (void)user;
    for (size_t i = 0; i < n; ++i) g[i] = 0.0;
    return 0;
}
static int zero_energy(size_t n, const double *x, double *h, void *user) {
    (void)n, (void)x, (void)user;
    *h = 0.0;
    return 0;
}
static int zero_casimir(size_t dim, const double *x, double *out, void *user) {
    (void)dim, (void)x, (void)user;
    *out = 0.0;
    return 0;
}
static int scalar_zero(double u, double *out, void *user) {
    (void)u, (void)user;
    *out = 0.0;
    return 0;
}

/* The wrong-kind rule: every function defined for some kinds of system only
 * returns LPI_ERR_UNSUPPORTED, and changes nothing, on every other kind. */
static void test_wrong_kind_is_unsupported(void **state) {
    (void)state;
    lpi_system *systems[5] = {NULL};
    assert_int_equal(lpi_rigid_body_create(&systems[0], 1.0, 2.0, 3.0), LPI_OK);
    assert_int_equal(lpi_pendulum_create(&systems[1]), LPI_OK);
    const int32_t i[1] = {0}, j[1] = {1}, k[1] = {2};
    const double c[1] = {1.0};
    assert_int_equal(lpi_generic_create(&systems[2], 3, 1, i, j, k, c), LPI_OK);
    assert_int_equal(lpi_moments_create(&systems[3]), LPI_OK);
    const int count = lpi_sine_euler_create(&systems[4], 5) == LPI_OK ? 5 : 4;
    for (int s = 0; s < count; ++s) {
        lpi_system *sys = systems[s];
        const char *kind = lpi_kind(sys);
        const int rigid = strcmp(kind, "rigid-body") == 0;
        const int generic = strcmp(kind, "generic") == 0 || strcmp(kind, "moments") == 0;
        const int moments = strcmp(kind, "moments") == 0;
        const int sine_euler = strcmp(kind, "sine-euler") == 0;
        double out[64] = {0}, x[64] = {0}, seconds, transforms;
        int32_t N;
        size_t rank;
        const int32_t index[1] = {0};
        if (!rigid)
            LPI_ASSERT_FAILS(sys, lpi_rigid_body_exact(sys, 0.5, out), LPI_ERR_UNSUPPORTED,
                             "lpi_rigid_body_exact");
        if (!generic) {
            LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 1, index, zero_gradient, zero_energy, NULL),
                             LPI_ERR_UNSUPPORTED, "lpi_add_piece");
            LPI_ASSERT_FAILS(sys, lpi_add_casimir(sys, zero_casimir, NULL), LPI_ERR_UNSUPPORTED,
                             "lpi_add_casimir");
            LPI_ASSERT_FAILS(sys, lpi_poisson_rank(sys, x, lpi_dim(sys), &rank),
                             LPI_ERR_UNSUPPORTED, "lpi_poisson_rank");
        }
        if (!moments)
            LPI_ASSERT_FAILS(sys, lpi_moments_add_product_piece(sys, scalar_zero, scalar_zero, NULL),
                             LPI_ERR_UNSUPPORTED, "lpi_moments_add_product_piece");
        if (!sine_euler) {
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_size(sys, &N), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_size");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, x, 50), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_set_modes");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_get_modes(sys, out, 50), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_get_modes");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_grid(sys, x, 25), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_set_grid");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_get_grid(sys, out, 25), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_get_grid");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_enstrophy(sys, out), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_enstrophy");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_casimir_traces(sys, 2, out), LPI_ERR_UNSUPPORTED,
                             "lpi_sine_euler_casimir_traces");
            LPI_ASSERT_FAILS(sys, lpi_sine_euler_fft_floor(sys, 1, &seconds, &transforms),
                             LPI_ERR_UNSUPPORTED, "lpi_sine_euler_fft_floor");
            const char *matrix_methods[] = {"isomp", "rk4-matrix", "direct-eq5"};
            for (int m = 0; m < 3; ++m) {
                LPI_ASSERT_FAILS(sys, lpi_set_method(sys, matrix_methods[m]), LPI_ERR_UNSUPPORTED,
                                 "lpi_set_method");
                assert_non_null(strstr(lpi_last_error(sys), kind));
                assert_string_equal(lpi_get_method(sys), "leapfrog");
            }
        }
        lpi_destroy(sys);
    }
}

/* A value whose sum of terms passes DBL_MAX but whose half (or mean) does
 * not is no overflow: energies, enstrophies and traces are scaled before
 * they are summed where the sum overflows. */
static void test_values_near_the_largest_double(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    double e = 0.0, c = 0.0;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 1.0, 1.0), LPI_OK);
    const double m[3] = {1e154, 1e154, 0.0};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    assert_int_equal(lpi_energy(sys, &e), LPI_OK);
    assert_true(e == 0.5 * m[0] * m[0] + 0.5 * m[1] * m[1]);
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, &c, 1), LPI_ERR_OVERFLOW, "lpi_casimirs"); /* 2e308 */
    lpi_destroy(sys);
}

static void test_sine_euler_values_near_the_largest_double(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    double e = 0.0;
    if (lpi_sine_euler_create(&sys, 5) != LPI_OK) LPI_SKIP("this build has no sine-Euler (no FFTW3)");
    /* Public coordinates: Re w_(0,1) = Re w_(0,2) = 1e154 (and conjugates). */
    double x[25] = {0}, shell_energy[3], shell_enstrophy[3];
    size_t shells = 0;
    x[1] = 1e154;
    assert_int_equal(lpi_set_state(sys, x, 25), LPI_OK);
    assert_int_equal(lpi_sine_euler_enstrophy(sys, &e), LPI_OK); /* 1e308 */
    assert_true(e == 1e308);
    assert_int_equal(lpi_sine_euler_spectrum(sys, shell_energy, shell_enstrophy, 3, &shells), LPI_OK);
    assert_true(shell_enstrophy[0] == 1e308);
    x[3] = 1e154;
    assert_int_equal(lpi_set_state(sys, x, 25), LPI_OK);
    assert_int_equal(lpi_energy(sys, &e), LPI_OK); /* (1 + 1/4) 1e308 */
    assert_true(fabs(e - 1.25e308) <= 1e-15 * 1.25e308);
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_enstrophy(sys, &e), LPI_ERR_OVERFLOW, "lpi_sine_euler_enstrophy");
    /* w_(1,1) = 1e154 (1 + i), lambda = 1/2: |w|^2 = 2e308 overflows, but
     * each mode's term lambda/2 |w|^2 is 5e307, and H = 1e308. */
    memset(x, 0, sizeof x);
    x[11] = x[12] = 1e154;
    assert_int_equal(lpi_set_state(sys, x, 25), LPI_OK);
    assert_int_equal(lpi_energy(sys, &e), LPI_OK);
    assert_true(fabs(e - 1e308) <= 1e-15 * 1e308);
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_spectrum(sys, shell_energy, shell_enstrophy, 3, &shells),
                     LPI_ERR_OVERFLOW, "lpi_sine_euler_spectrum"); /* the enstrophy shell, 2e308 */
    assert_null(strstr(lpi_last_error(sys), "energy"));
    /* W = w_0 I, w_0 = 1e308: the trace N w_0 overflows, (1/N) tr W = w_0
     * does not; (1/N) tr W^2 = 1e616 does. */
    double traces[2] = {0.0, 0.0};
    memset(x, 0, sizeof x);
    x[0] = 1e308;
    assert_int_equal(lpi_set_state(sys, x, 25), LPI_OK);
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 1, traces), LPI_OK);
    assert_true(fabs(traces[0] - 1e308) <= 1e-15 * 1e308);
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_casimir_traces(sys, 2, traces), LPI_ERR_OVERFLOW,
                     "lpi_sine_euler_casimir_traces");
    assert_non_null(strstr(lpi_last_error(sys), "tr W^2"));
    lpi_destroy(sys);
}

/* A refused number is named in the message, with its value. */
static void test_messages_give_the_value(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    double out[3];
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, -0.5, 10), LPI_ERR_INVALID, "lpi_set_implicit_options");
    assert_non_null(strstr(lpi_last_error(sys), "tolerance must be finite and > 0, got -0.5"));
    LPI_ASSERT_FAILS(sys, lpi_set_implicit_options(sys, INFINITY, 10), LPI_ERR_INVALID, "lpi_set_implicit_options");
    assert_non_null(strstr(lpi_last_error(sys), "got inf"));
    LPI_ASSERT_FAILS(sys, lpi_step(sys, -INFINITY, 1), LPI_ERR_NONFINITE, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "dt = -inf is not finite"));
    LPI_ASSERT_FAILS(sys, lpi_rigid_body_exact(sys, INFINITY, out), LPI_ERR_NONFINITE, "lpi_rigid_body_exact");
    assert_non_null(strstr(lpi_last_error(sys), "t = inf is not finite"));
    lpi_destroy(sys);
}

/* The time after many short calls is their spans summed and rounded once:
 * 10^5 calls of one step of 0.1 end at the time one call of 10^5 steps does,
 * to the bit (each call rounding t + dt drifted 1.3e-11 in 10^6 calls), and
 * so do calls of mixed lengths and a negative dt among them. */
static void test_time_of_many_calls(void **state) {
    (void)state;
    lpi_system *one = NULL, *many = NULL;
    const double x[3] = {0.6, 0.8, 0.1};
    assert_int_equal(lpi_pendulum_create(&one), LPI_OK);
    assert_int_equal(lpi_pendulum_create(&many), LPI_OK);
    assert_int_equal(lpi_set_state(one, x, 3), LPI_OK);
    assert_int_equal(lpi_set_state(many, x, 3), LPI_OK);
    assert_int_equal(lpi_step(one, 0.1, 100000), LPI_OK);
    for (int i = 0; i < 100000; ++i) assert_int_equal(lpi_step(many, 0.1, 1), LPI_OK);
    assert_true(lpi_time(many) == lpi_time(one));
    assert_true(lpi_time(one) == 10000.0);
    /* 7 steps of 0.3, back 3 of 0.3, on 1/3 steps: 4 * 0.3 + 1/3 * 9 */
    assert_int_equal(lpi_set_state(many, x, 3), LPI_OK);
    for (int i = 0; i < 7; ++i) assert_int_equal(lpi_step(many, 0.3, 1), LPI_OK);
    assert_int_equal(lpi_step(many, -0.3, 3), LPI_OK);
    for (int i = 0; i < 9; ++i) assert_int_equal(lpi_step(many, 1.0 / 3.0, 1), LPI_OK);
    assert_true(lpi_time(many) == 4 * 0.3 + 9 * (1.0 / 3.0));
    lpi_destroy(one);
    lpi_destroy(many);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version_and_status_names),
        cmocka_unit_test(test_method_registry),
        cmocka_unit_test(test_create_rejects_bad_inertia),
        cmocka_unit_test(test_null_handle),
        cmocka_unit_test(test_bad_arguments_leave_state_unchanged),
        cmocka_unit_test(test_nonfinite_step_is_rolled_back),
        cmocka_unit_test(test_successful_calls),
        cmocka_unit_test(test_getters),
        cmocka_unit_test(test_wrong_kind_is_unsupported),
        cmocka_unit_test(test_values_near_the_largest_double),
        cmocka_unit_test(test_sine_euler_values_near_the_largest_double),
        cmocka_unit_test(test_messages_give_the_value),
        cmocka_unit_test(test_time_of_many_calls),
    };
    return lpi_run_tests(tests);
}
