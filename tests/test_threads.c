/* Separate handles on separate threads (and on the threads of a host's
 * OpenMP region, and in a child of fork): every kind of system (sine-Euler
 * included, so FFTW plans are made concurrently under the library's planner
 * lock) gives, to the bit, the result of the same run on one thread; failed
 * calls without a handle keep their message per thread. Thread counts are
 * bounded, and threads the system refuses (here: an address-space limit too
 * small for their stacks) give LPI_ERR_NO_MEMORY from lpi_set_threads and
 * lpi_step instead of the OpenMP runtime ending the process. Built and run
 * under ThreadSanitizer by `make check-tsan`. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "lpi_test.h"

/* Valgrind runs one thread at a time (a race a test sets up cannot happen),
 * and has its own mappings (an address-space limit leaves no room). */
static int under_valgrind(void) {
    const char *preload = getenv("LD_PRELOAD");
    return preload && strstr(preload, "vgpreload");
}

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

/* ---- thread limits -------------------------------------------------------- */

static lpi_system *sine_euler_15(void) {
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, 15) != LPI_OK) return NULL;
    double w[2 * 15 * 15] = {0};
    w[2 * (2 * 15 + 1)] = 1.0, w[2 * (13 * 15 + 14)] = 1.0; /* modes (2, 1), (-2, -1) */
    w[2 * 3] = 0.5, w[2 * 12] = 0.5;                       /* modes (0, 3), (0, -3) */
    if (lpi_sine_euler_set_modes(sys, w, 2 * 15 * 15) != LPI_OK) return NULL;
    return sys;
}

/* Limits the address space to what is mapped now plus `headroom` bytes. */
static int limit_address_space(size_t headroom, struct rlimit *previous) {
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (!f || fscanf(f, "%lu", &pages) != 1) return -1;
    fclose(f);
    if (getrlimit(RLIMIT_AS, previous) != 0) return -1;
    struct rlimit low = *previous;
    low.rlim_cur = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + headroom;
    return setrlimit(RLIMIT_AS, &low);
}

typedef struct {
    lpi_system *sys;
    pthread_mutex_t mutex;
    pthread_cond_t go;
    int released, status;
} stepper;

/* Waits until released, then steps on this (new) host thread. */
static void *step_when_released(void *argument) {
    stepper *s = argument;
    pthread_mutex_lock(&s->mutex);
    while (!s->released) pthread_cond_wait(&s->go, &s->mutex);
    pthread_mutex_unlock(&s->mutex);
    s->status = lpi_step(s->sys, 0.01, 2);
    return NULL;
}

/* In a child process, as the limit would end it: 0 when every status is the
 * documented one, 100 without OpenMP, else 10 + the number of the failed
 * check (libgomp ending the process exits with 1). */
static int run_under_a_low_limit(int n) {
    lpi_system *sys = sine_euler_15();
    if (!sys) return 100;
    if (lpi_step(sys, 0.01, 1) != LPI_OK) return 11; /* plans made */
    stepper s = {sys, PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0, -1};
    pthread_t other;
    if (pthread_create(&other, NULL, step_when_released, &s) != 0) return 12;
    struct rlimit previous;
    if (limit_address_space(1 << 20, &previous) != 0) return 13;
    /* n - 1 thread stacks do not fit: refused, and the count stays 1. */
    const int refused = lpi_set_threads(sys, n);
    if (refused == LPI_ERR_UNSUPPORTED) return 100; /* no OpenMP */
    if (refused != LPI_ERR_NO_MEMORY) return 14;
    if (strstr(lpi_last_error(sys), "refused to start thread") == NULL) return 15;
    if (lpi_step(sys, 0.01, 2) != LPI_OK) return 16;
    if (setrlimit(RLIMIT_AS, &previous) != 0) return 17;
    /* With room again the count is accepted and used. */
    if (lpi_set_threads(sys, n) != LPI_OK) return 18;
    if (lpi_step(sys, 0.01, 2) != LPI_OK) return 19;
    /* Another host thread needs a team of its own: under the limit, lpi_step
     * on it is refused with a status too. */
    if (limit_address_space(1 << 20, &previous) != 0) return 20;
    pthread_mutex_lock(&s.mutex);
    s.released = 1;
    pthread_cond_signal(&s.go);
    pthread_mutex_unlock(&s.mutex);
    pthread_join(other, NULL);
    if (s.status != LPI_ERR_NO_MEMORY) return 21;
    if (setrlimit(RLIMIT_AS, &previous) != 0) return 22;
    return lpi_destroy(sys) == LPI_OK ? 0 : 23;
}

