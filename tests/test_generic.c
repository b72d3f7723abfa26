/* Generic Lie-Poisson systems: the rigid body and the pendulum written as
 * generic systems reproduce the built-in models to round-off; Poisson rank,
 * user Casimirs, energy; every bad input with its exact status, a message
 * naming the function and the fault, and the state unchanged. */
#include <float.h>

#include "lpi_test.h"

/* so(3): {m1,m2} = -m3, {m1,m3} = m2, {m2,m3} = -m1 (the paper's J). */
static const int32_t kSoI[] = {0, 0, 1}, kSoJ[] = {1, 2, 2}, kSoK[] = {2, 1, 0};
static const double kSoC[] = {-1, 1, -1};
/* e(2) for the pendulum: {x1,x3} = -x2, {x2,x3} = x1. */
static const int32_t kE2I[] = {0, 1}, kE2J[] = {2, 2}, kE2K[] = {1, 0};
static const double kE2C[] = {-1, 1};

static const double kInertia[3] = {1.0, 2.0, 3.0};

static int half_square_grad(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)user;
    g[0] = x[0];
    return 0;
}
static int half_square_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)user;
    *h = 0.5 * x[0] * x[0];
    return 0;
}
static int norm2_casimir(size_t dim, const double *x, double *out, void *user) {
    (void)user;
    *out = 0;
    for (size_t q = 0; q < dim; ++q) *out += x[q] * x[q];
    return 0;
}

static lpi_system *generic_rigid_body(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, kSoI, kSoJ, kSoK, kSoC), LPI_OK);
    for (int32_t k = 0; k < 3; ++k)
        assert_int_equal(lpi_add_piece(sys, 1, &k, lpi_test_axis_gradient, lpi_test_axis_energy, (void *)&kInertia[k]),
                         LPI_OK);
    assert_int_equal(lpi_add_casimir(sys, norm2_casimir, NULL), LPI_OK);
    return sys;
}

static lpi_system *generic_pendulum(void) {
    lpi_system *sys = NULL;
    const int32_t x2 = 1, x3 = 2;
    assert_int_equal(lpi_generic_create(&sys, 3, 2, kE2I, kE2J, kE2K, kE2C), LPI_OK);
    assert_int_equal(lpi_add_piece(sys, 1, &x2, lpi_test_linear_gradient, lpi_test_linear_energy, NULL),
                     LPI_OK);
    assert_int_equal(lpi_add_piece(sys, 1, &x3, half_square_grad, half_square_energy, NULL), LPI_OK);
    return sys;
}

/* Runs both systems side by side and returns the largest distance seen. */
static double max_difference(lpi_system *a, lpi_system *b, const char *method, const double *x0,
                             double dt, int chunks, int64_t steps) {
    double xa[3], xb[3], worst = 0;
    assert_int_equal(lpi_set_method(a, method), LPI_OK);
    assert_int_equal(lpi_set_method(b, method), LPI_OK);
    assert_int_equal(lpi_set_state(a, x0, 3), LPI_OK);
    assert_int_equal(lpi_set_state(b, x0, 3), LPI_OK);
    for (int c = 0; c < chunks; ++c) {
        assert_int_equal(lpi_step(a, dt, steps), LPI_OK);
        assert_int_equal(lpi_step(b, dt, steps), LPI_OK);
        assert_int_equal(lpi_get_state(a, xa, 3), LPI_OK);
        assert_int_equal(lpi_get_state(b, xb, 3), LPI_OK);
        const double d = lpi_test_distance(xa, xb, 3);
        if (d > worst) worst = d;
    }
    return worst;
}

static void test_rigid_body_matches_built_in(void **state) {
    (void)state;
    lpi_system *generic = generic_rigid_body(), *built_in = NULL;
    assert_int_equal(lpi_rigid_body_create(&built_in, kInertia[0], kInertia[1], kInertia[2]), LPI_OK);
    assert_int_equal(lpi_set_split(built_in, "axes"), LPI_OK);
    const double m0[3] = {1.0, 0.5, -0.3};
    const char *methods[] = {"lie-trotter", "leapfrog", "triple-jump-4", "rk4"};
    for (int q = 0; q < 4; ++q) {
        const double d = max_difference(generic, built_in, methods[q], m0, 0.05, 10, 100);
        printf("rigid body, %s, 1000 steps: generic vs built-in %.3g\n", methods[q], d);
        /* Round-off only: up to 6000 flows, the built-in with compensated
         * state, the generic without, so ~u sqrt(flows) times the growth of
         * perturbations along this orbit. */
        assert_true(d < 5e-13);
    }
    /* Energy and the user's Casimir agree with the built-in ones. */
    double h1, h2, c1, c2;
    assert_int_equal(lpi_energy(generic, &h1), LPI_OK);
    assert_int_equal(lpi_energy(built_in, &h2), LPI_OK);
    assert_true(fabs(h1 - h2) < 1e-14);
    assert_int_equal(lpi_casimir_count(generic), 1);
    assert_int_equal(lpi_casimirs(generic, &c1, 1), LPI_OK);
    assert_int_equal(lpi_casimirs(built_in, &c2, 1), LPI_OK);
    assert_true(fabs(c1 - c2) < 1e-14);
    lpi_destroy(generic);
    lpi_destroy(built_in);
}

static void test_pendulum_matches_built_in(void **state) {
    (void)state;
    lpi_system *generic = generic_pendulum(), *built_in = NULL;
    assert_int_equal(lpi_pendulum_create(&built_in), LPI_OK);
    const double x0[3] = {0.6, -0.8, 1.2};
    const char *methods[] = {"lie-trotter", "leapfrog", "triple-jump-4", "rk4"};
    for (int q = 0; q < 4; ++q) {
        const double d = max_difference(generic, built_in, methods[q], x0, 0.05, 10, 100);
        printf("pendulum, %s, 1000 steps: generic vs built-in %.3g\n", methods[q], d);
        assert_true(d < 1e-13);
    }
    double h1, h2;
    assert_int_equal(lpi_energy(generic, &h1), LPI_OK);
    assert_int_equal(lpi_energy(built_in, &h2), LPI_OK);
    assert_true(fabs(h1 - h2) < 1e-14);
    assert_int_equal(lpi_casimir_count(generic), 0);
    lpi_destroy(generic);
    lpi_destroy(built_in);
}

static void test_poisson_rank(void **state) {
    (void)state;
    lpi_system *rb = generic_rigid_body(), *pend = generic_pendulum();
    size_t rank = 99;
    const double m[3] = {0.3, -1.2, 0.7}, zero[3] = {0, 0, 0};
    assert_int_equal(lpi_poisson_rank(rb, m, 3, &rank), LPI_OK);
    assert_int_equal(rank, 2);
    assert_int_equal(lpi_poisson_rank(rb, zero, 3, &rank), LPI_OK);
    assert_int_equal(rank, 0);
    assert_int_equal(lpi_poisson_rank(pend, m, 3, &rank), LPI_OK);
    assert_int_equal(rank, 2);
    /* At x1 = x2 = 0 the pendulum's J vanishes. */
    const double axis[3] = {0, 0, 5};
    assert_int_equal(lpi_poisson_rank(pend, axis, 3, &rank), LPI_OK);
    assert_int_equal(rank, 0);
    /* An abelian algebra (no constants) has rank 0 everywhere. */
    lpi_system *abelian = NULL;
    assert_int_equal(lpi_generic_create(&abelian, 4, 0, NULL, NULL, NULL, NULL), LPI_OK);
    const double y[4] = {1, 2, 3, 4};
    assert_int_equal(lpi_poisson_rank(abelian, y, 4, &rank), LPI_OK);
    assert_int_equal(rank, 0);
    lpi_destroy(abelian);
    lpi_destroy(rb);
    lpi_destroy(pend);
}

