/* Helpers shared by the cmocka tests: skips and the exit status ctest reads,
 * status checks with message and unchanged-state assertions, an independent
 * RK4 reference, order fitting. */
#ifndef LPI_TEST_H
#define LPI_TEST_H

#include <liepoisson.h>
#include <malloc.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#ifdef __cplusplus /* cmocka.h declares its functions without C linkage */
extern "C" {
#endif
#include <cmocka.h>
#ifdef __cplusplus
}
#endif

#include "mapped_bytes.h"

/* ---- skips and the exit status ------------------------------------------
 * A test that cannot run here (this build lacks an optional part, or a tool
 * it runs under cannot host it) calls LPI_SKIP with the reason: the reason is
 * printed and cmocka lists the test as SKIPPED, never as passed. A program
 * ends with `return lpi_run_tests(tests);`, whose status ctest reads: 1 when
 * a test failed, 77 (the SKIP_RETURN_CODE every test is registered with) when
 * every test was skipped, 0 otherwise. */
static inline int *lpi_test_skip_count(void) {
    static int count;
    return &count;
}

#define LPI_SKIP(...)                      \
    do {                                   \
        printf("skipped: ");               \
        printf(__VA_ARGS__);               \
        printf("\n");                      \
        fflush(stdout);                    \
        ++*lpi_test_skip_count();          \
        skip();                            \
    } while (0)

static inline int lpi_test_exit_status(int failed, size_t count) {
    if (failed) return 1;
    if (count > 0 && (size_t)*lpi_test_skip_count() == count) {
        printf("every test was skipped\n");
        return 77;
    }
    return 0;
}

#define lpi_run_tests(tests)                                              \
    lpi_test_exit_status(cmocka_run_group_tests(tests, NULL, NULL),       \
                         sizeof(tests) / sizeof((tests)[0]))

/* What this build has, asked of the library as a program would. */
static inline int lpi_test_have_sine_euler(void) {
    lpi_system *probe = NULL;
    const int have = lpi_sine_euler_create(&probe, 3) == LPI_OK;
    lpi_destroy(probe);
    return have;
}

/* What a handle shows, to compare bit for bit: state, time, method, split and
 * flows per step (which the implicit methods measure in each call). */
typedef struct {
    double x[4096];
    size_t n;
    double time;
    char method[64], split[64];
    size_t flows;
} lpi_snapshot;

static inline void lpi_take_snapshot(const lpi_system *sys, lpi_snapshot *s) {
    s->n = lpi_dim(sys);
    assert_true(s->n <= sizeof s->x / sizeof s->x[0]);
    assert_int_equal(lpi_get_state(sys, s->x, s->n), LPI_OK);
    s->time = lpi_time(sys);
    snprintf(s->method, sizeof s->method, "%s", lpi_get_method(sys));
    snprintf(s->split, sizeof s->split, "%s", lpi_get_split(sys));
    assert_int_equal(lpi_flows_per_step(sys, &s->flows), LPI_OK);
}

static inline void lpi_assert_unchanged(const lpi_system *sys, const lpi_snapshot *before) {
    lpi_snapshot after;
    lpi_take_snapshot(sys, &after);
    assert_int_equal(after.n, before->n);
    assert_memory_equal(after.x, before->x, before->n * sizeof(double));
    assert_memory_equal(&after.time, &before->time, sizeof(double));
    assert_string_equal(after.method, before->method);
    assert_string_equal(after.split, before->split);
    assert_int_equal(after.flows, before->flows);
}

/* Asserts that `call` returns `expected`, that the handle's (or the thread's)
 * last error names `function`, and that the state did not change. */
#define LPI_ASSERT_FAILS(sys, call, expected, function)                                   \
    do {                                                                                  \
        lpi_snapshot lpi_before_;                                                         \
        if (sys) lpi_take_snapshot(sys, &lpi_before_);                                    \
        int lpi_status_ = (call);                                                         \
        if (lpi_status_ != (expected))                                                    \
            fail_msg("%s returned %s, expected %s (%s)", #call, lpi_status_name(lpi_status_), \
                     lpi_status_name(expected), lpi_last_error(sys));                     \
        const char *lpi_msg_ = lpi_last_error(sys);                                       \
        if (strstr(lpi_msg_, function) == NULL)                                           \
            fail_msg("message '%s' does not name %s", lpi_msg_, function);                \
        if (sys) lpi_assert_unchanged(sys, &lpi_before_);                                 \
    } while (0)