/* In the parent the pool of OpenMP threads must not exist yet at the fork
 * (libgomp's threads are not copied into a child), so this runs first. */
static void test_refused_threads_give_a_status(void **state) {
    (void)state;
    /* An address-space limit does not mix with a sanitizer's shadow memory
     * and allocator, or with valgrind's own mappings. */
    LPI_SKIP_UNDER_A_SANITIZER();
    if (under_valgrind()) LPI_SKIP("thread limits under a low RLIMIT_AS: not under valgrind");
    fflush(stdout);
    const pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        _exit(run_under_a_low_limit(4));
    }
    int status = 0;
    assert_int_equal(waitpid(child, &status, 0), child);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 100)
        LPI_SKIP("thread limits: built without FFTW or without OpenMP");
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        fail_msg("under a low RLIMIT_AS the child %s %d", WIFEXITED(status) ? "failed check" :
                 "was killed by signal", WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
}

/* The modes (n doubles) of sys after `steps` steps of 0.01 with `threads`
 * threads, stepped on the calling thread, sys destroyed; 0 on success, 100
 * for no system (built without FFTW). */
static int modes_after_steps(lpi_system *sys, int threads, int steps, double *w, size_t n) {
    if (!sys) return 100;
    int status = lpi_set_threads(sys, threads);
    if (status == LPI_OK) status = lpi_step(sys, 0.01, steps);
    if (status == LPI_OK) status = lpi_sine_euler_get_modes(sys, w, n);
    lpi_destroy(sys);
    return status;
}

static int fifteen_after_20_steps(int threads, double *w) {
    return modes_after_steps(sine_euler_15(), threads, 20, w, 2 * 15 * 15);
}

/* A host program that steps its handles from its own OpenMP parallel region
 * (one handle a thread, or one handle on the master thread alone) gets the
 * bits of a serial run: the library's one-thread flows use plain loops, not
 * work sharing that would bind to the host's team (it skipped lines, waited
 * at barriers the other threads never reached, and indexed block buffers by
 * the host's thread numbers). */
static void test_steps_inside_a_host_parallel_region(void **state) {
    (void)state;
#ifndef _OPENMP
    LPI_SKIP("a host parallel region: this test is built without OpenMP");
#else
    double serial[2 * 15 * 15];
    if (fifteen_after_20_steps(1, serial) != LPI_OK) LPI_SKIP("built without FFTW: no sine-Euler system");
    double each[2][2 * 15 * 15], master[2 * 15 * 15];
    int status[2] = {-1, -1}, master_status = -1;
#pragma omp parallel num_threads(2)
    {
        const int me = omp_get_thread_num();
        status[me] = fifteen_after_20_steps(1, each[me]);
    }
#pragma omp parallel num_threads(2)
    {
#pragma omp master
        master_status = fifteen_after_20_steps(1, master);
    }
    for (int i = 0; i < 2; ++i) {
        assert_int_equal(status[i], LPI_OK);
        assert_memory_equal(each[i], serial, sizeof serial);
    }
    assert_int_equal(master_status, LPI_OK);
    assert_memory_equal(master, serial, sizeof serial);
#endif
}

#ifdef _OPENMP
/* A field at N = 45 (22 lines a direction: two blocks, so that more than
 * one thread gets work), or NULL. */
static lpi_system *sine_euler_45(void) {
    enum { N = 45 };
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, N) != LPI_OK) return NULL;
    double w[2 * N * N] = {0};
    for (int k = 1; k <= 6; ++k) { /* modes (k, 2k) and their mirrors (-k, -2k) */
        const int row = k, col = 2 * k, mirror = (N - row) * N + (N - col);
        w[2 * (row * N + col)] = w[2 * mirror] = 1.0 / k;
        w[2 * (row * N + col) + 1] = 0.5 / k, w[2 * mirror + 1] = -0.5 / k;
    }
    if (lpi_sine_euler_set_modes(sys, w, 2 * N * N) != LPI_OK) {
        lpi_destroy(sys);
        return NULL;
    }
    return sys;
}