static void test_either_order_and_agreeing_duplicates(void **state) {
    (void)state;
    /* so(3) given with some pairs reversed and one entry repeated. */
    const int32_t i[] = {1, 0, 2, 1}, j[] = {0, 2, 1, 0}, k[] = {2, 1, 0, 2};
    const double c[] = {1, 1, 1, 1};
    lpi_system *sys = NULL, *reference = generic_rigid_body();
    assert_int_equal(lpi_generic_create(&sys, 3, 4, i, j, k, c), LPI_OK);
    for (int32_t a = 0; a < 3; ++a)
        assert_int_equal(lpi_add_piece(sys, 1, &a, lpi_test_axis_gradient, lpi_test_axis_energy, (void *)&kInertia[a]),
                         LPI_OK);
    const double m0[3] = {1.0, 0.5, -0.3};
    assert_true(max_difference(sys, reference, "leapfrog", m0, 0.1, 1, 50) == 0.0);
    lpi_destroy(sys);
    lpi_destroy(reference);
}

/* ---- bad input ------------------------------------------------------------- */

static void expect_create_failure(size_t dim, size_t nnz, const int32_t *i, const int32_t *j,
                                  const int32_t *k, const double *c, int status,
                                  const char *detail) {
    lpi_system *sys = (lpi_system *)&sys; /* must come back NULL */
    LPI_ASSERT_FAILS(NULL, lpi_generic_create(&sys, dim, nnz, i, j, k, c), status,
                     "lpi_generic_create");
    assert_null(sys);
    if (strstr(lpi_last_error(NULL), detail) == NULL)
        fail_msg("message '%s' does not mention '%s'", lpi_last_error(NULL), detail);
}

static void test_create_errors(void **state) {
    (void)state;
    const int32_t zero[] = {0}, one[] = {1}, two[] = {2}, three[] = {3}, minus[] = {-1};
    const double unit[] = {1.0};
    expect_create_failure(0, 0, NULL, NULL, NULL, NULL, LPI_ERR_INVALID, "dim must be >= 1");
    expect_create_failure(3, 1, NULL, one, two, unit, LPI_ERR_NULL, "i is NULL");
    expect_create_failure(3, 1, zero, one, two, NULL, LPI_ERR_NULL, "c is NULL");
    expect_create_failure(3, 1, zero, one, three, unit, LPI_ERR_INVALID,
                          "entry 0: k = 3 is outside 0..2");
    expect_create_failure(3, 1, minus, one, two, unit, LPI_ERR_INVALID,
                          "entry 0: i = -1 is outside 0..2");
    const double nan[] = {NAN};
    expect_create_failure(3, 1, zero, one, two, nan, LPI_ERR_NONFINITE, "entry 0: c = nan");
    /* {x_1, x_1} = x_2: not antisymmetric. */
    expect_create_failure(3, 1, one, one, two, unit, LPI_ERR_INVALID, "{x_1, x_1} must be 0");
    /* {x_0, x_1} = x_2 and {x_1, x_0} = x_2 contradict antisymmetry. */
    {
        const int32_t i[] = {0, 1}, j[] = {1, 0}, k[] = {2, 2};
        const double c[] = {1.0, 1.0};
        expect_create_failure(3, 2, i, j, k, c, LPI_ERR_INVALID,
                              "entry 1: gives {x_1, x_0} the coefficient 1 on x_2, but entry 0 "
                              "implies -1");
    }
    /* The same entry twice with different values. */
    {
        const int32_t i[] = {0, 0}, j[] = {1, 1}, k[] = {2, 2};
        const double c[] = {1.0, 2.0};
        expect_create_failure(3, 2, i, j, k, c, LPI_ERR_INVALID, "but entry 0 implies 1");
    }
    /* [e0,e1] = e2, [e1,e2] = e1: Jac(0,1,2) = -e2 != 0. */
    {
        const int32_t i[] = {0, 1}, j[] = {1, 2}, k[] = {2, 1};
        const double c[] = {1.0, 1.0};
        expect_create_failure(3, 2, i, j, k, c, LPI_ERR_INVALID,
                              "Jacobi identity at (i, j, k) = (0, 1, 2)");
        assert_non_null(strstr(lpi_last_error(NULL), "on x_2"));
    }
    /* so(3) plus a fourth element with {x_3, x_0} = x_3 and nothing else:
     * Jac(1, 2, 3) = {{x_1, x_2}, x_3} = -{x_0, x_3} = x_3. */
    {
        const int32_t i[] = {0, 0, 1, 3}, j[] = {1, 2, 2, 0}, k[] = {2, 1, 0, 3};
        const double c[] = {-1, 1, -1, 1};
        expect_create_failure(4, 4, i, j, k, c, LPI_ERR_INVALID,
                              "Jacobi identity at (i, j, k) = (1, 2, 3)");
        assert_non_null(strstr(lpi_last_error(NULL), "coefficient 1 on x_3"));
    }
    /* The same at any scale: the Jacobiator is quadratic in the constants,
     * and its products overflowed past 1.3e154 (inf against inf passed) and
     * underflowed below 1e-162 (0 against 0). so(3) scaled stays accepted. */
    const double scales[] = {1e155, 1e300, DBL_MAX, 1e-170, 1e-300, 5e-324};
    for (size_t s = 0; s < sizeof scales / sizeof scales[0]; ++s) {
        const int32_t i[] = {0, 1}, j[] = {1, 2}, k[] = {2, 1};
        const double c[] = {scales[s], scales[s]};
        expect_create_failure(3, 2, i, j, k, c, LPI_ERR_INVALID, "Jacobi identity at (i, j, k) = (0, 1, 2)");
        const double so3[] = {-scales[s], scales[s], -scales[s]};
        lpi_system *sys = NULL;
        assert_int_equal(lpi_generic_create(&sys, 3, 3, kSoI, kSoJ, kSoK, so3), LPI_OK);
        lpi_destroy(sys);
    }
    LPI_ASSERT_FAILS(NULL, lpi_generic_create(NULL, 3, 3, kSoI, kSoJ, kSoK, kSoC), LPI_ERR_NULL,
                     "lpi_generic_create");
}

static int ones_gradient(size_t n, const double *x, double *g, void *user) {
    (void)x; (void)user;
    for (size_t p = 0; p < n; ++p) g[p] = 1.0;
    return 0;
}
static int sum_energy(size_t n, const double *x, double *h, void *user) {
    (void)user;
    *h = 0.0;
    for (size_t p = 0; p < n; ++p) *h += x[p];
    return 0;
}

/* R x| R^n ({x_0, x_a} = x_a, a = 1 .. n) is a Lie algebra, R^n an abelian
 * piece; one bracket more, {x_1, x_2} = x_1, breaks Jacobi at (0, 1, 2), and
 * x_0 among a piece's indices breaks abelianness, each named. (The checks
 * follow the brackets: they took n^2 triples and pairs, 37 s for the
 * algebra at n = 20000 and 25 s for a piece of 160000 indices.) */
