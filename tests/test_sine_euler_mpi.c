/* Sine-Euler spread over MPI processes (liepoisson_mpi.h), run by ctest under
 * mpirun with 1 to 4 processes: the distributed handle follows the library's
 * one-process model to the bit (a 4th-order method, 10 steps, N prime and
 * composite: the state, modes, grid, traces, stream function and shell
 * spectrum, as lpi_sine_euler_create_mpi(3) says; energy and enstrophy to
 * round-off), its outputs are the same on every process, checkpoints are one
 * file that both load, and bad input gets the same status on every process
 * with the state unchanged. */
#include <liepoisson_mpi.h>
#include <unistd.h>

#include "lpi_test.h"

static int rank_, size_;

/* The same random field on every process (public coordinates, N^2). */
static void random_field(double *x, size_t n, unsigned seed) {
    uint64_t s = 0x9E3779B97F4A7C15ull ^ seed;
    for (size_t i = 0; i < n; ++i) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        x[i] = ((double)(s >> 11) / 9007199254740992.0 - 0.5);
    }
}

static double max_abs(const double *x, size_t n) {
    double m = 0.0;
    for (size_t i = 0; i < n; ++i) m = fmax(m, fabs(x[i]));
    return m;
}

static double max_diff(const double *a, const double *b, size_t n) {
    double m = 0.0;
    for (size_t i = 0; i < n; ++i) m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* Every process holds the same bytes. */
static void assert_same_on_every_process(const double *x, size_t n) {
    double *root = malloc(n * sizeof *root);
    assert_non_null(root);
    memcpy(root, x, n * sizeof *root);
    MPI_Bcast(root, (int)n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    assert_memory_equal(root, x, n * sizeof *root);
    free(root);
}

/* A spread handle and a one-process handle with the same field and method. */
static void make_pair(int N, const char *method, lpi_system **spread, lpi_system **single, double *x) {
    const size_t n = (size_t)N * N;
    random_field(x, n, (unsigned)N);
    assert_int_equal(lpi_sine_euler_create_mpi(spread, N, MPI_COMM_WORLD), LPI_OK);
    assert_int_equal(lpi_sine_euler_create(single, N), LPI_OK);
    assert_int_equal(lpi_set_state(*spread, x, n), LPI_OK);
    assert_int_equal(lpi_set_state(*single, x, n), LPI_OK);
    assert_int_equal(lpi_set_method(*spread, method), LPI_OK);
    assert_int_equal(lpi_set_method(*single, method), LPI_OK);
}

static void test_matches_one_process(void **state) {
    (void)state;
    /* 5: M = 2 lines, fewer than the processes at P = 3 and 4 (some hold none).
     * 27 = 3^3: nine of its 36 directions are Column directions, whose lines a
     * process gathers down the columns of the mode array. */
    static const int orders[] = {5, 13, 15, 25, 27, 31};
    for (size_t k = 0; k < sizeof orders / sizeof orders[0]; ++k) {
        const int N = orders[k];
        const size_t n = (size_t)N * N;
        double *x0 = malloc(n * sizeof *x0), *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
        assert_true(x0 && a && b);
        lpi_system *spread, *single;
        make_pair(N, "suzuki-4", &spread, &single, x0);
        /* The state read back before stepping is the one set. */
        assert_int_equal(lpi_get_state(spread, a, n), LPI_OK);
        assert_memory_equal(a, x0, n * sizeof *a);
        assert_int_equal(lpi_step(spread, 0.05, 10), LPI_OK);
        assert_int_equal(lpi_step(single, 0.05, 10), LPI_OK);
        assert_int_equal(lpi_get_state(spread, a, n), LPI_OK);
        assert_int_equal(lpi_get_state(single, b, n), LPI_OK);
        const double scale = max_abs(b, n);
        const double gap = max_diff(a, b, n);
        if (rank_ == 0) printf("N = %d, P = %d: max |spread - one process| / max |w| = %.2e\n", N, size_, gap / scale);
        assert_memory_equal(a, b, n * sizeof *a);
        assert_true(max_diff(a, x0, n) > 1e-3 * scale); /* the field moved */
        assert_same_on_every_process(a, n);

        double h1, h2, z1, z2, t1[3], t2[3];
        assert_int_equal(lpi_energy(spread, &h1), LPI_OK);
        assert_int_equal(lpi_energy(single, &h2), LPI_OK);
        assert_true(fabs(h1 - h2) <= 1e-12 * fabs(h2));
        assert_same_on_every_process(&h1, 1);
        assert_int_equal(lpi_sine_euler_enstrophy(spread, &z1), LPI_OK);
        assert_int_equal(lpi_sine_euler_enstrophy(single, &z2), LPI_OK);
        assert_true(fabs(z1 - z2) <= 1e-12 * fabs(z2));
        assert_int_equal(lpi_sine_euler_casimir_traces(spread, 3, t1), LPI_OK);
        assert_int_equal(lpi_sine_euler_casimir_traces(single, 3, t2), LPI_OK);
        assert_memory_equal(t1, t2, sizeof t1);
        assert_same_on_every_process(t1, 3);

        /* Modes and grid: the whole field on every process. */
        double *m1 = malloc(2 * n * sizeof *m1), *m2 = malloc(2 * n * sizeof *m2);
        assert_true(m1 && m2);
        assert_int_equal(lpi_sine_euler_get_modes(spread, m1, 2 * n), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(single, m2, 2 * n), LPI_OK);
        assert_memory_equal(m1, m2, 2 * n * sizeof *m1);
        assert_int_equal(lpi_sine_euler_get_grid(spread, m1, n), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_grid(single, m2, n), LPI_OK);
        assert_memory_equal(m1, m2, n * sizeof *m1);
        assert_same_on_every_process(m1, n);
        free(m1), free(m2);
        lpi_destroy(spread), lpi_destroy(single);
        free(x0), free(a), free(b);
    }
}

/* Threads per process change no bit (one handle, so one set of FFTW plans). */
static void test_threads_per_process(void **state) {
    (void)state;
    const int N = 67; /* M = 33: three blocks of lines on one process */
    const size_t n = (size_t)N * N;
    double *x = malloc(n * sizeof *x), *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    assert_true(x && a && b);
    lpi_system *sys;
    random_field(x, n, 7);
    assert_int_equal(lpi_sine_euler_create_mpi(&sys, N, MPI_COMM_WORLD), LPI_OK);
    assert_int_equal(lpi_set_state(sys, x, n), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.03, 5), LPI_OK);
    assert_int_equal(lpi_get_state(sys, a, n), LPI_OK);
    const int threads = lpi_set_threads(sys, 2);
    if (threads == LPI_ERR_UNSUPPORTED) {
        lpi_destroy(sys), free(x), free(a), free(b);
        LPI_SKIP("this build has no OpenMP");
    }
    assert_int_equal(threads, LPI_OK);
    assert_int_equal(lpi_set_state(sys, x, n), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.03, 5), LPI_OK);
    assert_int_equal(lpi_get_state(sys, b, n), LPI_OK);
    assert_memory_equal(a, b, n * sizeof *a);
    lpi_destroy(sys), free(x), free(a), free(b);
}