static int forty_five_after_5_steps(int threads, double *w) {
    return modes_after_steps(sine_euler_45(), threads, 5, w, 2 * 45 * 45);
}
#endif

/* A handle set to 2 or 3 threads and stepped from inside a host's active
 * parallel region opens a nested region, which gets one thread where nested
 * regions are inactive (the default): that one thread does all of a flow,
 * the phase tables the others would write included, and the result has the
 * bits of a serial run (with nested regions active, the usual team has them
 * too). */
static void test_threads_asked_inside_a_host_parallel_region(void **state) {
    (void)state;
#ifndef _OPENMP
    LPI_SKIP("a host parallel region: this test is built without OpenMP");
#else
    double serial[2 * 45 * 45], inside[2 * 45 * 45];
    const int status = forty_five_after_5_steps(1, serial);
    if (status == 100) LPI_SKIP("built without FFTW: no sine-Euler system");
    assert_int_equal(status, LPI_OK);
    for (int threads = 2; threads <= 3; ++threads) {
        int stepped = -1;
#pragma omp parallel num_threads(2)
        {
#pragma omp master
            stepped = forty_five_after_5_steps(threads, inside);
        }
        assert_int_equal(stepped, LPI_OK);
        assert_memory_equal(inside, serial, sizeof serial);
    }
#endif
}

/* In a child of fork(2), the thread that forked after the library ran a team
 * of threads on it is refused more than one thread under libgomp
 * (LPI_ERR_UNSUPPORTED: its pool was not copied, and a team would wait
 * forever); libomp (KMP_VERSION_MAJOR, a Clang build) starts afresh in a
 * child, and runs them. One thread, and another thread of the child, run as
 * usual. Runs after the tests that start teams on this thread. */
static void *child_thread_steps(void *w) {
    static int status;
    status = fifteen_after_20_steps(2, w);
    return &status;
}
static void test_fork_after_threads(void **state) {
    (void)state;
    double parent[2 * 15 * 15];
    const int status = fifteen_after_20_steps(2, parent);
    if (status == LPI_ERR_UNSUPPORTED || status == 100)
        LPI_SKIP("fork after threads: built without FFTW or without OpenMP");
    assert_int_equal(status, LPI_OK);
    fflush(stdout);
    const pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        alarm(60); /* a hang ends the child, and the test fails */
        double w[2 * 15 * 15];
        /* libomp (or libiomp5) is the library's runtime wherever one is
         * loaded: a Clang build's own, or a Clang-built host's, which takes
         * the OpenMP calls of a GCC-built library (tests/check_mixed_openmp.sh).
         * Asked at run time: this test's compiler need not be the library's. */
        if (dlsym(RTLD_DEFAULT, "kmp_get_stacksize_s")) {
            if (fifteen_after_20_steps(2, w) != LPI_OK || memcmp(w, parent, sizeof w) != 0) _exit(1);
        } else if (fifteen_after_20_steps(2, w) != LPI_ERR_UNSUPPORTED) {
            _exit(1);
        }
        if (fifteen_after_20_steps(1, w) != LPI_OK || memcmp(w, parent, sizeof w) != 0) _exit(2);
        pthread_t other;
        void *result = NULL;
        if (pthread_create(&other, NULL, child_thread_steps, w) != 0) _exit(3);
        pthread_join(other, &result);
        if (*(int *)result != LPI_OK || memcmp(w, parent, sizeof w) != 0) _exit(4);
        _exit(0);
    }
    int wait_status = 0;
    assert_int_equal(waitpid(child, &wait_status, 0), child);
    if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0)
        fail_msg("the child of fork %s %d", WIFEXITED(wait_status) ? "failed check" : "was killed by signal",
                 WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : WTERMSIG(wait_status));
}

