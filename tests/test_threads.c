/* Separate handles on separate threads: every kind of system (sine-Euler
 * included, so FFTW plans are made concurrently under the library's planner
 * lock) gives, to the bit, the result of the same run on one thread; failed
 * calls without a handle keep their message per thread. Built and run under
 * ThreadSanitizer by `make check-tsan`. */
#include <pthread.h>

#include "lpi_test.h"

enum { kKinds = 6, kCopies = 2, kMaxDim = 2 * 15 * 15 };

static int v_grad(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x; (void)user;
    g[0] = 0.5;
    g[1] = 0.01;
    return 0;
}
static int v_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)user;
    *h = 0.5 * x[0] + 0.01 * x[1];
    return 0;
}
static const double kInertia[3] = {1.0, 2.0, 3.0};

/* Builds system `kind`, runs it and writes its final state; 0 on success.
 * No cmocka assertions here: they are not thread-safe. */
static int run_kind(int kind, double *out, size_t *n) {
    lpi_system *sys = NULL;
    int status = LPI_OK;
    double x[kMaxDim];
    memset(x, 0, sizeof x);
    switch (kind) {
    case 0:
        status = lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0);
        x[0] = 1.0, x[1] = 0.5, x[2] = -0.3;
        break;
    case 1:
        status = lpi_pendulum_create(&sys);
        x[0] = sin(2.0), x[1] = -cos(2.0), x[2] = 0.3;
        break;
    case 2: {
        static const int32_t i[] = {0, 0, 1}, j[] = {1, 2, 2}, k[] = {2, 1, 0};
        static const double c[] = {-1, 1, -1};
        status = lpi_generic_create(&sys, 3, 3, i, j, k, c);
        for (int32_t a = 0; a < 3 && status == LPI_OK; ++a)
            status = lpi_add_piece(sys, 1, &a, lpi_test_axis_gradient, lpi_test_axis_energy, (void *)&kInertia[a]);
        x[0] = 1.0, x[1] = 0.5, x[2] = -0.3;
        break;
    }
    case 3: {
        static const int32_t v[] = {0, 3}, t[] = {2, 7};
        status = lpi_moments_create(&sys);
        if (status == LPI_OK) status = lpi_add_piece(sys, 2, v, v_grad, v_energy, NULL);
        if (status == LPI_OK) status = lpi_add_piece(sys, 2, t, v_grad, v_energy, NULL);
        const double m[8] = {1.0, 0.1, 1.0, 3.0, 0.2, 1.0, 0.1, 3.0};
        memcpy(x, m, sizeof m);
        break;
    }
    default: { /* sine-Euler, N = 7 and N = 15 */
        const int N = kind == 4 ? 7 : 15;
        status = lpi_sine_euler_create(&sys, N);
        if (status != LPI_OK) break;
        double w[kMaxDim];
        memset(w, 0, sizeof w);
        for (int a = 1; a < 4; ++a) { /* modes (a, 1) and their conjugates */
            const int ma = N - a, mb = N - 1;
            w[2 * (a * N + 1)] = 1.0 / a, w[2 * (a * N + 1) + 1] = 0.5 / a;
            w[2 * (ma * N + mb)] = 1.0 / a, w[2 * (ma * N + mb) + 1] = -0.5 / a;
        }
        w[2 * (2 * N)] = 0.7, w[2 * ((N - 2) * N)] = 0.7; /* modes (2, 0), (-2, 0) */
        status = lpi_sine_euler_set_modes(sys, w, 2 * (size_t)N * N);
        if (status == LPI_OK) status = lpi_set_method(sys, "yoshida-6");
        if (status == LPI_OK) status = lpi_step(sys, 0.01, 50);
        if (status == LPI_OK) *n = lpi_dim(sys), status = lpi_get_state(sys, out, *n);
        lpi_destroy(sys);
        return status;
    }
    }
    if (status == LPI_OK) *n = lpi_dim(sys), status = lpi_set_state(sys, x, *n);
    if (status == LPI_OK) status = lpi_set_method(sys, "kahan-li-6");
    if (status == LPI_OK) status = lpi_step(sys, 0.01, 2000);
    if (status == LPI_OK) status = lpi_get_state(sys, out, *n);
    lpi_destroy(sys);
    return status;
}

typedef struct {
    int kind;
    int status;
    int own_error; /* the thread's own last error survived the others */
    size_t n;
    double x[kMaxDim];
} job;

static void *worker(void *arg) {
    job *j = arg;
    /* A failure with no handle: its message is this thread's. */
    char expected[64];
    snprintf(expected, sizeof expected, "I1 must be > 0, got -%d", j->kind + 1);
    lpi_system *bad = NULL;
    lpi_rigid_body_create(&bad, -(double)(j->kind + 1), 1.0, 1.0);
    j->status = run_kind(j->kind, j->x, &j->n);
    /* Unless this thread's own create failed since (no FFTW), the message is
     * still the one it caused, whatever the other threads did. */
    j->own_error = j->status != LPI_OK || strstr(lpi_last_error(NULL), expected) != NULL;
    return NULL;
}

static void test_handles_on_threads(void **state) {
    (void)state;
    /* References on this thread first. */
    double reference[kKinds][kMaxDim];
    size_t ref_n[kKinds];
    int available[kKinds];
    for (int k = 0; k < kKinds; ++k) {
        const int status = run_kind(k, reference[k], &ref_n[k]);
        available[k] = status == LPI_OK;
        if (!available[k]) assert_int_equal(status, LPI_ERR_UNSUPPORTED); /* no FFTW */
    }
    static job jobs[kKinds * kCopies];
    pthread_t threads[kKinds * kCopies];
    for (int t = 0; t < kKinds * kCopies; ++t) {
        jobs[t].kind = t % kKinds;
        assert_int_equal(pthread_create(&threads[t], NULL, worker, &jobs[t]), 0);
    }
    for (int t = 0; t < kKinds * kCopies; ++t) assert_int_equal(pthread_join(threads[t], NULL), 0);
    for (int t = 0; t < kKinds * kCopies; ++t) {
        const int k = jobs[t].kind;
        assert_true(jobs[t].own_error);
        if (!available[k]) {
            assert_int_equal(jobs[t].status, LPI_ERR_UNSUPPORTED);
            continue;
        }
        assert_int_equal(jobs[t].status, LPI_OK);
        assert_int_equal(jobs[t].n, ref_n[k]);
        assert_memory_equal(jobs[t].x, reference[k], ref_n[k] * sizeof(double));
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_handles_on_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