static void test_large_semidirect_product(void **state) {
    (void)state;
    enum { n = 3000 };
    static int32_t i[n + 1], j[n + 1], k[n + 1], indices[n + 1];
    static double c[n + 1];
    for (int a = 0; a < n; ++a) i[a] = 0, j[a] = a + 1, k[a] = a + 1, c[a] = 1.0, indices[a] = a + 1;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, n + 1, n, i, j, k, c), LPI_OK);
    indices[n] = 0;
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, n + 1, indices, ones_gradient, sum_energy, NULL),
                     LPI_ERR_NOT_ABELIAN, "lpi_add_piece");
    assert_non_null(strstr(lpi_last_error(sys), "indices 1 and 0 do not commute, {x_1, x_0} = -1 x_1"));
    assert_int_equal(lpi_add_piece(sys, n, indices, ones_gradient, sum_energy, NULL), LPI_OK);
    lpi_destroy(sys);
    i[n] = 1, j[n] = 2, k[n] = 1, c[n] = 1.0;
    expect_create_failure(n + 1, n + 1, i, j, k, c, LPI_ERR_INVALID, "Jacobi identity at (i, j, k) = (0, 1, 2)");
}

static int failing_grad(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x;
    int *calls = (int *)user;
    g[0] = 1.0;
    return ++*calls > 5 ? 7 : 0; /* fails part-way through a run */
}
static int nan_grad(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x; (void)user;
    g[0] = NAN;
    return 0;
}
static int failing_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)x; (void)user;
    *h = 0;
    return 3;
}
static int failing_casimir(size_t dim, const double *x, double *out, void *user) {
    (void)dim; (void)x; (void)user;
    *out = 0;
    return 4;
}

static void test_add_piece_errors(void **state) {
    (void)state;
    lpi_system *sys = generic_rigid_body();
    const double m0[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m0, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK);
    const int32_t pair[] = {0, 1}, out_of_range[] = {3}, negative[] = {-2}, duplicate[] = {2, 2};
    const int32_t ok = 0, four[] = {0, 1, 2, 0};

    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 2, pair, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_NOT_ABELIAN, "lpi_add_piece");
    assert_non_null(strstr(lpi_last_error(sys), "indices 0 and 1 do not commute, {x_0, x_1} = -1 x_2"));
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 1, out_of_range, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_INVALID, "lpi_add_piece");
    assert_non_null(strstr(lpi_last_error(sys), "indices[0] = 3 is outside 0..2"));
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 1, negative, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_INVALID, "lpi_add_piece");
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 2, duplicate, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_INVALID, "lpi_add_piece");
    assert_non_null(strstr(lpi_last_error(sys), "indices[0] and indices[1] are both 2"));
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 0, &ok, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_INVALID, "lpi_add_piece");
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 4, four, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_INVALID, "lpi_add_piece");
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 1, &ok, NULL, lpi_test_axis_energy, NULL), LPI_ERR_NULL,
                     "lpi_add_piece");
    assert_non_null(strstr(lpi_last_error(sys), "gradient callback is NULL"));
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 1, &ok, lpi_test_axis_gradient, NULL, NULL), LPI_ERR_NULL,
                     "lpi_add_piece");
    assert_non_null(strstr(lpi_last_error(sys), "energy callback is NULL"));
    LPI_ASSERT_FAILS(sys, lpi_add_piece(sys, 1, NULL, lpi_test_axis_gradient, lpi_test_axis_energy, NULL), LPI_ERR_NULL,
                     "lpi_add_piece");
    LPI_ASSERT_FAILS(NULL, lpi_add_piece(NULL, 1, &ok, lpi_test_axis_gradient, lpi_test_axis_energy, NULL), LPI_ERR_NULL,
                     "lpi_add_piece");
    LPI_ASSERT_FAILS(sys, lpi_add_casimir(sys, NULL, NULL), LPI_ERR_NULL, "lpi_add_casimir");
    assert_int_equal(lpi_casimir_count(sys), 1);

    /* Nothing was added: the system still equals a fresh generic rigid body. */
    lpi_system *fresh = generic_rigid_body();
    assert_true(max_difference(sys, fresh, "leapfrog", m0, 0.1, 1, 20) == 0.0);
    lpi_destroy(fresh);

    size_t rank = 0;
    const double bad[3] = {1, NAN, 0};
    LPI_ASSERT_FAILS(sys, lpi_poisson_rank(sys, m0, 2, &rank), LPI_ERR_SIZE, "lpi_poisson_rank");
    LPI_ASSERT_FAILS(sys, lpi_poisson_rank(sys, bad, 3, &rank), LPI_ERR_NONFINITE, "lpi_poisson_rank");
    LPI_ASSERT_FAILS(sys, lpi_poisson_rank(sys, m0, 3, NULL), LPI_ERR_NULL, "lpi_poisson_rank");
    LPI_ASSERT_FAILS(sys, lpi_poisson_rank(sys, NULL, 3, &rank), LPI_ERR_NULL, "lpi_poisson_rank");
    lpi_destroy(sys);

    /* Built-in models have no user pieces. */
    lpi_system *rb = NULL;
    assert_int_equal(lpi_rigid_body_create(&rb, 1, 2, 3), LPI_OK);
    LPI_ASSERT_FAILS(rb, lpi_add_piece(rb, 1, &ok, lpi_test_axis_gradient, lpi_test_axis_energy, NULL),
                     LPI_ERR_UNSUPPORTED, "lpi_add_piece");
    LPI_ASSERT_FAILS(rb, lpi_add_casimir(rb, norm2_casimir, NULL), LPI_ERR_UNSUPPORTED,
                     "lpi_add_casimir");
    LPI_ASSERT_FAILS(rb, lpi_poisson_rank(rb, m0, 3, &rank), LPI_ERR_UNSUPPORTED,
                     "lpi_poisson_rank");
    lpi_destroy(rb);
}

static void test_callback_failures_roll_back(void **state) {
    (void)state;
    const double m0[3] = {1.0, 0.5, -0.3};
    const char *methods[] = {"leapfrog", "rk4"};
    for (int q = 0; q < 2; ++q) {
        lpi_system *sys = NULL;
        int calls = 0;
        const int32_t x0 = 0, x1 = 1;
        assert_int_equal(lpi_generic_create(&sys, 3, 3, kSoI, kSoJ, kSoK, kSoC), LPI_OK);
        assert_int_equal(lpi_add_piece(sys, 1, &x0, lpi_test_axis_gradient, lpi_test_axis_energy, (void *)&kInertia[0]),
                         LPI_OK);
        assert_int_equal(lpi_add_piece(sys, 1, &x1, failing_grad, failing_energy, &calls), LPI_OK);
        assert_int_equal(lpi_set_method(sys, methods[q]), LPI_OK);
        assert_int_equal(lpi_set_state(sys, m0, 3), LPI_OK);
        LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.1, 10), LPI_ERR_CALLBACK, "lpi_step");
        assert_non_null(strstr(lpi_last_error(sys),
                               "the gradient callback of piece 1 (indices {1}) returned 7"));
        assert_true(lpi_time(sys) == 0.0);
        double h;
        LPI_ASSERT_FAILS(sys, lpi_energy(sys, &h), LPI_ERR_CALLBACK, "lpi_energy");
        assert_non_null(strstr(lpi_last_error(sys), "energy callback of piece 1"));
        lpi_destroy(sys);
    }
    /* A non-finite gradient. */
    lpi_system *sys = NULL;
    const int32_t x2 = 2;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, kSoI, kSoJ, kSoK, kSoC), LPI_OK);
    assert_int_equal(lpi_add_piece(sys, 1, &x2, nan_grad, lpi_test_axis_energy, (void *)&kInertia[2]), LPI_OK);
    assert_int_equal(lpi_set_state(sys, m0, 3), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.1, 2), LPI_ERR_CALLBACK, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "piece 0 (indices {2}) gave a non-finite component 0"));
    /* A failing Casimir callback. */
    assert_int_equal(lpi_add_casimir(sys, norm2_casimir, NULL), LPI_OK);
    assert_int_equal(lpi_add_casimir(sys, failing_casimir, NULL), LPI_OK);
    assert_int_equal(lpi_casimir_count(sys), 2);
    double c[2];
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, c, 2), LPI_ERR_CALLBACK, "lpi_casimirs");
    assert_non_null(strstr(lpi_last_error(sys), "Casimir 1 returned 4"));
    lpi_destroy(sys);
}