/* One file, written by rank 0: the one-process library loads it to the same
 * state, and lpi_load_mpi continues the trajectory to the bit. */
static void test_checkpoint(void **state) {
    (void)state;
    const int N = 15;
    const size_t n = (size_t)N * N;
    double x[225], a[225], b[225];
    char path[64];
    snprintf(path, sizeof path, "test_sine_euler_mpi_%d.lpi", size_);
    lpi_system *spread, *single, *loaded, *reloaded;
    make_pair(N, "mclachlan-4", &spread, &single, x);
    assert_int_equal(lpi_step(spread, 0.05, 10), LPI_OK);
    assert_int_equal(lpi_save(spread, path), LPI_OK);
    assert_int_equal(lpi_load(&loaded, path), LPI_OK);
    assert_int_equal(lpi_get_state(spread, a, n), LPI_OK);
    assert_int_equal(lpi_get_state(loaded, b, n), LPI_OK);
    assert_memory_equal(a, b, sizeof a);
    assert_string_equal(lpi_get_method(loaded), "mclachlan-4");
    assert_int_equal(lpi_load_mpi(&reloaded, path, MPI_COMM_WORLD), LPI_OK);
    assert_true(lpi_time(reloaded) == lpi_time(spread));
    assert_int_equal(lpi_step(spread, 0.05, 10), LPI_OK);
    assert_int_equal(lpi_step(reloaded, 0.05, 10), LPI_OK);
    assert_int_equal(lpi_get_state(spread, a, n), LPI_OK);
    assert_int_equal(lpi_get_state(reloaded, b, n), LPI_OK);
    assert_memory_equal(a, b, sizeof a);
    /* A file that is not there: LPI_ERR_IO on every process. */
    lpi_system *none = NULL;
    assert_int_equal(lpi_load_mpi(&none, "no/such/file.lpi", MPI_COMM_WORLD), LPI_ERR_IO);
    assert_int_equal(lpi_load_mpi(&none, "", MPI_COMM_WORLD), LPI_ERR_INVALID);
    assert_null(none);
    /* A file that is no checkpoint: LPI_ERR_FORMAT naming it, as lpi_load
     * does (rank 0's check of the header left the path out before). */
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank_ == 0) {
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fputs("not a checkpoint\n", f);
        assert_int_equal(fclose(f), 0);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    assert_int_equal(lpi_load_mpi(&none, path, MPI_COMM_WORLD), LPI_ERR_FORMAT);
    assert_non_null(strstr(lpi_last_error(NULL), path));
    assert_non_null(strstr(lpi_last_error(NULL), "magic"));
    assert_null(none);
    /* An intact checkpoint of a baseline's run: a system spread over
     * processes cannot step by it (LPI_ERR_UNSUPPORTED, not a bad file). */
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank_ == 0) {
        assert_int_equal(lpi_set_method(single, "rk4"), LPI_OK);
        assert_int_equal(lpi_step(single, 0.05, 2), LPI_OK);
        assert_int_equal(lpi_save(single, path), LPI_OK);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    assert_int_equal(lpi_load_mpi(&none, path, MPI_COMM_WORLD), LPI_ERR_UNSUPPORTED);
    assert_non_null(strstr(lpi_last_error(NULL), "baseline"));
    assert_null(none);
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank_ == 0) remove(path);
    lpi_destroy(spread), lpi_destroy(single), lpi_destroy(loaded), lpi_destroy(reloaded);
}