/* The child's exit: 0 when it ended by itself with status 0, else fails. */
static void expect_child_passed(pid_t child, const char *what) {
    int wait_status = 0;
    assert_int_equal(waitpid(child, &wait_status, 0), child);
    if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0)
        fail_msg("%s: the child of fork %s %d", what, WIFEXITED(wait_status) ? "failed check" : "was killed by signal",
                 WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : WTERMSIG(wait_status));
}

/* An observer that forks in the middle of a two-thread step: the child ends
 * the step (its flows on one thread, the same bits) where libgomp's team
 * waited for ever for the parent's threads. */
static int fork_at_step_5(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys, (void)t;
    if (step == 5) {
        fflush(stdout);
        *(pid_t *)user = fork();
        if (*(pid_t *)user == 0) alarm(60);
    }
    return 0;
}
enum { kForkN = 47 }; /* several blocks of lines a flow: two threads share them */
static lpi_system *smooth_field(void) {
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, kForkN) != LPI_OK) return NULL;
    static double grid[kForkN * kForkN];
    for (int a = 0; a < kForkN; ++a)
        for (int b = 0; b < kForkN; ++b)
            grid[a * kForkN + b] = cos(2 * M_PI * a / kForkN) + 0.5 * sin(2 * M_PI * (a + 2 * b) / kForkN);
    if (lpi_sine_euler_set_grid(sys, grid, kForkN * kForkN) != LPI_OK) return NULL;
    return sys;
}
static void test_fork_inside_a_step(void **state) {
    (void)state;
    static double parent[2 * kForkN * kForkN], w[2 * kForkN * kForkN];
    const size_t n = 2 * kForkN * kForkN;
    if (modes_after_steps(smooth_field(), 1, 10, parent, n) != LPI_OK)
        LPI_SKIP("fork inside a step: built without FFTW");
    lpi_system *sys = smooth_field();
    const int threads = lpi_set_threads(sys, 2);
    if (threads == LPI_ERR_UNSUPPORTED) {
        lpi_destroy(sys);
        LPI_SKIP("fork inside a step: built without OpenMP");
    }
    assert_int_equal(threads, LPI_OK);
    pid_t child = -1;
    assert_int_equal(lpi_set_observer(sys, 1, fork_at_step_5, &child), LPI_OK);
    const int status = lpi_step(sys, 0.01, 10);
    if (child == 0) {
        const int got = lpi_sine_euler_get_modes(sys, w, n);
        _exit(status != LPI_OK || got != LPI_OK ? 1 : memcmp(w, parent, sizeof w) != 0 ? 2 : 0);
    }
    assert_true(child > 0);
    assert_int_equal(status, LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, w, n), LPI_OK);
    assert_memory_equal(w, parent, sizeof w);
    lpi_destroy(sys);
    expect_child_passed(child, "fork inside a two-thread step");
}

/* A host's own OpenMP region on a thread, then a fork from it: the child asks
 * for two threads there. libgomp's team would wait for ever for the
 * parent's threads, which the library cannot see were started: refused
 * (LPI_ERR_UNSUPPORTED), where lpi_set_threads hung; libomp runs them. */
#ifdef _OPENMP
static void *host_region_then_fork(void *result) {
    int sum = 0;
#pragma omp parallel num_threads(2) reduction(+ : sum)
    sum += 1;
    fflush(stdout);
    const pid_t child = fork();
    if (child == 0) {
        alarm(60);
        lpi_system *sys = sine_euler_15();
        const int status = lpi_set_threads(sys, 2);
        const int libomp = dlsym(RTLD_DEFAULT, "kmp_get_stacksize_s") != NULL;
        if (status != (libomp ? LPI_OK : LPI_ERR_UNSUPPORTED)) _exit(1);
        if (!libomp && !strstr(lpi_last_error(sys), "fork")) _exit(2);
        double w[2 * 15 * 15];
        if (lpi_set_threads(sys, 1) != LPI_OK || lpi_step(sys, 0.01, 20) != LPI_OK ||
            lpi_sine_euler_get_modes(sys, w, 2 * 15 * 15) != LPI_OK)
            _exit(3);
        _exit(0);
    }
    *(pid_t *)result = sum == 2 || sum == 1 ? child : -1;
    return NULL;
}
#endif
static void test_fork_after_a_host_region(void **state) {
    (void)state;
#ifndef _OPENMP
    LPI_SKIP("a host region before fork: this test is built without OpenMP");
#else
    double w[2 * 15 * 15];
    if (fifteen_after_20_steps(1, w) != LPI_OK) LPI_SKIP("a host region before fork: built without FFTW");
    if (fifteen_after_20_steps(2, w) == LPI_ERR_UNSUPPORTED)
        LPI_SKIP("a host region before fork: the library is built without OpenMP");
    pthread_t host;
    pid_t child = -1;
    assert_int_equal(pthread_create(&host, NULL, host_region_then_fork, &child), 0);
    assert_int_equal(pthread_join(host, NULL), 0);
    assert_true(child > 0);
    expect_child_passed(child, "a host region, then fork");
#endif
}