/* The gradient buffer holds zeros when the callback is called, as the
 * energy's and the Casimirs' outputs do: a callback that writes only its
 * nonzero components, or adds into them, gets the same results on every
 * call. The buffer kept the last call's values, a failed call's too (the
 * same step from the same state then ended elsewhere). */
static int nonzero_on_entry;
static int adding_gradient(size_t n, const double *x, double *g, void *user) {
    for (size_t p = 0; p < n; ++p) nonzero_on_entry |= g[p] != 0.0;
    g[0] += x[0]; /* H = x_0^2 / 2 on {0, 1}: g[1] stays 0 */
    int *calls_before_failing = user;
    if (*calls_before_failing > 0 && --*calls_before_failing == 0) {
        g[1] = 5.0;
        return 3;
    }
    return 0;
}

static void test_gradient_buffer_zeroed(void **state) {
    (void)state;
    const double x0[3] = {0.3, -0.2, 0.7};
    const char *methods[] = {"leapfrog", "yoshida-6", "rk4", "implicit-midpoint"};
    for (int q = 0; q < 4; ++q) {
        lpi_system *sys = NULL, *fresh = NULL;
        int fails_at[2] = {3, 0};
        const int32_t pair[2] = {0, 1}, angle = 2;
        for (int copy = 0; copy < 2; ++copy) {
            lpi_system **made = copy == 0 ? &sys : &fresh;
            assert_int_equal(lpi_generic_create(made, 3, 2, kE2I, kE2J, kE2K, kE2C), LPI_OK);
            assert_int_equal(lpi_add_piece(*made, 2, pair, adding_gradient, half_square_energy, &fails_at[copy]),
                             LPI_OK);
            assert_int_equal(lpi_add_piece(*made, 1, &angle, half_square_grad, half_square_energy, NULL), LPI_OK);
            assert_int_equal(lpi_set_method(*made, methods[q]), LPI_OK);
            assert_int_equal(lpi_set_state(*made, x0, 3), LPI_OK);
        }
        nonzero_on_entry = 0;
        LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.1, 10), LPI_ERR_CALLBACK, "lpi_step");
        assert_int_equal(lpi_step(sys, 0.1, 10), LPI_OK);
        assert_int_equal(lpi_step(fresh, 0.1, 10), LPI_OK);
        assert_false(nonzero_on_entry);
        double a[3], b[3];
        assert_int_equal(lpi_get_state(sys, a, 3), LPI_OK);
        assert_int_equal(lpi_get_state(fresh, b, 3), LPI_OK);
        assert_memory_equal(a, b, sizeof a);
        lpi_destroy(sys);
        lpi_destroy(fresh);
    }
}

/* sl(2) (x_e, x_f, x_h; {h,e} = 2e, {h,f} = -2f, {e,f} = h) with the piece
 * H = x_h^2 / 2: x_e -> x_e e^-s, x_f -> x_f e^s with s = 2 x_h t, whose
 * closed form is the plane path's hyperbolic case. However far one flow
 * contracts x_e, it keeps its relative accuracy and the Casimir
 * x_h^2 + 4 x_e x_f stays at round-off (cosh - sinh lost e^2s of it). */
static void test_hyperbolic_piece_keeps_contracted_components(void **state) {
    (void)state;
    const int32_t i[] = {2, 2, 0}, j[] = {0, 1, 1}, k[] = {0, 1, 2};
    const double c[] = {2, -2, 1};
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    const int32_t h = 2;
    assert_int_equal(lpi_add_piece(sys, 1, &h, half_square_grad, half_square_energy, NULL), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    for (double s = 0.5; s <= 32.0; s *= 2) {
        const double x0[3] = {0.3, -0.7, 1.25}, dt = s / (2 * 1.25); /* 2 x_h dt = s exactly */
        double x[3];
        assert_int_equal(lpi_set_state(sys, x0, 3), LPI_OK);
        assert_int_equal(lpi_step(sys, dt, 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, x, 3), LPI_OK);
        const long double e = 0.3L * expl(-(long double)s), f = -0.7L * expl((long double)s);
        const double casimir0 = 1.25 * 1.25 + 4 * 0.3 * -0.7;
        const long double casimir = (long double)x[2] * x[2] + 4.0L * x[0] * x[1];
        const double error_e = (double)(fabsl(x[0] - e) / fabsl(e));
        const double error_f = (double)(fabsl(x[1] - f) / fabsl(f));
        const double drift = (double)(fabsl(casimir - casimir0) / fabs(casimir0));
        printf("sl(2), H = x_h^2/2, s = %g: rel. error x_e %.1e, x_f %.1e; Casimir %.1e\n", s, error_e,
               error_f, drift);
        assert_true(error_e < 4 * 2.2e-16 && error_f < 4 * 2.2e-16);
        assert_true(x[2] == x0[2]);
        assert_true(drift < 8 * 2.2e-16);
    }
    lpi_destroy(sys);
}

static void test_no_pieces(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, kSoI, kSoJ, kSoK, kSoC), LPI_OK);
    const double m0[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m0, 3), LPI_OK);
    const char *methods[] = {"lie-trotter", "leapfrog", "rk4"};
    for (int q = 0; q < 3; ++q) {
        assert_int_equal(lpi_set_method(sys, methods[q]), LPI_OK);
        LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.1, 1), LPI_ERR_INVALID, "lpi_step");
        assert_non_null(strstr(lpi_last_error(sys), "no Hamiltonian pieces"));
    }
    double h = 1;
    assert_int_equal(lpi_energy(sys, &h), LPI_OK);
    assert_true(h == 0.0);
    lpi_destroy(sys);
}

/* H = x1: a spin in a field, so(3) rotated by the same angle every flow. */
static int field_gradient(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x; (void)user;
    g[0] = 1.0;
    return 0;
}
static int field_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)user;
    *h = x[0];
    return 0;
}

/* A rotation by a constant angle keeps |x|^2 without bias: over many random
 * states the mean change of |x|^2 in one flow is zero within its standard
 * error. Formed as x + (W x) from the rounded cosine and sine, its
 * determinant was off 1 by the same amount every flow (t = 0.7: 106
 * standard errors from zero over 2e5 states); three shears keep it 1. */
