/* A user callback that calls back into its own handle: piece gradients and
 * energies, Casimir callbacks and the moment product piece may not call any
 * status-returning function on that handle (LPI_ERR_BUSY, nothing changed,
 * lpi_destroy frees nothing), so a callback can neither free nor change the
 * system under the call that runs it, nor recurse into itself. Calls on other
 * handles work. Inside an observer, a read that runs callbacks (lpi_energy of
 * a generic system) gives those callbacks the same protection. */
#include "lpi_test.h"

static const double kInertia[3] = {1.0, 2.0, 3.5};
static const double kM0[3] = {0.3, 1.1, -0.7};
static const int32_t kI[] = {0, 1, 2}, kJ[] = {1, 2, 0}, kK[] = {2, 0, 1};
static const double kC[] = {1, 1, 1};

/* What a callback tried on its own handle, and how many answers were BUSY. */
typedef struct {
    lpi_system *self;
    lpi_system *other;
    int attempts, busy, other_ok;
} probe;

/* Every kind of call a callback could make on its handle. */
static void intrude(probe *p) {
    lpi_system *s = p->self;
    const double x[3] = {5, 5, 5}, gammas[1] = {1.0};
    double out[8];
    size_t n;
    const int32_t axis[] = {1};
    const int statuses[] = {
        lpi_set_state(s, x, 3),
        lpi_step(s, 0.1, 1),
        lpi_set_method(s, "rk4"),
        lpi_set_composition(s, 1, gammas),
        lpi_add_piece(s, 1, axis, lpi_test_axis_gradient, lpi_test_axis_energy, (void *)&kInertia[1]),
        lpi_add_casimir(s, NULL, NULL),
        lpi_set_observer(s, 1, NULL, NULL),
        lpi_destroy(s),
        /* reads that would re-enter the callbacks or see a state in flux */
        lpi_get_state(s, out, 3),
        lpi_energy(s, out),
        lpi_casimirs(s, out, lpi_casimir_count(s)),
        lpi_flows_per_step(s, &n),
        lpi_poisson_rank(s, x, 3, &n),
    };
    for (size_t i = 0; i < sizeof statuses / sizeof statuses[0]; ++i) {
        p->attempts++;
        p->busy += statuses[i] == LPI_ERR_BUSY;
    }
    if (p->other) p->other_ok += lpi_step(p->other, 0.01, 1) == LPI_OK;
}

static int intruding_gradient(size_t n, const double *x, double *g, void *user) {
    intrude(user);
    return lpi_test_axis_gradient(n, x, g, (void *)&kInertia[0]);
}
static int intruding_energy(size_t n, const double *x, double *h, void *user) {
    intrude(user);
    return lpi_test_axis_energy(n, x, h, (void *)&kInertia[0]);
}
static int plain_gradient(size_t n, const double *x, double *g, void *user) {
    (void)user;
    return lpi_test_axis_gradient(n, x, g, (void *)&kInertia[0]);
}
static int intruding_casimir(size_t dim, const double *x, double *out, void *user) {
    intrude(user);
    *out = 0;
    for (size_t i = 0; i < dim; ++i) *out += x[i] * x[i];
    return 0;
}

static lpi_system *so3(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, kI, kJ, kK, kC), LPI_OK);
    assert_int_equal(lpi_set_state(sys, kM0, 3), LPI_OK);
    return sys;
}