/* Another thread planning (a new system, FFTW's patient planner) while the
 * process forks: the child's first plan waited for ever for the planner
 * lock the other thread held at the fork; the fork now waits for it. */
static atomic_int keep_planning = 1;
static void *plan_in_a_loop(void *unused) {
    (void)unused;
    while (keep_planning) {
        lpi_system *sys = NULL;
        if (lpi_sine_euler_create(&sys, 45) != LPI_OK) break;
        lpi_sine_euler_set_planning(sys, "patient");
        lpi_step(sys, 0.01, 1);
        lpi_destroy(sys);
    }
    return NULL;
}
static void test_fork_while_another_thread_plans(void **state) {
    (void)state;
    if (under_valgrind()) LPI_SKIP("fork while another thread plans: valgrind runs one thread at a time");
    double w[2 * 15 * 15];
    if (fifteen_after_20_steps(1, w) != LPI_OK) LPI_SKIP("fork while planning: built without FFTW");
    keep_planning = 1;
    pthread_t planner;
    assert_int_equal(pthread_create(&planner, NULL, plan_in_a_loop, NULL), 0);
    for (int i = 0; i < 5; ++i) {
        usleep(20000);
        fflush(stdout);
        const pid_t child = fork();
        assert_true(child >= 0);
        if (child == 0) {
            alarm(60);
            double v[2 * 15 * 15];
            _exit(fifteen_after_20_steps(1, v) != LPI_OK ? 1 : memcmp(v, w, sizeof v) != 0 ? 2 : 0);
        }
        expect_child_passed(child, "fork while another thread plans");
    }
    keep_planning = 0;
    assert_int_equal(pthread_join(planner, NULL), 0);
}

/* A host planning with FFTW on its own thread while the library plans: FFTW's
 * planner is the process's, and the library's own lock did not cover the
 * host's plans (the heap corrupted: "double free", or FFTW's assertions). */
#if LPI_TEST_WITH_FFTW
#include <fftw3.h>
static atomic_int host_plans = 1;
static void *host_plans_with_fftw(void *count) {
    fftw_complex *buffer = fftw_alloc_complex(64);
    long plans = 0;
    while (host_plans) {
        fftw_plan plan = fftw_plan_dft_1d(17 + (int)(plans % 40), buffer, buffer, FFTW_FORWARD, FFTW_ESTIMATE);
        fftw_destroy_plan(plan);
        ++plans;
    }
    fftw_free(buffer);
    *(long *)count = plans;
    return NULL;
}
#endif
static void test_host_plans_beside_the_library(void **state) {
    (void)state;
#if !LPI_TEST_WITH_FFTW
    LPI_SKIP("a host's own FFTW plans: built without FFTW, or with an FFTW without planner hooks");
#else
    if (under_valgrind()) LPI_SKIP("a host's own FFTW plans: valgrind runs one thread at a time");
    host_plans = 1;
    long plans = 0;
    pthread_t host;
    assert_int_equal(pthread_create(&host, NULL, host_plans_with_fftw, &plans), 0);
    for (int i = 0; i < 40; ++i) {
        lpi_system *sys = NULL;
        const int N = 3 + 2 * (i % 20);
        assert_int_equal(lpi_sine_euler_create(&sys, N), LPI_OK);
        double grid[41 * 41] = {0};
        grid[1] = 1.0, grid[N] = 2.0;
        assert_int_equal(lpi_sine_euler_set_grid(sys, grid, (size_t)N * N), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.01, 1), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_planning(sys, "measure"), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.01, 1), LPI_OK);
        assert_int_equal(lpi_destroy(sys), LPI_OK);
    }
    host_plans = 0;
    assert_int_equal(pthread_join(host, NULL), 0);
    print_message("the host made %ld plans beside the library's\n", plans);