/* SQG over a topography (lambda = 1/|n|, f_n = -h_n / |n|^2 for a smooth h):
 * the spread system follows the one-process system to the bit after 10 steps of
 * a 4th-order method, its energy is this H, its stream function and spectra
 * agree, and a checkpoint carries lambda and f into lpi_load_mpi. */
static void sqg_over_topography(int N, double *lambda, double *f) {
    const int M = (N - 1) / 2;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int p = a > M ? a - N : a, q = b > M ? b - N : b;
            const double n2 = (double)(p * p + q * q);
            const size_t i = (size_t)a * N + b;
            lambda[i] = n2 == 0 ? 0.0 : 1.0 / sqrt(n2);
            /* h: real on the grid, so h_{-n} = conj(h_n); nonzero for |n| <= 2. */
            const double h = n2 == 0 || n2 > 4 ? 0.0 : 0.3 / (1.0 + n2);
            f[2 * i] = n2 == 0 ? 0.0 : -h / n2;
            f[2 * i + 1] = n2 == 0 ? 0.0 : -0.1 * h * (p + 2 * q) / n2; /* odd in n */
        }
}

static void test_hamiltonian(void **state) {
    (void)state;
    /* 45 = 9 x 5: pieces that own modes by the first later class (a squared prime). */
    const int orders[] = {13, 15, 45};
    for (int k = 0; k < 3; ++k) {
        const int N = orders[k];
        const size_t n = (size_t)N * N;
        double *x0 = malloc(n * sizeof *x0), *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b),
               *lambda = malloc(n * sizeof *lambda), *f = malloc(2 * n * sizeof *f),
               *e1 = malloc(n * sizeof *e1), *e2 = malloc(n * sizeof *e2);
        assert_true(x0 && a && b && lambda && f && e1 && e2);
        sqg_over_topography(N, lambda, f);
        lpi_system *spread, *single, *reloaded;
        make_pair(N, "suzuki-4", &spread, &single, x0);
        assert_int_equal(lpi_sine_euler_set_hamiltonian(spread, lambda, n, f, 2 * n), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_hamiltonian(single, lambda, n, f, 2 * n), LPI_OK);
        double h1, h2;
        assert_int_equal(lpi_energy(spread, &h1), LPI_OK);
        assert_int_equal(lpi_energy(single, &h2), LPI_OK);
        assert_true(fabs(h1 - h2) <= 1e-13 * fabs(h2));
        assert_int_equal(lpi_step(spread, 0.05, 3), LPI_OK);
        assert_int_equal(lpi_step(single, 0.05, 3), LPI_OK);
        assert_int_equal(lpi_get_state(spread, a, n), LPI_OK);
        assert_int_equal(lpi_get_state(single, b, n), LPI_OK);
        const double scale = max_abs(b, n), gap = max_diff(a, b, n);
        if (rank_ == 0)
            printf("SQG over topography, N = %d, P = %d: max |spread - one process| / max |w| = %.2e\n", N,
                   size_, gap / scale);
        assert_memory_equal(a, b, n * sizeof *a);
        assert_same_on_every_process(a, n);
        assert_int_equal(lpi_energy(spread, &h1), LPI_OK);
        assert_int_equal(lpi_energy(single, &h2), LPI_OK);
        assert_true(fabs(h1 - h2) <= 1e-12 * fabs(h2));
        assert_int_equal(lpi_sine_euler_get_stream(spread, e1, n), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_stream(single, e2, n), LPI_OK);
        assert_memory_equal(e1, e2, n * sizeof *e1);
        size_t shells1 = 0, shells2 = 0;
        assert_int_equal(lpi_sine_euler_spectrum(spread, e1, a, n, &shells1), LPI_OK);
        assert_int_equal(lpi_sine_euler_spectrum(single, e2, b, n, &shells2), LPI_OK);
        assert_true(shells1 == shells2 && shells1 > 0);
        assert_memory_equal(e1, e2, shells1 * sizeof *e1);

        char path[64];
        snprintf(path, sizeof path, "test_sine_euler_mpi_h_%d.lpi", size_);
        assert_int_equal(lpi_save(spread, path), LPI_OK);
        assert_int_equal(lpi_load_mpi(&reloaded, path, MPI_COMM_WORLD), LPI_OK);
        assert_int_equal(lpi_energy(reloaded, &h2), LPI_OK);
        assert_true(h1 == h2);
        assert_int_equal(lpi_step(spread, 0.05, 2), LPI_OK);
        assert_int_equal(lpi_step(reloaded, 0.05, 2), LPI_OK);
        assert_int_equal(lpi_get_state(spread, a, n), LPI_OK);
        assert_int_equal(lpi_get_state(reloaded, b, n), LPI_OK);
        assert_memory_equal(a, b, n * sizeof *a);
        MPI_Barrier(MPI_COMM_WORLD);
        if (rank_ == 0) remove(path);
        /* Processes that pass different Hamiltonians: refused on all, unchanged. */
        lambda[1] += rank_ == size_ - 1 && size_ > 1 ? 0.5 : 0.0;
        lambda[N - 1] = lambda[1]; /* mode (0, -1) mirrors (0, 1) */
        const int status = lpi_sine_euler_set_hamiltonian(spread, lambda, n, f, 2 * n);
        assert_int_equal(status, size_ > 1 ? LPI_ERR_INVALID : LPI_OK);
        lpi_destroy(spread), lpi_destroy(single), lpi_destroy(reloaded);
        free(x0), free(a), free(b), free(lambda), free(f), free(e1), free(e2);
    }
}