static void test_constant_rotation_without_bias(void **state) {
    (void)state;
    static const int32_t i[] = {0, 1, 2}, j[] = {1, 2, 0}, k[] = {2, 0, 1};
    static const double c[] = {1.0, 1.0, 1.0};
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    const int32_t axis = 0;
    assert_int_equal(lpi_add_piece(sys, 1, &axis, field_gradient, field_energy, NULL), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    const double steps[3] = {0.7, 0.3, 2.5}; /* 2.5: the turned shears (past pi / 2) */
    for (int d = 0; d < 3; ++d) {
        uint64_t seed = 99;
        lpi_test_mean change = {0};
        for (int m = 0; m < 60000; ++m) {
            double x[3], y[3];
            for (int e = 0; e < 3; ++e) x[e] = lpi_test_uniform(&seed);
            assert_int_equal(lpi_set_state(sys, x, 3), LPI_OK);
            assert_int_equal(lpi_step(sys, steps[d], 1), LPI_OK);
            assert_int_equal(lpi_get_state(sys, y, 3), LPI_OK);
            long double before = 0.0L, after = 0.0L;
            for (int e = 0; e < 3; ++e) before += (long double)x[e] * x[e], after += (long double)y[e] * y[e];
            lpi_test_mean_add(&change, (double)((after - before) / before));
        }
        double mean, spread;
        const double z = lpi_test_mean_z(&change, &mean, &spread);
        printf("so(3), H = x1, one flow of %g: mean change of |x|^2 %.2e, %.1f standard errors "
               "(rounding: %.2e a flow)\n", steps[d], mean, z, spread);
        assert_true(fabs(z) < 5.0);
    }
    lpi_destroy(sys);
}

/* H = a h on sl(2) (h, e, f: {h, e} = 2 e, {h, f} = -2 f, {e, f} = h), a
 * from the user pointer. */
static int scaled_gradient(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x;
    g[0] = *(const double *)user;
    return 0;
}
static int scaled_energy(size_t n, const double *x, double *h, void *user) {
    (void)n;
    *h = *(const double *)user * x[0];
    return 0;
}

/* e1 f1 / (e0 f0) - 1, the products exact (fma). */
static double product_change(double e0, double f0, double e1, double f1) {
    const double p0 = e0 * f0, q0 = fma(e0, f0, -p0), p1 = e1 * f1, q1 = fma(e1, f1, -p1);
    return ((p1 - p0) + (q1 - q0)) / p0;
}

/* The flow of H = a h scales e by e^-2at and f by e^2at: it keeps e f, and
 * the Casimir h^2 + 4 e f, whatever the state. The two factors are
 * constants of every flow; rounded apart (the plane's closed form, or expm1
 * and -v / (1 + v) in doubles) their product was off 1 by the same amount
 * every flow: 690 standard errors from zero over 2e5 states at t = a = 1.
 * Taken to twice the precision from one expm1, and applied by one rounding
 * of each product, they change e f by nothing measurable. t = 5, a = 1
 * contracts e by e^-10 (the reciprocal side). */
static void test_constant_scaling_without_bias(void **state) {
    (void)state;
    static const int32_t i[] = {0, 0, 1}, j[] = {1, 2, 2}, k[] = {1, 2, 0};
    static const double c[] = {2.0, -2.0, 1.0};
    static const double cases[][2] = {{0.03, 0.3}, {0.7, 0.3}, {1.0, 1.0}, {0.3, 3.0}, {5.0, 1.0}};
    for (size_t q = 0; q < sizeof cases / sizeof cases[0]; ++q) {
        double a = cases[q][1];
        lpi_system *sys = NULL;
        assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
        const int32_t h = 0;
        assert_int_equal(lpi_add_piece(sys, 1, &h, scaled_gradient, scaled_energy, &a), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
        uint64_t seed = 7;
        lpi_test_mean change = {0};
        for (int m = 0; m < 60000; ++m) {
            double x[3], y[3];
            for (int e = 0; e < 3; ++e) x[e] = lpi_test_uniform(&seed);
            assert_int_equal(lpi_set_state(sys, x, 3), LPI_OK);
            assert_int_equal(lpi_step(sys, cases[q][0], 1), LPI_OK);
            assert_int_equal(lpi_get_state(sys, y, 3), LPI_OK);
            lpi_test_mean_add(&change, product_change(x[1], x[2], y[1], y[2]));
        }
        double mean, spread;
        const double z = lpi_test_mean_z(&change, &mean, &spread);
        printf("sl(2), H = %g h, one flow of %g: mean change of e f %.2e, %.1f standard errors "
               "(rounding: %.2e a flow)\n", a, cases[q][0], mean, z, spread);
        assert_true(fabs(z) < 5.0);
        lpi_destroy(sys);
    }
}

/* The same for scalings that share no expm1 with a group: R x| R^4 with
 * {h, x1} = 2 x1, {h, x2} = -2 x2, {h, x3} = 3 x3, {h, x4} = -3 x4 under
 * H = h keeps x1 x2 and x3 x4; 3 is no multiple of 2, so x3 and x4 scale
 * alone, and from expm1(0.3) and expm1(-0.3) the product x3 x4 moved by 252
 * standard errors over 2e5 flows. Each now takes e^-a as the reciprocal of
 * e^a from expm1(|a|). */
static void test_lone_scalings_without_bias(void **state) {
    (void)state;
    static const int32_t i[] = {0, 0, 0, 0}, j[] = {1, 2, 3, 4}, k[] = {1, 2, 3, 4};
    static const double c[] = {2.0, -2.0, 3.0, -3.0};
    double a = 1.0;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 5, 4, i, j, k, c), LPI_OK);
    const int32_t h = 0;
    assert_int_equal(lpi_add_piece(sys, 1, &h, scaled_gradient, scaled_energy, &a), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    uint64_t seed = 11;
    lpi_test_mean changes[2] = {{0.0, 0.0, 0}, {0.0, 0.0, 0}};
    for (int m = 0; m < 60000; ++m) {
        double x[5], y[5];
        for (int e = 0; e < 5; ++e) x[e] = 1.0 + 0.5 * lpi_test_uniform(&seed);
        assert_int_equal(lpi_set_state(sys, x, 5), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.1, 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, y, 5), LPI_OK);
        lpi_test_mean_add(&changes[0], product_change(x[1], x[2], y[1], y[2]));
        lpi_test_mean_add(&changes[1], product_change(x[3], x[4], y[3], y[4]));
    }
    for (int q = 0; q < 2; ++q) {
        double mean, spread;
        const double z = lpi_test_mean_z(&changes[q], &mean, &spread);
        printf("R x| R^4, weights %s, one flow of 0.1: mean change of %s %.2e, %.1f standard errors\n",
               q ? "+-3 (alone)" : "+-2 (a group)", q ? "x3 x4" : "x1 x2", mean, z);
        assert_true(fabs(z) < 5.0);
    }
    lpi_destroy(sys);
}

/* H = J1 + 0.7 P1 on the abelian set {J1, P1} of e(3). */
static int pair_gradient(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x; (void)user;
    g[0] = 1.0, g[1] = 0.7;
    return 0;
}
static int pair_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)user;
    *h = x[0] + 0.7 * x[1];
    return 0;
}

/* e(3) (J = 0..2, P = 3..5) with H = J1 rotates (J2, J3) and (P2, P3) by the
 * same constant angle: two blocks sharing no index; with H = J1 + 0.7 P1 the
 * 4 x 4 block is coupled, but it is the product of two that commute, each
 * one parameter's. Taken whole, the block went the Pade way, its exp(tA)
 * rounded alike every flow, and |P|^2 moved with one sign (66 and 187
 * standard errors at t = 0.7); as factors and blocks, planes by shears and
 * the rest by its series, neither |P|^2 nor J.P has a measurable bias. */