#endif
}

/* The host plans on another thread while the process forks: the child's
 * plan found the planner's lock taken for ever (the lock the library put
 * around every FFTW plan, the host's too). */
#if LPI_TEST_WITH_FFTW
static void *host_plans_alone(void *unused) {
    (void)unused;
    fftw_complex *buffer = fftw_alloc_complex(64);
    while (host_plans) fftw_destroy_plan(fftw_plan_dft_1d(31, buffer, buffer, FFTW_FORWARD, FFTW_ESTIMATE));
    fftw_free(buffer);
    return NULL;
}
#endif
static void test_fork_while_the_host_plans(void **state) {
    (void)state;
#if !LPI_TEST_WITH_FFTW
    LPI_SKIP("fork while the host plans: built without FFTW, or with an FFTW without planner hooks");
#else
    if (under_valgrind()) LPI_SKIP("fork while the host plans: valgrind runs one thread at a time");
    host_plans = 1;
    pthread_t host;
    assert_int_equal(pthread_create(&host, NULL, host_plans_alone, NULL), 0);
    for (int i = 0; i < 20; ++i) {
        fflush(stdout);
        const pid_t child = fork();
        assert_true(child >= 0);
        if (child == 0) {
            alarm(60);
            fftw_complex buffer[17];
            fftw_destroy_plan(fftw_plan_dft_1d(17, buffer, buffer, FFTW_FORWARD, FFTW_ESTIMATE));
            double w[2 * 15 * 15];
            _exit(fifteen_after_20_steps(1, w) != LPI_OK ? 1 : 0);
        }
        expect_child_passed(child, "fork while the host plans");
    }
    host_plans = 0;
    assert_int_equal(pthread_join(host, NULL), 0);
#endif
}

/* fork(2) from a signal handler that interrupted the library's planning on
 * the same thread: the fork handler waited for the lock its own thread
 * held. Run by this program again (`forks-from-a-signal-handler`), a
 * process that has had no other thread: in one that had, glibc's fork
 * takes malloc's locks, which the interrupted code may hold. */
static const char *program_path;
static void fork_and_leave(int signal) {
    (void)signal;
    const pid_t child = fork();
    if (child == 0) _exit(0);
    if (child > 0) waitpid(child, NULL, 0);
}
static int forks_from_a_signal_handler(void) {
    signal(SIGALRM, fork_and_leave);
    const struct itimerval every_2_ms = {{0, 2000}, {0, 2000}};
    setitimer(ITIMER_REAL, &every_2_ms, NULL);
    for (int i = 0; i < 100; ++i) {
        lpi_system *sys = NULL;
        if (lpi_sine_euler_create(&sys, 15 + 2 * (i % 10)) != LPI_OK) return 1;
        lpi_sine_euler_set_planning(sys, "measure");
        lpi_step(sys, 0.01, 1);
        lpi_destroy(sys);
    }
    return 0;
}
static void test_fork_from_a_signal_handler(void **state) {
    (void)state;
    double w[2 * 15 * 15];
    if (fifteen_after_20_steps(1, w) != LPI_OK) LPI_SKIP("fork from a signal handler: built without FFTW");
    if (under_valgrind()) LPI_SKIP("fork from a signal handler: a timer every 2 ms is too often for valgrind");
#ifdef LPI_TEST_SANITIZER
    /* A sanitizer's allocator takes its locks in fork, which the interrupted
     * code may hold (ThreadSanitizer reports the handler's fork itself). */
    LPI_SKIP("fork from a signal handler: not under " LPI_TEST_SANITIZER ", whose fork takes its allocator's locks");
#endif
    /* libomp's own child handler allocates, which a child forked while
     * malloc was interrupted cannot (its heap corrupt, or a lock held). */
    if (dlsym(RTLD_DEFAULT, "kmp_get_stacksize_s"))
        LPI_SKIP("fork from a signal handler: libomp's fork handler allocates in the child");
    fflush(stdout);
    const pid_t runner = fork();
    assert_true(runner >= 0);
    if (runner == 0) {
        execl("/proc/self/exe", program_path, "forks-from-a-signal-handler", (char *)NULL);
        _exit(127);
    }
    int wait_status = 0;
    pid_t done = 0;
    for (int waited = 0; waited < 600 && (done = waitpid(runner, &wait_status, WNOHANG)) == 0; ++waited)
        usleep(100000);
    if (done == 0) {
        kill(runner, SIGKILL);
        waitpid(runner, NULL, 0);
        fail_msg("forks from a signal handler during planning: no end after 60 s");
    }
    assert_true(WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0);
}