/* Bytes the allocator has handed out and not had back (small blocks and
 * mmapped ones); 0 where the allocator is not glibc's (sanitizers, valgrind). */
static size_t bytes_in_use(void) {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
    const struct mallinfo2 info = mallinfo2();
    return info.uordblks + info.hblkhd;
#else
    return 0;
#endif
}

/* Whether bytes_in_use sees a block of 1 MiB (a sanitizer's allocator, or
 * another libc's, does not report to mallinfo2): asked before the work. */
static int allocator_reports_bytes(void) {
    const size_t before = bytes_in_use();
    char *block = malloc(1 << 20);
    assert_non_null(block);
    memset(block, 1, 1 << 20);
    const size_t during = bytes_in_use();
    free(block);
    return during >= before + (1 << 20);
}

/* What a handle on comm holds after the whole field and a forced Hamiltonian
 * were set (they are the caller's) and a step was taken (the first step
 * sizes every buffer a step uses). */
static size_t bytes_held(int N, MPI_Comm comm, const double *x, const double *lambda, const double *f) {
    const size_t n = (size_t)N * N;
    lpi_system *sys;
    const size_t before = bytes_in_use();
    assert_int_equal(lpi_sine_euler_create_mpi(&sys, N, comm), LPI_OK);
    assert_int_equal(lpi_set_state(sys, x, n), LPI_OK);
    assert_int_equal(lpi_sine_euler_set_hamiltonian(sys, lambda, n, f, 2 * n), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 1), LPI_OK);
    double h;
    assert_int_equal(lpi_energy(sys, &h), LPI_OK);
    const size_t after = bytes_in_use();
    lpi_destroy(sys);
    return after > before ? after - before : 0;
}

/* While stepping a process holds O(N^2 / P) bytes: no table of the whole
 * field (lambda, f, the pieces' ownership) is replicated. The same program
 * spread over P processes holds at most 1/P of what one process holds, plus
 * O(N) bytes: per process, the transforms' block of 16 lines, the phase
 * tables, line 0 with its weights and the exchange's buffers for line 0 and
 * its riders (about 820 N at N = 255 and P = 4; 1024 N allowed). Measured
 * in bytes, not as a fraction of what one process holds, which shrank when
 * the exchange's buffers were sized once instead of grown by doubling. */