/* ---- a call short of memory ----------------------------------------------
 * lpi_test_with_address_space_limited runs one call with this process's
 * address space limited (when `limited`) to what it has mapped, so that what
 * the call maps is refused: blocks of 16 KiB and more are then mapped on
 * their own, never carved from freed heap (whose threshold glibc otherwise
 * raises as large blocks are freed). It returns the call's status. Not under
 * a sanitizer: a test that calls it starts with
 * LPI_SKIP_UNDER_A_SANITIZER(). AddressSanitizer ends the process when a
 * mapping is refused, and ThreadSanitizer's own allocator runs out. */
#if defined(__SANITIZE_ADDRESS__)
#define LPI_TEST_SANITIZER "AddressSanitizer"
#elif defined(__SANITIZE_THREAD__)
#define LPI_TEST_SANITIZER "ThreadSanitizer"
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LPI_TEST_SANITIZER "AddressSanitizer"
#elif __has_feature(thread_sanitizer)
#define LPI_TEST_SANITIZER "ThreadSanitizer"
#endif
#endif
#ifdef LPI_TEST_SANITIZER
#define LPI_SKIP_UNDER_A_SANITIZER() LPI_SKIP("a low address-space limit: not under " LPI_TEST_SANITIZER)
#else
#define LPI_SKIP_UNDER_A_SANITIZER() ((void)0)
#endif

typedef int (*lpi_test_limited_call)(lpi_system *sys, const void *context);
static inline int lpi_test_with_address_space_limited(int limited, lpi_test_limited_call call, lpi_system *sys,
                                                      const void *context) {
    mallopt(M_MMAP_THRESHOLD, 16 * 1024);
    malloc_trim(0);
    struct rlimit saved;
    assert_int_equal(getrlimit(RLIMIT_AS, &saved), 0);
    const size_t mapped = lpi_test_mapped_bytes();
    if (limited && mapped > 0 && (saved.rlim_cur == RLIM_INFINITY || saved.rlim_cur > mapped)) {
        struct rlimit tight = saved;
        tight.rlim_cur = mapped;
        assert_int_equal(setrlimit(RLIMIT_AS, &tight), 0);
    }
    const int status = call(sys, context);
    if (limited) assert_int_equal(setrlimit(RLIMIT_AS, &saved), 0);
    return status;
}

/* Random numbers in [-1, 1) from a 64-bit linear congruential generator:
 * the same sequence on every platform, for the tests' random states. */
static inline double lpi_test_uniform(uint64_t *seed) {
    *seed = *seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*seed >> 11) * 0x1p-52 - 1.0;
}

/* Whether a quantity's mean is zero: samples added one by one, then the mean,
 * the spread and the mean in standard errors (z), for the bias tests. */
typedef struct {
    double sum, squares;
    long count;
} lpi_test_mean;

static inline void lpi_test_mean_add(lpi_test_mean *m, double value) {
    m->sum += value, m->squares += value * value, ++m->count;
}
static inline double lpi_test_mean_z(const lpi_test_mean *m, double *mean, double *spread) {
    *mean = m->sum / (double)m->count;
    *spread = sqrt(m->squares / (double)m->count - *mean * *mean);
    return *mean / (*spread / sqrt((double)m->count));
}

/* Classical RK4 written independently of the library, for references. */
typedef void (*lpi_test_field)(const double *x, double *dx, const void *ctx);