static void test_piece_and_casimir_callbacks_cannot_touch_their_handle(void **state) {
    (void)state;
    lpi_system *sys = so3(), *other = NULL;
    assert_int_equal(lpi_rigid_body_create(&other, 1, 2, 3), LPI_OK);
    assert_int_equal(lpi_set_state(other, kM0, 3), LPI_OK);
    probe p = {sys, other, 0, 0, 0};
    const int32_t axis[] = {0};
    assert_int_equal(lpi_add_piece(sys, 1, axis, intruding_gradient, intruding_energy, &p), LPI_OK);
    assert_int_equal(lpi_add_casimir(sys, intruding_casimir, &p), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);

    /* The same run without intrusions, for comparison. */
    lpi_system *plain = so3();
    assert_int_equal(lpi_add_piece(plain, 1, axis, lpi_test_axis_gradient, lpi_test_axis_energy,
                                   (void *)&kInertia[0]), LPI_OK);
    assert_int_equal(lpi_set_method(plain, "lie-trotter"), LPI_OK);

    assert_int_equal(lpi_step(sys, 0.1, 4), LPI_OK); /* 4 gradient calls */
    assert_int_equal(lpi_step(plain, 0.1, 4), LPI_OK);
    double e, c;
    assert_int_equal(lpi_energy(sys, &e), LPI_OK);       /* 1 energy call */
    assert_int_equal(lpi_casimirs(sys, &c, 1), LPI_OK);  /* 1 Casimir call */
    assert_int_equal(p.attempts, 6 * 13);
    assert_int_equal(p.busy, p.attempts);
    assert_int_equal(p.other_ok, 6);
    assert_non_null(strstr(lpi_last_error(sys), "lpi_poisson_rank"));
    assert_non_null(strstr(lpi_last_error(sys), "callback"));

    /* Nothing the callbacks tried took effect. */
    double a[3], b[3];
    assert_int_equal(lpi_get_state(sys, a, 3), LPI_OK);
    assert_int_equal(lpi_get_state(plain, b, 3), LPI_OK);
    assert_memory_equal(a, b, sizeof a);
    assert_true(lpi_time(sys) == lpi_time(plain));
    assert_int_equal(lpi_casimir_count(sys), 1);
    size_t flows = 0;
    assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
    assert_int_equal(flows, 1); /* still lie-trotter, still one piece */

    assert_int_equal(lpi_destroy(plain), LPI_OK);
    assert_int_equal(lpi_destroy(other), LPI_OK);
    assert_int_equal(lpi_destroy(sys), LPI_OK);
}

/* The moment product piece's H and H' callbacks. */
static int intruding_h(double u, double *out, void *user) {
    intrude(user);
    *out = 0.02 * u + 0.01 * u * u;
    return 0;
}
static int intruding_dh(double u, double *out, void *user) {
    intrude(user);
    *out = 0.02 + 0.02 * u;
    return 0;
}

static void test_moment_product_piece_callbacks(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    assert_int_equal(lpi_moments_create(&sys), LPI_OK);
    const double x[8] = {1.0, 0.1, 1.0, 3.0, 0.2, 1.0, 0.1, 3.0};
    assert_int_equal(lpi_set_state(sys, x, 8), LPI_OK);
    probe p = {sys, NULL, 0, 0, 0};
    assert_int_equal(lpi_moments_add_product_piece(sys, intruding_h, intruding_dh, &p), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 2), LPI_OK);
    double e;
    assert_int_equal(lpi_energy(sys, &e), LPI_OK);
    assert_true(p.attempts > 0);
    assert_int_equal(p.busy, p.attempts);
    assert_int_equal(lpi_destroy(sys), LPI_OK);
}

/* Inside the observer, lpi_energy of a generic system runs the energy
 * callbacks: they are protected like any other callback. */
static int energy_reading_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)step, (void)t, (void)user;
    double e;
    return lpi_energy(sys, &e) != LPI_OK;
}

static void test_callbacks_inside_an_observer(void **state) {
    (void)state;
    lpi_system *sys = so3();
    probe p = {sys, NULL, 0, 0, 0};
    const int32_t axis[] = {2};
    assert_int_equal(lpi_add_piece(sys, 1, axis, plain_gradient, intruding_energy, &p), LPI_OK);
    assert_int_equal(lpi_set_observer(sys, 1, energy_reading_observer, NULL), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK); /* 3 observations, 3 energies */
    assert_int_equal(p.attempts, 3 * 13);
    assert_int_equal(p.busy, p.attempts);
    assert_int_equal(lpi_destroy(sys), LPI_OK);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_piece_and_casimir_callbacks_cannot_touch_their_handle),
        cmocka_unit_test(test_moment_product_piece_callbacks),
        cmocka_unit_test(test_callbacks_inside_an_observer),
    };
    return lpi_run_tests(tests);
}