static void changes_of_e3(lpi_system *sys, const char *hamiltonian);
static void test_disjoint_blocks_without_bias(void **state) {
    (void)state;
    static const int32_t i[] = {0, 1, 2, 0, 1, 2, 0, 1, 2}, j[] = {1, 2, 0, 4, 5, 3, 5, 3, 4},
                         k[] = {2, 0, 1, 5, 3, 4, 4, 5, 3};
    static const double c[] = {1, 1, 1, 1, 1, 1, -1, -1, -1};
    for (int pair = 0; pair < 2; ++pair) {
        lpi_system *sys = NULL;
        assert_int_equal(lpi_generic_create(&sys, 6, 9, i, j, k, c), LPI_OK);
        const int32_t set[2] = {0, 3};
        if (pair)
            assert_int_equal(lpi_add_piece(sys, 2, set, pair_gradient, pair_energy, NULL), LPI_OK);
        else
            assert_int_equal(lpi_add_piece(sys, 1, set, field_gradient, field_energy, NULL), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
        changes_of_e3(sys, pair ? "J1 + 0.7 P1" : "J1");
        lpi_destroy(sys);
    }
}

/* The mean changes of |P|^2 and J.P in one flow of 0.7 over random states. */
static void changes_of_e3(lpi_system *sys, const char *hamiltonian) {
    uint64_t seed = 7;
    lpi_test_mean changes[2] = {{0.0, 0.0, 0}, {0.0, 0.0, 0}};
    for (int m = 0; m < 60000; ++m) {
        double x[6], y[6];
        for (int e = 0; e < 6; ++e) x[e] = lpi_test_uniform(&seed);
        assert_int_equal(lpi_set_state(sys, x, 6), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.7, 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, y, 6), LPI_OK);
        long double p0 = 0.0L, p1 = 0.0L, q0 = 0.0L, q1 = 0.0L;
        for (int e = 3; e < 6; ++e) {
            p0 += (long double)x[e] * x[e], p1 += (long double)y[e] * y[e];
            q0 += (long double)x[e - 3] * x[e], q1 += (long double)y[e - 3] * y[e];
        }
        lpi_test_mean_add(&changes[0], (double)((p1 - p0) / p0));
        lpi_test_mean_add(&changes[1], (double)((q1 - q0) / sqrtl(3.0L * p0)));
    }
    for (int q = 0; q < 2; ++q) {
        double mean, spread;
        const double z = lpi_test_mean_z(&changes[q], &mean, &spread);
        printf("e(3), H = %s, one flow of 0.7: mean change of %s %.2e, %.1f standard errors\n",
               hamiltonian, q == 0 ? "|P|^2" : "J.P", mean, z);
        assert_true(fabs(z) < 5.0);
    }
}

/* R^2 x| R^3 with [e0, f] = M f and [e1, f] = -M f: the pieces' matrices
 * cancel, C_1 = -C_0. H = a0 x0 + a1 x1 flows by exp(t (a0 - a1) C_0):
 * the identity for a0 = a1, however large. Applied as the factors exp(t a0
 * C_0) exp(t a1 C_1), each growing what the other shrinks, the product had
 * scaled x by 1e25 (a0 = a1 = 100, t = 1). */
static double amplitudes[2];
static int amplitude_gradient(size_t n, const double *x, double *g, void *user) {
    (void)x, (void)user;
    for (size_t p = 0; p < n; ++p) g[p] = amplitudes[p];
    return 0;
}
static int amplitude_energy(size_t n, const double *x, double *h, void *user) {
    (void)user;
    *h = 0.0;
    for (size_t p = 0; p < n; ++p) *h += amplitudes[p] * x[p];
    return 0;
}
static lpi_system *cancelling_actions(int parameters) {
    static const double M[3][3] = {{0.3, 1.0, 0.0}, {-1.0, 0.3, 0.5}, {0.2, 0.0, -0.7}};
    int32_t i[18], j[18], k[18];
    double c[18];
    size_t nnz = 0;
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row)
            for (int p = 0; p < parameters && M[row][col] != 0.0; ++p)
                i[nnz] = p, j[nnz] = col + 2, k[nnz] = row + 2, c[nnz++] = p ? -M[row][col] : M[row][col];
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 5, nnz, i, j, k, c), LPI_OK);
    const int32_t set[2] = {0, 1};
    assert_int_equal(lpi_add_piece(sys, (size_t)parameters, set, amplitude_gradient, amplitude_energy, NULL),
                     LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    return sys;
}
static void test_cancelling_factors(void **state) {
    (void)state;
    lpi_system *both = cancelling_actions(2), *one = cancelling_actions(1);
    const double x[5] = {0.1, 0.2, 0.5, -0.25, 0.75};
    const double cases[][2] = {{1, 1}, {20, 20}, {100, 100}, {50, 49}, {-30, -31.5}, {7, 3}};
    for (size_t n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
        double y[5], z[5];
        amplitudes[0] = cases[n][0], amplitudes[1] = cases[n][1];
        assert_int_equal(lpi_set_state(both, x, 5), LPI_OK);
        assert_int_equal(lpi_step(both, 1.0, 1), LPI_OK);
        assert_int_equal(lpi_get_state(both, y, 5), LPI_OK);
        /* The same flow on e0's action alone, a0 - a1 its amplitude. */
        amplitudes[0] = cases[n][0] - cases[n][1];
        assert_int_equal(lpi_set_state(one, x, 5), LPI_OK);
        assert_int_equal(lpi_step(one, 1.0, 1), LPI_OK);
        assert_int_equal(lpi_get_state(one, z, 5), LPI_OK);
        double error = 0.0, size = 0.0;
        for (int e = 0; e < 5; ++e) error = fmax(error, fabs(y[e] - z[e])), size = fmax(size, fabs(z[e]));
        printf("a = (%g, %g): the flow differs from its one-parameter form by %.1e of |x|\n",
               cases[n][0], cases[n][1], error / size);
        assert_true(error <= 1e-13 * size);
        if (cases[n][0] == cases[n][1]) assert_memory_equal(y, x, sizeof x);
    }
    lpi_destroy(both);
    lpi_destroy(one);
}

/* R x| R^2 with {x0, x_(1+i)} = -A_il x_(1+l): H = x0 flows (x1, x2) by
 * exp(t A). An elliptic A that is no rotation, turning about a half turn:
 * its shears were formed as (2 + m00 - 1) / m10, 0 / 0 there, and came out
 * 3.8e-2 wrong at r = pi. Against M = cos r I + (sin r / r) A in long double. */