static void test_thread_count_bound(void **state) {
    (void)state;
    lpi_system *sys = sine_euler_15();
    if (!sys || lpi_set_threads(sys, 2) == LPI_ERR_UNSUPPORTED) {
        lpi_destroy(sys);
        LPI_SKIP("thread count bound: built without FFTW or without OpenMP");
    }
    cpu_set_t set;
    assert_int_equal(sched_getaffinity(0, sizeof set, &set), 0);
    const int bound = 4 * CPU_COUNT(&set);
    assert_int_equal(lpi_set_threads(sys, bound), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 2), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_set_threads(sys, bound + 1), LPI_ERR_INVALID, "lpi_set_threads");
    LPI_ASSERT_FAILS(sys, lpi_set_threads(sys, INT32_MAX), LPI_ERR_INVALID, "lpi_set_threads");
    assert_non_null(strstr(lpi_last_error(sys), "exceeds"));
    lpi_destroy(sys);
}

/* ---- one handle, two threads: the second is refused ------------------------ */

/* The observer holds the first thread inside lpi_step until the second has
 * made its calls. */
typedef struct {
    pthread_mutex_t lock;
    pthread_cond_t changed;
    int inside, intruded;
    lpi_system *sys;
    int statuses[4];
    int another_thread_named, handle_message_kept;
} handoff;

static int holding_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys; (void)step; (void)t;
    handoff *h = user;
    pthread_mutex_lock(&h->lock);
    if (!h->inside) {
        h->inside = 1;
        pthread_cond_broadcast(&h->changed);
        while (!h->intruded) pthread_cond_wait(&h->changed, &h->lock);
    }
    pthread_mutex_unlock(&h->lock);
    return 0;
}

static void *intruder(void *arg) {
    handoff *h = arg;
    pthread_mutex_lock(&h->lock);
    while (!h->inside) pthread_cond_wait(&h->changed, &h->lock);
    pthread_mutex_unlock(&h->lock);
    const double x[3] = {5.0, 5.0, 5.0};
    double e;
    /* A change, a read (which the observer itself may make) and a destroy. */
    h->statuses[0] = lpi_set_state(h->sys, x, 3);
    h->statuses[1] = lpi_energy(h->sys, &e);
    h->statuses[2] = lpi_step(h->sys, 0.1, 1);
    h->statuses[3] = lpi_destroy(h->sys);
    h->another_thread_named = strstr(lpi_last_error(NULL), "another thread") != NULL;
    pthread_mutex_lock(&h->lock);
    h->intruded = 1;
    pthread_cond_broadcast(&h->changed);
    pthread_mutex_unlock(&h->lock);
    return NULL;
}

/* A call on a handle while another thread is inside a call on it is refused
 * with LPI_ERR_BUSY, whatever that call is doing (here: its observer, which
 * could itself read the handle), changes nothing, and leaves its message to
 * the calling thread (lpi_last_error(NULL)): the handle's own is the other
 * thread's to write. */