static inline void lpi_test_rk4(lpi_test_field f, const void *ctx, size_t n, double *x,
                                double T, int64_t steps) {
    double k1[64], k2[64], k3[64], k4[64], y[64];
    const double h = T / (double)steps;
    assert_true(n <= 64);
    for (int64_t s = 0; s < steps; ++s) {
        f(x, k1, ctx);
        for (size_t i = 0; i < n; ++i) y[i] = x[i] + 0.5 * h * k1[i];
        f(y, k2, ctx);
        for (size_t i = 0; i < n; ++i) y[i] = x[i] + 0.5 * h * k2[i];
        f(y, k3, ctx);
        for (size_t i = 0; i < n; ++i) y[i] = x[i] + h * k3[i];
        f(y, k4, ctx);
        for (size_t i = 0; i < n; ++i) x[i] += h / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
}

/* Euler's equations of the free rigid body, dm/dt = m x (m / I); ctx = I. */
static inline void lpi_test_rigid_body_field(const double *m, double *dm, const void *ctx) {
    const double *inertia = (const double *)ctx;
    const double w[3] = {m[0] / inertia[0], m[1] / inertia[1], m[2] / inertia[2]};
    dm[0] = m[1] * w[2] - m[2] * w[1];
    dm[1] = m[2] * w[0] - m[0] * w[2];
    dm[2] = m[0] * w[1] - m[1] * w[0];
}

/* The piece m_k^2 / (2 I_k) of a rigid body written as a generic system;
 * user points at I_k. */
static inline int lpi_test_axis_gradient(size_t n, const double *x, double *g, void *user) {
    (void)n;
    g[0] = x[0] / *(const double *)user;
    return 0;
}
static inline int lpi_test_axis_energy(size_t n, const double *x, double *h, void *user) {
    (void)n;
    *h = 0.5 * x[0] * x[0] / *(const double *)user;
    return 0;
}

/* A piece H = x_sigma[0] on one index (grad 1): the pendulum's kick, the moments' squeeze. */
static inline int lpi_test_linear_gradient(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x; (void)user;
    g[0] = 1.0;
    return 0;
}
static inline int lpi_test_linear_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)user;
    *h = x[0];
    return 0;
}

/* Sine-Euler mode indices: the representative of a mod N in -M..M, and a mod N. */
static inline int lpi_test_centred(int a, int N) { return a > N / 2 ? a - N : a; }
static inline int lpi_test_mod(int a, int N) { return ((a % N) + N) % N; }

/* A reproducible Hermitian sine-Euler field (modes in FFT order, 2 N^2
 * doubles) with w_0 = 0 and amplitude scale / (1 + |m|^2), drawn from a
 * linear congruential generator started at `state`. */
static inline void lpi_test_random_field(int N, uint64_t state, double scale, double *w) {
    memset(w, 0, sizeof(double) * 2 * (size_t)N * (size_t)N);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int ra = lpi_test_centred(a, N), rb = lpi_test_centred(b, N);
            if (ra < 0 || (ra == 0 && rb <= 0)) continue;
            double v[2];
            for (int i = 0; i < 2; ++i) {
                state = state * 6364136223846793005ull + 1442695040888963407ull;
                v[i] = (double)(state >> 11) / 9007199254740992.0 - 0.5;
            }
            const double decay = scale / (1.0 + ra * ra + rb * rb);
            const int m = a * N + b, minus = lpi_test_mod(-a, N) * N + lpi_test_mod(-b, N);
            w[2 * m] = v[0] * decay, w[2 * m + 1] = v[1] * decay;
            w[2 * minus] = v[0] * decay, w[2 * minus + 1] = -v[1] * decay;
        }
}

/* Least-squares slope of log(error) against log(step). */
static inline double lpi_fit_order(const double *steps, const double *errors, int count) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < count; ++i) {
        const double lx = log(steps[i]), ly = log(errors[i]);
        sx += lx; sy += ly; sxx += lx * lx; sxy += lx * ly;
    }
    return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

static inline double lpi_test_distance(const double *a, const double *b, size_t n) {
    double s = 0;
    for (size_t i = 0; i < n; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(s);
}

/* Integrates sys from x0 to T with `steps` steps of `method` and returns the
 * distance of the end state from `reference`. */
static inline double lpi_test_error(lpi_system *sys, const char *method, const double *x0,
                                    double T, int64_t steps, const double *reference) {
    const size_t n = lpi_dim(sys);
    double x[4096];
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    assert_int_equal(lpi_set_state(sys, x0, n), LPI_OK);
    assert_int_equal(lpi_step(sys, T / (double)steps, steps), LPI_OK);
    assert_int_equal(lpi_get_state(sys, x, n), LPI_OK);
    return lpi_test_distance(x, reference, n);
}

#endif