static void test_elliptic_plane_near_half_turns(void **state) {
    (void)state;
    const double pi = 3.14159265358979323846;
    const double radians[] = {pi, pi * (1.0 + 1e-8), pi * (1.0 - 1e-12), 3.0 * pi, 0.5 * pi, 2.0};
    for (size_t n = 0; n < sizeof radians / sizeof radians[0]; ++n) {
        /* A = [[3, 0.25], [c, -3]], c chosen so that r^2 = -(9 + 0.25 c). */
        const double p = 3.0, b = 0.25, c = -(radians[n] * radians[n] + p * p) / b;
        const double A[2][2] = {{p, b}, {c, -p}};
        const int32_t i[4] = {0, 0, 0, 0}, j[4] = {1, 1, 2, 2}, k[4] = {1, 2, 1, 2};
        const double constants[4] = {-A[0][0], -A[0][1], -A[1][0], -A[1][1]};
        lpi_system *sys = NULL;
        assert_int_equal(lpi_generic_create(&sys, 3, 4, i, j, k, constants), LPI_OK);
        const int32_t axis = 0;
        assert_int_equal(lpi_add_piece(sys, 1, &axis, field_gradient, field_energy, NULL), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
        const double x[3] = {0.1, 1.0, 0.5};
        double y[3];
        assert_int_equal(lpi_set_state(sys, x, 3), LPI_OK);
        assert_int_equal(lpi_step(sys, 1.0, 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, y, 3), LPI_OK);
        const long double r = sqrtl(-((long double)p * p + (long double)b * c));
        const long double C = cosl(r), S = sinl(r) / r;
        double error = 0.0;
        for (int row = 0; row < 2; ++row) {
            const long double exact = (C + S * A[row][row]) * x[1 + row] + S * A[row][1 - row] * x[2 - row];
            error = fmax(error, (double)fabsl(y[1 + row] - exact));
        }
        printf("elliptic plane, r = %.17g: error %.1e\n", (double)r, error);
        assert_true(error < 1e-13);
        lpi_destroy(sys);
    }
}

/* R x| R with {x0, x1} = -x1: H = a x0 scales x1 by e^(a t). A contraction
 * past e^-708, where exp is subnormal, kept only its bits (x1 = 1e300 scaled
 * by e^-740 was 2.6e-3 off), and a subnormal x1 grown into the normal range
 * kept only its own (3e-320 e^720: 3.2e-5 off). */
static double scale_rate;
static int scale_gradient(size_t n, const double *x, double *g, void *user) {
    (void)n, (void)x, (void)user;
    g[0] = scale_rate;
    return 0;
}
static int scale_energy(size_t n, const double *x, double *h, void *user) {
    (void)n, (void)user;
    *h = scale_rate * x[0];
    return 0;
}
static void test_scalings_beyond_the_normal_range(void **state) {
    (void)state;
    const int32_t i[1] = {0}, j[1] = {1}, k[1] = {1};
    const double c[1] = {-1.0};
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 2, 1, i, j, k, c), LPI_OK);
    const int32_t axis = 0;
    assert_int_equal(lpi_add_piece(sys, 1, &axis, scale_gradient, scale_energy, NULL), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    const double cases[][2] = {{1e300, -740.0}, {1e300, -720.0}, {3e-320, 720.0}, {5e-324, 1000.0}, {1.0, -709.0}};
    for (size_t n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
        const double x[2] = {0.0, cases[n][0]};
        double y[2];
        scale_rate = cases[n][1];
        assert_int_equal(lpi_set_state(sys, x, 2), LPI_OK);
        assert_int_equal(lpi_step(sys, 1.0, 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, y, 2), LPI_OK);
        /* e^a as two halves, each in range: a few roundings, not long
         * double (which valgrind evaluates as double). */
        const double half = exp(0.5 * cases[n][1]), exact = cases[n][0] * half * half;
        const double error = fabs((y[1] - exact) / exact);
        printf("x1 = %g scaled by e^%g: %.17g, relative error %.1e\n", cases[n][0], cases[n][1], y[1], error);
        assert_true(error < 1e-15);
    }
    lpi_destroy(sys);
}

/* R x| R^3 with {x0, y_i} = M_il y_l, M = [[a, 1, 0], [0, a, 0], [0, 0, 2a]]:
 * H = x0 takes the diagonal-and-series path, y -> exp(-s M) y. From y =
 * (0, 1, 1) the series gives y1 / y2 = -s and the diagonal ln y2 = -a s,
 * ln y3 = -2a s: one time s for both. a = 255/128 has 8 significant bits,
 * so s = t g is cut to 45; the diagonal had taken t g uncut, up to 2^-45 of
 * s away from the series (1.3e-14 at t = 0.7), which no flow of the algebra
 * does (the Casimir y1/y2 - ln|y3| / 2a moved 1e-14 a flow, one way). */
static void test_diagonal_runs_with_its_series(void **state) {
    (void)state;
    const double a = 255.0 / 128.0;
    const int32_t i[4] = {0, 0, 0, 0}, j[4] = {1, 1, 2, 3}, k[4] = {1, 2, 2, 3};
    const double c[4] = {a, 1.0, a, 2.0 * a};
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 4, 4, i, j, k, c), LPI_OK);
    const int32_t axis = 0;
    assert_int_equal(lpi_add_piece(sys, 1, &axis, field_gradient, field_energy, NULL), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    const double steps[4] = {0.3, 0.7, 1.1, 1.7};
    for (int n = 0; n < 4; ++n) {
        const double x[4] = {0.0, 0.0, 1.0, 1.0};
        double y[4];
        assert_int_equal(lpi_set_state(sys, x, 4), LPI_OK);
        assert_int_equal(lpi_step(sys, steps[n], 1), LPI_OK);
        assert_int_equal(lpi_get_state(sys, y, 4), LPI_OK);
        const double series = -y[1] / y[2], diagonal = -log(y[2]) / a, doubled = -log(y[3]) / (2.0 * a);
        const double apart = fmax(fabs(diagonal - series), fabs(doubled - series)) / series;
        printf("t = %g: the series ran for %.17g, the diagonal %.17g and %.17g (%.1e apart)\n", steps[n],
               series, diagonal, doubled, apart);
        assert_true(apart < 1e-15);
    }
    lpi_destroy(sys);
}

/* x^T Q x as an exact sum of exact products (fma), Q symmetric given by its
 * upper triangle, rounded once at the end: the Casimir's change is then
 * measured without a bias of its own. size: the sum of |Q_ij x_i x_j|. */
static long double quadratic_form(int n, const double *Q, const double *x, long double *size) {
    double sum = 0.0, error = 0.0;
    *size = 0.0L;
    for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j) {
            const double q = Q[i * n + j] * (i == j ? 1.0 : 2.0); /* small integers or powers of 2 */
            if (q == 0.0) continue;
            const double p = x[i] * x[j], e = fma(x[i], x[j], -p);
            const double terms[2] = {q * p, q * e}; /* exact, then */
            for (int t = 0; t < 2; ++t) {             /* Knuth's two_sum into sum + error */
                const double total = sum + terms[t], part = total - sum;
                error += (sum - (total - part)) + (terms[t] - part);
                sum = total;
            }
            *size += fabsl((long double)q * x[i] * x[j]);
        }
    return (long double)sum + error;
}

/* A linear piece whose block of three or more indices one parameter
 * couples (su(3) in the basis {E_ij - E_ji, i (E_ij + E_ji), i (E11 - E22),
 * i (E22 - E33)}, H = 0.7 x0; so(3) in the dense basis M = [[2, 1, 1], [1,
 * 1, 0], [3, 2, 2]], H = 0.7 x2) took the Pade path, which rounds exp(t A)
 * once a flow: with g constant, the same map every flow, and the quadratic
 * Casimir moved with one sign (81 and 158 standard errors over 2e4 random
 * states at t = 1). Its flows are bounded (imaginary eigenvalues): the
 * series on the vector now, every rounding one of the state's. */