static void test_another_thread_is_refused(void **state) {
    (void)state;
    handoff h = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0, 0, NULL, {0}, 0, 0};
    const double m0[3] = {0.3, 1.1, -0.7};
    lpi_system *reference = NULL;
    assert_int_equal(lpi_rigid_body_create(&h.sys, 1.0, 2.0, 3.0), LPI_OK);
    assert_int_equal(lpi_rigid_body_create(&reference, 1.0, 2.0, 3.0), LPI_OK);
    assert_int_equal(lpi_set_state(h.sys, m0, 3), LPI_OK);
    assert_int_equal(lpi_set_state(reference, m0, 3), LPI_OK);
    assert_int_equal(lpi_set_observer(h.sys, 1, holding_observer, &h), LPI_OK);
    pthread_t other;
    assert_int_equal(pthread_create(&other, NULL, intruder, &h), 0);
    assert_int_equal(lpi_step(h.sys, 0.01, 5), LPI_OK);
    assert_int_equal(pthread_join(other, NULL), 0);
    for (int i = 0; i < 4; ++i) assert_int_equal(h.statuses[i], LPI_ERR_BUSY);
    assert_true(h.another_thread_named);
    assert_string_equal(lpi_last_error(h.sys), "");
    assert_int_equal(lpi_step(reference, 0.01, 5), LPI_OK);
    double a[3], b[3];
    assert_int_equal(lpi_get_state(h.sys, a, 3), LPI_OK);
    assert_int_equal(lpi_get_state(reference, b, 3), LPI_OK);
    assert_memory_equal(a, b, sizeof a);
    lpi_destroy(reference);
    assert_int_equal(lpi_destroy(h.sys), LPI_OK);
}

/* Two threads calling lpi_step on one handle at once, as fast as they can:
 * each call runs alone or is refused, and the time is the steps that ran. */
typedef struct {
    lpi_system *sys;
    pthread_barrier_t *start;
    int ran, refused, other;
} racer;

static void *race(void *arg) {
    racer *r = arg;
    pthread_barrier_wait(r->start);
    for (int i = 0; i < 400; ++i) {
        const int status = lpi_step(r->sys, 0.25, 20);
        if (status == LPI_OK) r->ran++;
        else if (status == LPI_ERR_BUSY) r->refused++;
        else r->other++;
    }
    return NULL;
}

static void test_two_threads_at_once(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    const double m0[3] = {0.3, 1.1, -0.7};
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    assert_int_equal(lpi_set_state(sys, m0, 3), LPI_OK);
    pthread_barrier_t start;
    assert_int_equal(pthread_barrier_init(&start, NULL, 2), 0);
    racer r[2] = {{sys, &start, 0, 0, 0}, {sys, &start, 0, 0, 0}};
    pthread_t t[2];
    for (int i = 0; i < 2; ++i) assert_int_equal(pthread_create(&t[i], NULL, race, &r[i]), 0);
    for (int i = 0; i < 2; ++i) assert_int_equal(pthread_join(t[i], NULL), 0);
    pthread_barrier_destroy(&start);
    assert_int_equal(r[0].other + r[1].other, 0);
    assert_int_equal(r[0].ran + r[0].refused, 400);
    /* Calls of 20 steps of 0.25 from 0: every partial time is exact. */
    assert_true(lpi_time(sys) == 5.0 * (r[0].ran + r[1].ran));
    print_message("two threads, 800 calls: %d ran, %d refused\n", r[0].ran + r[1].ran,
                  r[0].refused + r[1].refused);
    assert_int_equal(lpi_destroy(sys), LPI_OK);
}

int main(int argc, char **argv) {
    program_path = argv[0];
    if (argc == 2 && strcmp(argv[1], "forks-from-a-signal-handler") == 0) return forks_from_a_signal_handler();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refused_threads_give_a_status),
        cmocka_unit_test(test_handles_on_threads),
        cmocka_unit_test(test_thread_count_bound),
        cmocka_unit_test(test_steps_inside_a_host_parallel_region),
        cmocka_unit_test(test_threads_asked_inside_a_host_parallel_region),
        cmocka_unit_test(test_fork_after_threads),
        cmocka_unit_test(test_fork_inside_a_step),
        cmocka_unit_test(test_fork_after_a_host_region),
        cmocka_unit_test(test_fork_while_another_thread_plans),
        cmocka_unit_test(test_host_plans_beside_the_library),
        cmocka_unit_test(test_fork_while_the_host_plans),
        cmocka_unit_test(test_fork_from_a_signal_handler),
        cmocka_unit_test(test_another_thread_is_refused),
        cmocka_unit_test(test_two_threads_at_once),
    };
    return lpi_run_tests(tests);
}