static void test_memory_per_process(void **state) {
    (void)state;
    if (!allocator_reports_bytes()) LPI_SKIP("the allocator does not report its bytes in use (not glibc's malloc)");
    const int N = 255; /* 3 x 5 x 17 */
    const size_t n = (size_t)N * N;
    double *x = malloc(n * sizeof *x), *lambda = malloc(n * sizeof *lambda), *f = malloc(2 * n * sizeof *f);
    assert_true(x && lambda && f);
    random_field(x, n, 3);
    sqg_over_topography(N, lambda, f);
    unsigned long long one_process = 0; /* the same program on every process: measured once */
    if (rank_ == 0) one_process = bytes_held(N, MPI_COMM_SELF, x, lambda, f);
    MPI_Bcast(&one_process, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    const size_t alone = (size_t)one_process;
    bytes_held(N, MPI_COMM_WORLD, x, lambda, f); /* Open MPI's own buffers for this exchange */
    const size_t spread = bytes_held(N, MPI_COMM_WORLD, x, lambda, f);
    free(x), free(lambda), free(f);
    const size_t allowed = alone / (size_t)size_ + 1024 * (size_t)N;
    printf("rank %d: N = %d, one process holds %zu bytes, one of %d holds %zu (%.3f of it; at most %zu, "
           "1/%d of it plus %zu N)\n", rank_, N, alone, size_, spread, (double)spread / (double)alone,
           allowed, size_, (size_t)1024);
    assert_true(spread <= allowed);
}

/* An N whose share would pass a process's physical memory is refused on
 * every process with LPI_ERR_NO_MEMORY, naming the bytes, before anything
 * is allocated (zero-filled vectors that large bring the out-of-memory
 * killer, or, with no overcommit, a bare "out of memory"). */
static void test_too_large_n(void **state) {
    (void)state;
    const double physical = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    const int32_t N = 1000001; /* N (N / 2P) complex modes a process: ~4e12 bytes over 4 */
    if (!(physical > 0) || 16.0 * N * (N / 2 / size_) <= physical)
        LPI_SKIP("this machine's memory holds the share, or it does not say how much it has");
    lpi_system *sys = (lpi_system *)0x1;
    LPI_ASSERT_FAILS(NULL, lpi_sine_euler_create_mpi(&sys, N, MPI_COMM_WORLD), LPI_ERR_NO_MEMORY,
                     "lpi_sine_euler_create_mpi");
    assert_null(sys);
    assert_non_null(strstr(lpi_last_error(NULL), "bytes"));
    assert_non_null(strstr(lpi_last_error(NULL), "physical memory"));
}

/* Stops the run at step 2 on rank 0 alone. */
static int stop_on_rank_0(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys, (void)t, (void)user;
    return rank_ == 0 && step == 2;
}

/* Processes that pass different arguments to a call: refused on every
 * process with LPI_ERR_INVALID before anything else (a value that one
 * process alone refused would leave the others waiting in a collective), the
 * state unchanged. Thread counts may differ; an observer that stops on one
 * process stops every process at the same step. */
static void test_different_arguments(void **state) {
    (void)state;
    if (size_ == 1) LPI_SKIP("needs 2 or more processes");
    const int N = 13;
    const size_t n = (size_t)N * N;
    double x[169], y[169], c[13], lambda[169], f[338];
    lpi_system *spread, *single;
    make_pair(N, "leapfrog", &spread, &single, x);
    const int last = rank_ == size_ - 1;
    LPI_ASSERT_FAILS(spread, lpi_step(spread, last ? 0.02 : 0.01, 3), LPI_ERR_INVALID, "lpi_step");
    LPI_ASSERT_FAILS(spread, lpi_step(spread, 0.01, last ? 4 : 3), LPI_ERR_INVALID, "lpi_step");
    LPI_ASSERT_FAILS(spread, lpi_step(spread, last ? NAN : 0.01, 3), LPI_ERR_INVALID, "lpi_step");
    LPI_ASSERT_FAILS(spread, lpi_set_state(spread, last ? NULL : x, n), LPI_ERR_INVALID, "lpi_set_state");
    LPI_ASSERT_FAILS(spread, lpi_set_state(spread, x, last ? n - 1 : n), LPI_ERR_INVALID, "lpi_set_state");
    LPI_ASSERT_FAILS(spread, lpi_get_state(spread, y, last ? n + 1 : n), LPI_ERR_INVALID, "lpi_get_state");
    LPI_ASSERT_FAILS(spread, lpi_casimirs(spread, c, last ? 3 : 13), LPI_ERR_INVALID, "lpi_casimirs");
    LPI_ASSERT_FAILS(spread, lpi_energy(spread, last ? NULL : c), LPI_ERR_INVALID, "lpi_energy");
    LPI_ASSERT_FAILS(spread, lpi_set_method(spread, last ? "suzuki-4" : "leapfrog"), LPI_ERR_INVALID,
                     "lpi_set_method");
    const double gammas[3][3] = {{1.0, -1.0, 1.0}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
    LPI_ASSERT_FAILS(spread, lpi_set_composition(spread, 3, gammas[last]), LPI_ERR_INVALID,
                     "lpi_set_composition");
    sqg_over_topography(N, lambda, f);
    lambda[1] = last ? NAN : lambda[1]; /* refused as not finite on one process alone */
    LPI_ASSERT_FAILS(spread, lpi_sine_euler_set_hamiltonian(spread, lambda, n, f, 2 * n), LPI_ERR_INVALID,
                     "lpi_sine_euler_set_hamiltonian");
    LPI_ASSERT_FAILS(spread, lpi_save(spread, last ? NULL : "never_written.lpi"), LPI_ERR_INVALID, "lpi_save");
    assert_int_equal(access("never_written.lpi", F_OK), -1);
    /* Making a handle: the arguments are compared before any is checked. */
    lpi_system *none = NULL;
    assert_int_equal(lpi_sine_euler_create_mpi(last ? NULL : &none, N, MPI_COMM_WORLD), LPI_ERR_INVALID);
    assert_null(none);
    /* Different N: the same message on every process, naming both values. */
    if (size_ > 1) {
        assert_int_equal(lpi_sine_euler_create_mpi(&none, last ? N + 2 : N, MPI_COMM_WORLD), LPI_ERR_INVALID);
        assert_null(none);
        char expected[96];
        snprintf(expected, sizeof expected, "different N (%d on rank 0, %d on rank %d)", N, N + 2, size_ - 1);
        assert_non_null(strstr(lpi_last_error(NULL), expected));
    }
    assert_int_equal(lpi_load_mpi(&none, last ? NULL : "never_written.lpi", MPI_COMM_WORLD), LPI_ERR_INVALID);
    assert_null(none);
    assert_int_equal(lpi_load_mpi(last ? NULL : &none, "never_written.lpi", MPI_COMM_WORLD), LPI_ERR_INVALID);
    assert_null(none);

    /* A thread count refused on one process is refused on all, and the
     * count stays (each process bounds it by its own processors). */
    LPI_ASSERT_FAILS(spread, lpi_set_threads(spread, last ? 0 : 1), LPI_ERR_INVALID, "lpi_set_threads");
    /* Threads per process may differ: the same bits. */
    const int threads = lpi_set_threads(spread, 1 + rank_ % 2);
    assert_true(threads == LPI_OK || threads == LPI_ERR_UNSUPPORTED);
    assert_int_equal(lpi_set_observer(spread, 1, stop_on_rank_0, NULL), LPI_OK);
    assert_int_equal(lpi_step(spread, 0.01, 5), LPI_STOPPED);
    assert_true(lpi_time(spread) == 2 * 0.01);
    assert_int_equal(lpi_step(single, 0.01, 2), LPI_OK);
    assert_int_equal(lpi_get_state(spread, x, n), LPI_OK);
    assert_int_equal(lpi_get_state(single, y, n), LPI_OK);
    assert_true(max_diff(x, y, n) <= 1e-14 * max_abs(y, n));
    lpi_destroy(spread), lpi_destroy(single);
}

/* Bad input: the same status on every process, the state unchanged. */
static void test_bad_input(void **state) {
    (void)state;
    const int N = 13;
    const size_t n = (size_t)N * N;
    double x[169], y[169];
    lpi_system *spread, *single, *none = NULL;
    make_pair(N, "leapfrog", &spread, &single, x);
    LPI_ASSERT_FAILS(spread, lpi_set_method(spread, "rk4"), LPI_ERR_UNSUPPORTED, "lpi_set_method");
    LPI_ASSERT_FAILS(spread, lpi_set_method(spread, "rk4-matrix"), LPI_ERR_UNSUPPORTED,
                     "lpi_set_method");
    /* A field that differs between the processes. */
    memcpy(y, x, sizeof y);
    y[5] += rank_;
    if (size_ > 1)
        LPI_ASSERT_FAILS(spread, lpi_set_state(spread, y, n), LPI_ERR_INVALID, "lpi_set_state");
    y[5] = NAN;
    LPI_ASSERT_FAILS(spread, lpi_set_state(spread, y, n), LPI_ERR_NONFINITE, "lpi_set_state");
    LPI_ASSERT_FAILS(spread, lpi_set_state(spread, y, n - 1), LPI_ERR_SIZE, "lpi_set_state");
    /* A field so large that the first flow overflows on every process. */
    for (size_t i = 0; i < n; ++i) y[i] = 1e308;
    assert_int_equal(lpi_set_state(spread, y, n), LPI_OK);
    LPI_ASSERT_FAILS(spread, lpi_step(spread, 1.0, 3), LPI_ERR_NONFINITE, "lpi_step");
    /* Creation. */
    assert_int_equal(lpi_sine_euler_create_mpi(&none, 14, MPI_COMM_WORLD), LPI_ERR_INVALID);
    assert_null(none);
    assert_int_equal(lpi_sine_euler_create_mpi(&none, 13, MPI_COMM_NULL), LPI_ERR_INVALID);
    if (size_ > 1) {
        assert_int_equal(lpi_sine_euler_create_mpi(&none, rank_ == 0 ? 13 : 15, MPI_COMM_WORLD),
                         LPI_ERR_INVALID);
        assert_null(none);
    }
    assert_int_equal(lpi_sine_euler_create_mpi(NULL, 13, MPI_COMM_WORLD), LPI_ERR_NULL);
    /* An intercommunicator (even ranks against odd ones) is refused on every
     * process: on 3, the odd group's one process waited for ever. */
    if (size_ > 1) {
        MPI_Comm group, inter;
        MPI_Comm_split(MPI_COMM_WORLD, rank_ % 2, rank_, &group);
        MPI_Intercomm_create(group, 0, MPI_COMM_WORLD, rank_ % 2 ? 0 : 1, 99, &inter);
        LPI_ASSERT_FAILS(NULL, lpi_sine_euler_create_mpi(&none, 13, inter), LPI_ERR_INVALID,
                         "intercommunicator");
        assert_null(none);
        MPI_Comm_free(&inter), MPI_Comm_free(&group);
    }
    lpi_destroy(spread), lpi_destroy(single);
}

/* One call with the last process's address space limited to what it has
 * mapped (lpi_test_with_address_space_limited). */
static int with_last_process_limited(lpi_test_limited_call call, lpi_system *sys, const void *context) {
    return lpi_test_with_address_space_limited(rank_ == size_ - 1, call, sys, context);
}

typedef struct {
    const double *lambda, *f;
    size_t n;
} hamiltonian_arguments;
static int first_step(lpi_system *sys, const void *context) {
    (void)context;
    return lpi_step(sys, 0.01, 1);
}
static int new_hamiltonian(lpi_system *sys, const void *context) {
    const hamiltonian_arguments *h = context;
    return lpi_sine_euler_set_hamiltonian(sys, h->lambda, h->n, h->f, 2 * h->n);
}
static int new_plans(lpi_system *sys, const void *context) {
    (void)context;
    return lpi_sine_euler_set_planning(sys, "estimate");
}

/* The address-space tests' system: spread over every process at N = 101
 * (what a call maps is then refused under the limit), a random field set,
 * SQG over topography's lambda and f at hand, and two buffers of N^2. */
typedef struct {
    size_t n;
    double *x, *lambda, *f, *a, *b;
    lpi_system *sys;
} limited_case;
static limited_case limited_case_create(unsigned seed) {
    const int N = 101;
    limited_case c = {(size_t)N * N, NULL, NULL, NULL, NULL, NULL, NULL};
    c.x = malloc(c.n * sizeof *c.x), c.lambda = malloc(c.n * sizeof *c.lambda);
    c.f = malloc(2 * c.n * sizeof *c.f), c.a = malloc(c.n * sizeof *c.a), c.b = malloc(c.n * sizeof *c.b);
    assert_true(c.x && c.lambda && c.f && c.a && c.b);
    random_field(c.x, c.n, seed);
    sqg_over_topography(N, c.lambda, c.f);
    assert_int_equal(lpi_sine_euler_create_mpi(&c.sys, N, MPI_COMM_WORLD), LPI_OK);
    assert_int_equal(lpi_set_state(c.sys, c.x, c.n), LPI_OK);
    return c;
}
static void limited_case_free(limited_case *c) {
    lpi_destroy(c->sys);
    free(c->x), free(c->lambda), free(c->f), free(c->a), free(c->b);
}

/* Calls that fail on one process alone, in what they allocate or set up (a
 * step's plans and buffers, a Hamiltonian, plans), refused here by an
 * address-space limit on the last process: every process returns
 * LPI_ERR_NO_MEMORY, nothing changed anywhere. Before, the others waited for
 * ever in the first flow's exchange (a step) or in the next collective, or
 * went on with another Hamiltonian than the last process. */
static void test_failure_on_one_process(void **state) {
    (void)state;
    LPI_SKIP_UNDER_A_SANITIZER();
    limited_case c = limited_case_create(5);
    lpi_system *sys = c.sys;
    const size_t n = c.n;
    double *before = c.a, *after = c.b;
    assert_int_equal(lpi_get_state(sys, before, n), LPI_OK);
    const hamiltonian_arguments sqg = {c.lambda, c.f, n};
    /* In this order: nothing before them has planned or exchanged. */
    const struct {
        const char *name;
        lpi_test_limited_call call;
        const void *context;
    } calls[] = {{"lpi_sine_euler_set_planning", new_plans, NULL},
                 {"lpi_step", first_step, NULL},
                 {"lpi_sine_euler_set_hamiltonian", new_hamiltonian, &sqg}};
    int refused = 0;
    for (int c = 0; c < 3; ++c) {
        double h0, h1;
        if (calls[c].call == new_hamiltonian) assert_int_equal(lpi_energy(sys, &h0), LPI_OK);
        const int status = with_last_process_limited(calls[c].call, sys, calls[c].context);
        if (status == LPI_OK) continue; /* nothing was refused: the limit did not bite */
        ++refused;
        assert_int_equal(status, LPI_ERR_NO_MEMORY);
        assert_non_null(strstr(lpi_last_error(sys), calls[c].name));
        const char *rigor = NULL;
        assert_int_equal(lpi_sine_euler_get_planning(sys, &rigor), LPI_OK);
        assert_string_equal(rigor, "estimate");
        assert_true(lpi_time(sys) == 0.0);
        assert_int_equal(lpi_get_state(sys, after, n), LPI_OK);
        assert_memory_equal(before, after, n * sizeof *after);
        if (calls[c].call == new_hamiltonian) {
            assert_int_equal(lpi_energy(sys, &h1), LPI_OK);
            assert_true(h1 == h0); /* the Hamiltonian as it was */
        }
    }
    assert_int_equal(lpi_step(sys, 0.01, 1), LPI_OK); /* and it goes on */
    limited_case_free(&c);
    if (rank_ == 0) printf("%d of 3 calls refused on the last of %d processes, on all\n", refused, size_);
    if (refused == 0) LPI_SKIP("an address-space limit refused nothing (a sanitizer's reserve?)");
}

/* lpi_load_mpi with the last process's address space limited: every buffer
 * it allocates between its collectives (the file's bytes, the Hamiltonian,
 * the process's share of the state, the handle) is agreed on, so every
 * process returns LPI_ERR_NO_MEMORY. Before, the others waited for ever in
 * the broadcast of the file (or in the next collective after the others). */
typedef struct {
    const char *path;
    lpi_system **out;
} load_arguments;
static int load_spread(lpi_system *sys, const void *context) {
    (void)sys;
    const load_arguments *load = context;
    return lpi_load_mpi(load->out, load->path, MPI_COMM_WORLD);
}
static void test_load_failure_on_one_process(void **state) {
    (void)state;
    LPI_SKIP_UNDER_A_SANITIZER();
    limited_case c = limited_case_create(11);
    lpi_system *sys = c.sys, *loaded = NULL;
    const size_t n = c.n;
    char path[64];
    snprintf(path, sizeof path, "test_sine_euler_mpi_short_%d.lpi", size_);
    assert_int_equal(lpi_sine_euler_set_hamiltonian(sys, c.lambda, n, c.f, 2 * n), LPI_OK);
    assert_int_equal(lpi_save(sys, path), LPI_OK);
    const load_arguments load = {path, &loaded};
    const int status = with_last_process_limited(load_spread, NULL, &load);
    int refused = status != LPI_OK;
    if (refused) {
        assert_int_equal(status, LPI_ERR_NO_MEMORY);
        assert_non_null(strstr(lpi_last_error(NULL), "lpi_load_mpi"));
        assert_null(loaded);
    } else {
        lpi_destroy(loaded);
    }
    /* The same status on every process. */
    int all = 0;
    MPI_Allreduce(&refused, &all, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
    assert_int_equal(all, refused);
    /* And the file loads once the memory is there. */
    assert_int_equal(lpi_load_mpi(&loaded, path, MPI_COMM_WORLD), LPI_OK);
    assert_int_equal(lpi_get_state(sys, c.a, n), LPI_OK);
    assert_int_equal(lpi_get_state(loaded, c.b, n), LPI_OK);
    assert_memory_equal(c.a, c.b, n * sizeof *c.a);
    lpi_destroy(loaded);
    limited_case_free(&c);
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank_ == 0) remove(path);
    if (!refused) LPI_SKIP("an address-space limit refused nothing (a sanitizer's reserve?)");
}

/* Run with --thread-single: MPI at MPI_THREAD_SINGLE, where no other thread
 * may exist, so threads within a process are refused. */
static void test_threads_need_funneled(void **state) {
    (void)state;
    lpi_system *sys;
    assert_int_equal(lpi_sine_euler_create_mpi(&sys, 13, MPI_COMM_WORLD), LPI_OK);
    assert_int_equal(lpi_set_threads(sys, 2), LPI_ERR_UNSUPPORTED);
    const char *why = lpi_last_error(sys);
    if (!strstr(why, "OpenMP")) assert_non_null(strstr(why, "MPI_THREAD_FUNNELED"));
    assert_int_equal(lpi_set_threads(sys, 1), LPI_OK);
    lpi_destroy(sys);
}

int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "--thread-single") == 0) {
        MPI_Init(NULL, NULL);
        const struct CMUnitTest single[] = {cmocka_unit_test(test_threads_need_funneled)};
        const int status = lpi_run_tests(single);
        MPI_Finalize();
        return status;
    }
    int provided;
    MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_one_process),
        cmocka_unit_test(test_threads_per_process),
        cmocka_unit_test(test_checkpoint),
        cmocka_unit_test(test_hamiltonian),
        cmocka_unit_test(test_memory_per_process),
        cmocka_unit_test(test_too_large_n),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_different_arguments),
        cmocka_unit_test(test_failure_on_one_process),
        cmocka_unit_test(test_load_failure_on_one_process),
    };
    const int status = lpi_run_tests(tests);
    MPI_Finalize();
    return status;
}