static void test_elliptic_block_without_bias(void **state) {
    (void)state;
    static const int32_t su3_i[] = {0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 5, 5},
                         su3_j[] = {1, 2, 3, 4, 5, 6, 7, 2, 3, 4, 5, 6, 7, 3, 3, 4, 5, 6, 7, 4, 5, 6, 7, 5, 6, 7, 6, 7},
                         su3_k[] = {6, 4, 5, 2, 3, 1, 1, 5, 4, 3, 2, 0, 0, 6, 7, 0, 1, 3, 3, 1, 0, 2, 2, 7, 5, 5, 4, 4};
    static const double su3_c[] = {2, -1, -1, 1, 1, -2, 1, 1, -1, 1, -1, 2, -1, 2,
                                   2, -1, 1, -1, -1, -1, -1, 1, 1, 2, 1, -2, -1, 2};
    static const int32_t so3_i[] = {0, 0, 0, 0, 1, 1, 1}, so3_j[] = {1, 1, 2, 2, 2, 2, 2},
                         so3_k[] = {0, 2, 0, 1, 0, 1, 2};
    static const double so3_c[] = {-5, 3, 1, -2, 9, -1, -5};
    /* sl(2) in the basis {e - delta f, h, f}, delta = 2^-40: elliptic, but
     * nearly parabolic (eigenvalues +-2i sqrt(delta)), its flows bounded only
     * by about 1/delta. */
    static const int32_t sl2_i[] = {0, 0, 0, 1}, sl2_j[] = {1, 1, 2, 2}, sl2_k[] = {0, 2, 1, 2};
    static const double sl2_c[] = {-2, -0x1p-38, 1, -2};
    /* The quadratic Casimirs, times 4, times 3 and times 2^-38: forms of
     * exact entries. */
    double su3_q[64] = {0}, so3_q[9] = {9, -1, -5, -1, 2, 0, -5, 0, 3}, sl2_q[9] = {0, 0, 2, 0, 1, 0, 2, 0, 0x1p-38};
    for (int e = 0; e < 6; ++e) su3_q[e * 9] = 3.0;
    su3_q[6 * 8 + 6] = su3_q[7 * 8 + 7] = 4.0, su3_q[6 * 8 + 7] = su3_q[7 * 8 + 6] = 2.0;
    static const double field = 0.7;
    static const char *const names[] = {"su(3)", "so(3) in a dense basis", "sl(2), nearly parabolic"};
    for (int algebra = 0; algebra < 3; ++algebra) {
        const int n = algebra ? 3 : 8;
        const int32_t index = algebra == 1 ? 2 : 0;
        lpi_system *sys = NULL;
        if (algebra == 2)
            assert_int_equal(lpi_generic_create(&sys, 3, 4, sl2_i, sl2_j, sl2_k, sl2_c), LPI_OK);
        else if (algebra == 1)
            assert_int_equal(lpi_generic_create(&sys, 3, 7, so3_i, so3_j, so3_k, so3_c), LPI_OK);
        else
            assert_int_equal(lpi_generic_create(&sys, 8, 28, su3_i, su3_j, su3_k, su3_c), LPI_OK);
        assert_int_equal(lpi_add_piece(sys, 1, &index, scaled_gradient, scaled_energy, (void *)&field), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
        const double *Q = algebra == 2 ? sl2_q : algebra ? so3_q : su3_q;
        uint64_t seed = 5;
        lpi_test_mean change = {0};
        for (int m = 0; m < 20000; ++m) {
            double x[8], y[8];
            for (int e = 0; e < n; ++e) x[e] = lpi_test_uniform(&seed);
            assert_int_equal(lpi_set_state(sys, x, (size_t)n), LPI_OK);
            assert_int_equal(lpi_step(sys, 1.0, 1), LPI_OK);
            assert_int_equal(lpi_get_state(sys, y, (size_t)n), LPI_OK);
            long double size0, size1;
            const long double before = quadratic_form(n, Q, x, &size0), after = quadratic_form(n, Q, y, &size1);
            lpi_test_mean_add(&change, (double)((after - before) / size0));
        }
        double mean, spread;
        const double z = lpi_test_mean_z(&change, &mean, &spread);
        printf("%s, H = 0.7 x%d, one flow of 1: mean change of the Casimir %.2e of its terms, %.1f "
               "standard errors (rounding: %.2e a flow)\n", names[algebra], (int)index, mean, z, spread);
        assert_true(fabs(z) < 5.0);
        lpi_destroy(sys);
    }
}

/* A state near DBL_MAX whose flow stays finite: the series' terms may
 * overflow where the flow does not (||h C||_1 above 1), and the flow is then
 * Pade's, not refused. The same flow of the state scaled by 2^-900, scaled
 * back, is the reference. */
static void test_elliptic_block_near_overflow(void **state) {
    (void)state;
    static const int32_t i[] = {0, 0, 0, 0, 1, 1, 1}, j[] = {1, 1, 2, 2, 2, 2, 2}, k[] = {0, 2, 0, 1, 0, 1, 2};
    static const double c[] = {-5, 3, 1, -2, 9, -1, -5}, field = 0.7;
    const int32_t index = 2;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 7, i, j, k, c), LPI_OK);
    assert_int_equal(lpi_add_piece(sys, 1, &index, scaled_gradient, scaled_energy, (void *)&field), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    const double huge[3] = {0x1.cf88311c44cbep+1022, 0x1.fcbf54b71469ep+1022, -0x1.7a5e85cdd5308p+1018};
    double small[3], y[3], reference[3];
    for (int e = 0; e < 3; ++e) small[e] = ldexp(huge[e], -900);
    assert_int_equal(lpi_set_state(sys, small, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 1.0, 1), LPI_OK);
    assert_int_equal(lpi_get_state(sys, reference, 3), LPI_OK);
    assert_int_equal(lpi_set_state(sys, huge, 3), LPI_OK);
    if (lpi_step(sys, 1.0, 1) != LPI_OK) fail_msg("a finite flow of a state near DBL_MAX: %s", lpi_last_error(sys));
    assert_int_equal(lpi_get_state(sys, y, 3), LPI_OK);
    for (int e = 0; e < 3; ++e)
        assert_true(fabs(y[e] - ldexp(reference[e], 900)) <= 1e-13 * 0x1p1023);
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rigid_body_matches_built_in),
        cmocka_unit_test(test_pendulum_matches_built_in),
        cmocka_unit_test(test_poisson_rank),
        cmocka_unit_test(test_either_order_and_agreeing_duplicates),
        cmocka_unit_test(test_create_errors),
        cmocka_unit_test(test_add_piece_errors),
        cmocka_unit_test(test_callback_failures_roll_back),
        cmocka_unit_test(test_gradient_buffer_zeroed),
        cmocka_unit_test(test_no_pieces),
        cmocka_unit_test(test_hyperbolic_piece_keeps_contracted_components),
        cmocka_unit_test(test_constant_rotation_without_bias),
        cmocka_unit_test(test_constant_scaling_without_bias),
        cmocka_unit_test(test_lone_scalings_without_bias),
        cmocka_unit_test(test_large_semidirect_product),
        cmocka_unit_test(test_disjoint_blocks_without_bias),
        cmocka_unit_test(test_cancelling_factors),
        cmocka_unit_test(test_elliptic_plane_near_half_turns),
        cmocka_unit_test(test_scalings_beyond_the_normal_range),
        cmocka_unit_test(test_diagonal_runs_with_its_series),
        cmocka_unit_test(test_elliptic_block_without_bias),
        cmocka_unit_test(test_elliptic_block_near_overflow),
    };
    return lpi_run_tests(tests);
}
