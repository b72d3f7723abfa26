/* Checkpoints: a loaded system continues the trajectory to the bit (every
 * saveable kind, every registered method, custom compositions, implicit
 * settings, the compensated carry); every truncation, every flipped byte, a
 * foreign, other-byte-order, newer-version or inconsistent checkpoint is
 * refused, and so is every payload no setter would accept (checkpoints
 * crafted here by an encoder of the documented layout, written
 * independently); files are read bounded, written atomically under any
 * legal name, and leave no temporary files. */
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lpi_test.h"

/* The mode of the file each write(2) of the library goes to, while armed:
 * what a reader could open while a save writes (write is interposed). */
static int record_write_modes;
static mode_t widest_write_mode;

ssize_t write(int fd, const void *bytes, size_t size) {
    static ssize_t (*real_write)(int, const void *, size_t);
    if (!real_write) real_write = (ssize_t(*)(int, const void *, size_t))dlsym(RTLD_NEXT, "write");
    struct stat st;
    if (record_write_modes && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) widest_write_mode |= st.st_mode & 07777;
    return real_write(fd, bytes, size);
}

/* ---- an independent CRC-32 (bit by bit) and the documented layout -------- */

static uint32_t crc32_bitwise(const unsigned char *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

static void reseal(unsigned char *buf, size_t size) {
    const uint32_t c = crc32_bitwise(buf, size - 4);
    memcpy(buf + size - 4, &c, 4);
}

/* A checkpoint written from the documented layout, field by field. */
typedef struct {
    const char *kind;
    size_t n_params;
    const double *params;
    const char *split, *method;
    size_t n_gammas;
    const double *gammas;
    double tolerance;
    int32_t iterations;
    double time;
    uint64_t n_state;     /* the stored count */
    size_t state_values;  /* the values that follow it */
    const double *state;
    uint32_t version;  /* 0: the current one, 2 (1: no time carry) */
    double time_carry;
} crafted;

typedef struct {
    unsigned char *p;
    size_t n;
} sink;

static void put(sink *b, const void *v, size_t n) {
    if (n == 0) return; /* memcpy from a NULL source is undefined even for 0 bytes */
    b->p = realloc(b->p, b->n + n);
    assert_non_null(b->p);
    memcpy(b->p + b->n, v, n);
    b->n += n;
}
static void put_u32(sink *b, uint32_t v) { put(b, &v, 4); }
static void put_string(sink *b, const char *s, size_t n) {
    put_u32(b, (uint32_t)n);
    put(b, s, n);
}

static unsigned char *craft(const crafted *c, size_t *size) {
    sink b = {NULL, 0};
    const unsigned char magic[8] = {0x89, 'L', 'P', 'I', 0x0D, 0x0A, 0x1A, 0x0A};
    put(&b, magic, 8);
    put_u32(&b, 0x01020304u);
    const uint32_t version = c->version ? c->version : 2;
    put_u32(&b, version);
    const uint64_t total_placeholder = 0;
    put(&b, &total_placeholder, 8);
    put_string(&b, c->kind, strlen(c->kind));
    put_u32(&b, (uint32_t)c->n_params);
    put(&b, c->params, 8 * c->n_params);
    put_string(&b, c->split, strlen(c->split));
    put_string(&b, c->method, strlen(c->method));
    put_u32(&b, (uint32_t)c->n_gammas);
    put(&b, c->gammas, 8 * c->n_gammas);
    put(&b, &c->tolerance, 8);
    put(&b, &c->iterations, 4);
    put(&b, &c->time, 8);
    if (version >= 2) put(&b, &c->time_carry, 8);
    put(&b, &c->n_state, 8);
    put(&b, c->state, 8 * c->state_values);
    put_u32(&b, 0); /* the checksum, sealed below */
    const uint64_t total = b.n;
    memcpy(b.p + 16, &total, 8);
    reseal(b.p, b.n);
    *size = b.n;
    return b.p;
}

/* A rigid body (1, 2, 3.5), leapfrog, default implicit settings, at t = 0.25,
 * m = (0.3, 1.1, -0.7) with a carry of a quarter ulp on m_1. */
static const double kInertia[3] = {1.0, 2.0, 3.5};
static double rigid_state[6];
static crafted rigid_crafted(void) {
    const double m[6] = {0.3, 1.1, -0.7, 0.0, 0x1p-54, 0.0};
    memcpy(rigid_state, m, sizeof m);
    const crafted c = {"rigid-body", 3, kInertia, "casimir-shift", "leapfrog", 0, NULL,
                       1e-13, 100, 0.25, 6, 6, rigid_state, 0, 0.0};
    return c;
}

static void assert_crafted_refused(const crafted *c, int status, const char *needle) {
    size_t size;
    unsigned char *buf = craft(c, &size);
    lpi_system *sys = (lpi_system *)0x1;
    LPI_ASSERT_FAILS(NULL, lpi_load_buffer(&sys, buf, size), status, "lpi_load_buffer");
    assert_null(sys);
    if (needle && !strstr(lpi_last_error(NULL), needle))
        fail_msg("message '%s' does not say '%s'", lpi_last_error(NULL), needle);
    free(buf);
}

static unsigned char *save(const lpi_system *sys, size_t *size) {
    assert_int_equal(lpi_save_buffer(sys, NULL, 0, size), LPI_OK);
    unsigned char *buf = malloc(*size);
    assert_non_null(buf);
    size_t written = 0;
    assert_int_equal(lpi_save_buffer(sys, buf, *size, &written), LPI_OK);
    assert_int_equal(written, *size);
    return buf;
}

static lpi_system *load(const unsigned char *buf, size_t size) {
    lpi_system *sys = NULL;
    const int status = lpi_load_buffer(&sys, buf, size);
    if (status != LPI_OK) fail_msg("lpi_load_buffer: %s", lpi_last_error(NULL));
    return sys;
}

static void assert_refused(const unsigned char *buf, size_t size, const char *needle) {
    lpi_system *sys = (lpi_system *)0x1;
    LPI_ASSERT_FAILS(NULL, lpi_load_buffer(&sys, buf, size), LPI_ERR_FORMAT, "lpi_load_buffer");
    assert_null(sys);
    if (needle && !strstr(lpi_last_error(NULL), needle))
        fail_msg("message '%s' does not say '%s'", lpi_last_error(NULL), needle);
}

/* ---- systems ------------------------------------------------------------- */

static lpi_system *rigid_body(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.5), LPI_OK);
    const double m[3] = {0.3, 1.1, -0.7};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    return sys;
}

static lpi_system *pendulum(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_pendulum_create(&sys), LPI_OK);
    const double x[3] = {0.6, -0.8, 1.3};
    assert_int_equal(lpi_set_state(sys, x, 3), LPI_OK);
    return sys;
}

static lpi_system *sine_euler(int N) {
    lpi_system *sys = NULL;
    const int status = lpi_sine_euler_create(&sys, N);
    if (status == LPI_ERR_UNSUPPORTED) return NULL; /* built without FFTW */
    assert_int_equal(status, LPI_OK);
    double grid[15 * 15];
    uint64_t s = 0x2545F4914F6CDD1Dull + (uint64_t)N;
    for (int i = 0; i < N * N; ++i) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        grid[i] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
    }
    assert_int_equal(lpi_sine_euler_set_grid(sys, grid, (size_t)N * N), LPI_OK);
    return sys;
}

/* Steps `warm` steps (the carry becomes nonzero), saves, steps `n` more; a
 * system loaded from the checkpoint then steps `n` as well: the two must end
 * with identical checkpoints (state with carry, time, method, everything). */
static void assert_resumes(lpi_system *sys, double dt, int64_t warm, int64_t n) {
    assert_int_equal(lpi_step(sys, dt, warm), LPI_OK);
    size_t size;
    unsigned char *saved = save(sys, &size);
    lpi_system *copy = load(saved, size);
    assert_int_equal(lpi_step(sys, dt, n), LPI_OK);
    assert_int_equal(lpi_step(copy, dt, n), LPI_OK);
    size_t size_a, size_b;
    unsigned char *a = save(sys, &size_a), *b = save(copy, &size_b);
    assert_int_equal(size_a, size_b);
    assert_memory_equal(a, b, size_a);
    assert_memory_not_equal(a, saved, size_a); /* the run did move */
    lpi_snapshot sa, sb;
    lpi_take_snapshot(sys, &sa);
    lpi_take_snapshot(copy, &sb);
    assert_memory_equal(sa.x, sb.x, sa.n * sizeof(double));
    assert_memory_equal(&sa.time, &sb.time, sizeof(double));
    free(saved), free(a), free(b);
    lpi_destroy(copy);
}

static void test_crc_reference(void **state) {
    (void)state;
    assert_int_equal(crc32_bitwise((const unsigned char *)"123456789", 9), 0xCBF43926u);
    lpi_system *sys = pendulum();
    size_t size;
    unsigned char *buf = save(sys, &size);
    uint32_t stored;
    memcpy(&stored, buf + size - 4, 4);
    assert_int_equal(stored, crc32_bitwise(buf, size - 4));
    const unsigned char magic[8] = {0x89, 'L', 'P', 'I', 0x0D, 0x0A, 0x1A, 0x0A};
    assert_memory_equal(buf, magic, 8);
    uint64_t total;
    memcpy(&total, buf + 16, 8);
    assert_int_equal(total, size);
    free(buf);
    lpi_destroy(sys);
}

static void test_resume_rigid_body(void **state) {
    (void)state;
    const char *splits[] = {"casimir-shift", "axes"};
    for (int s = 0; s < 2; ++s) {
        lpi_system *sys = rigid_body();
        assert_int_equal(lpi_set_split(sys, splits[s]), LPI_OK);
        assert_int_equal(lpi_set_method(sys, "yoshida-6"), LPI_OK);
        assert_resumes(sys, 0.01, 1000, 1000);
        lpi_destroy(sys);
    }
}

static void test_resume_pendulum(void **state) {
    (void)state;
    lpi_system *sys = pendulum();
    assert_int_equal(lpi_set_method(sys, "leapfrog"), LPI_OK);
    assert_resumes(sys, 0.05, 5000, 5000);
    lpi_destroy(sys);
}

/* The compensated carry is part of the checkpoint: the public state alone
 * (what lpi_get_state gives) would not continue the same trajectory. */
static void test_carry_is_needed(void **state) {
    (void)state;
    lpi_system *sys = pendulum();
    assert_int_equal(lpi_step(sys, 0.05, 5000), LPI_OK);
    size_t size;
    unsigned char *saved = save(sys, &size);
    lpi_system *copy = load(saved, size), *naive = pendulum();
    double x[3];
    assert_int_equal(lpi_get_state(sys, x, 3), LPI_OK);
    assert_int_equal(lpi_set_state(naive, x, 3), LPI_OK);
    double a[3], b[3], c[3];
    assert_int_equal(lpi_step(sys, 0.05, 20000), LPI_OK);
    assert_int_equal(lpi_step(copy, 0.05, 20000), LPI_OK);
    assert_int_equal(lpi_step(naive, 0.05, 20000), LPI_OK);
    assert_int_equal(lpi_get_state(sys, a, 3), LPI_OK);
    assert_int_equal(lpi_get_state(copy, b, 3), LPI_OK);
    assert_int_equal(lpi_get_state(naive, c, 3), LPI_OK);
    assert_memory_equal(a, b, sizeof a);
    assert_memory_not_equal(a, c, sizeof a);
    free(saved);
    lpi_destroy(sys), lpi_destroy(copy), lpi_destroy(naive);
}

static void test_resume_sine_euler(void **state) {
    (void)state;
    const int Ns[] = {9, 15};
    for (int i = 0; i < 2; ++i) {
        lpi_system *sys = sine_euler(Ns[i]);
        if (!sys) LPI_SKIP("built without FFTW: no sine-Euler system");
        /* Threads are not stored; results do not depend on them. */
        const int threads = lpi_set_threads(sys, 2);
        assert_true(threads == LPI_OK || threads == LPI_ERR_UNSUPPORTED);
        assert_int_equal(lpi_set_method(sys, "kahan-li-6"), LPI_OK);
        assert_resumes(sys, 0.02, 10, 10);
        int32_t N = 0;
        size_t size;
        unsigned char *buf = save(sys, &size);
        lpi_system *copy = load(buf, size);
        assert_int_equal(lpi_sine_euler_size(copy, &N), LPI_OK);
        assert_int_equal(N, Ns[i]);
        free(buf);
        lpi_destroy(copy);
        lpi_destroy(sys);
    }
}

/* Every registered method a rigid body takes (the matrix-form baselines, for
 * sine-Euler only, are the next test), a recursive one, a custom composition
 * and the implicit baseline with non-default settings. */
static void test_resume_every_method(void **state) {
    (void)state;
    for (int i = 0; i < lpi_method_count(); ++i) {
        lpi_system *sys = rigid_body();
        const int status = lpi_set_method(sys, lpi_method_name(i));
        if (status != LPI_ERR_UNSUPPORTED) {
            assert_int_equal(status, LPI_OK);
            assert_resumes(sys, 0.01, 37, 50);
        }
        lpi_destroy(sys);
    }
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_set_method(sys, "triple-jump-8"), LPI_OK);
    assert_resumes(sys, 0.01, 37, 50);
    const double g = 1.0 / (2.0 - cbrt(2.0));
    const double gammas[3] = {g, 1.0 - 2.0 * g, g};
    assert_int_equal(lpi_set_composition(sys, 3, gammas), LPI_OK);
    assert_resumes(sys, 0.01, 37, 50);
    assert_int_equal(lpi_set_method(sys, "implicit-midpoint"), LPI_OK);
    assert_int_equal(lpi_set_implicit_options(sys, 1e-6, 3), LPI_OK);
    assert_resumes(sys, 0.01, 37, 50);
    /* The loose settings travel: a fresh system with default settings ends
     * elsewhere. */
    size_t size;
    unsigned char *buf = save(sys, &size);
    lpi_system *copy = load(buf, size);
    assert_int_equal(lpi_set_implicit_options(copy, 1e-13, 100), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 50), LPI_OK);
    assert_int_equal(lpi_step(copy, 0.01, 50), LPI_OK);
    double a[3], b[3];
    assert_int_equal(lpi_get_state(sys, a, 3), LPI_OK);
    assert_int_equal(lpi_get_state(copy, b, 3), LPI_OK);
    assert_memory_not_equal(a, b, sizeof a);
    free(buf);
    lpi_destroy(copy);
    lpi_destroy(sys);
}

/* A composition lpi_set_composition accepts makes a checkpoint that loads.
 * Mirrored pairs run as their mean, which moves the weights' sum by half an
 * ulp of a pair's: the sum test must be the one on the means, which is what
 * the checkpoint stores and its load tests again. */
static void test_composition_near_sum_tolerance(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    /* Exactly 1 as given; the means of the outer pair round to 2^19, so the
     * weights that would run sum to 1 - 2^-33, beyond 1e-10. */
    const double wide[3] = {524288.0, 1.0 - 1048576.0 - 0x1p-33, 524288.0 + 0x1p-33};
    LPI_ASSERT_FAILS(sys, lpi_set_composition(sys, 3, wide), LPI_ERR_INVALID,
                     "lpi_set_composition");
    if (!strstr(lpi_last_error(sys), "mean"))
        fail_msg("message '%s' does not say the means are tested", lpi_last_error(sys));
    /* Weights near the relative tolerance (from a random search that found
     * ones whose checkpoint did not load), and more of them at random: every
     * accepted composition saves and loads with its weights. */
    const double found[5] = {0.85997794259338556, -0.75558083539622878, 0.79120578560572918,
                             -0.75558083539622367, 0.8599779425933779};
    uint64_t bits = 0x9E3779B97F4A7C15u;
    int accepted = 0, refused = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        double g[5];
        if (trial == 0) {
            memcpy(g, found, sizeof g);
        } else {
            double u[4];
            for (int k = 0; k < 4; ++k) {
                bits ^= bits << 13, bits ^= bits >> 7, bits ^= bits << 17;
                u[k] = (double)(bits >> 11) * 0x1p-53;
            }
            /* Pairs a few ulps apart, the sum off by up to 1.1 times the
             * tolerance. */
            g[0] = 2.0 * u[0] - 0.5, g[1] = -2.0 * u[1];
            g[3] = g[1] * (1.0 + (u[2] - 0.5) * 1e-15);
            g[4] = g[0] * (1.0 + (u[3] - 0.5) * 1e-15);
            g[2] = 1.0 - g[0] - g[1] - g[3] - g[4];
            const double magnitude = 2.0 * fabs(g[0]) + 2.0 * fabs(g[1]) + fabs(g[2]);
            bits ^= bits << 13, bits ^= bits >> 7, bits ^= bits << 17;
            g[2] += ((double)(bits >> 11) * 0x1p-53 - 0.5) * 2.2e-14 * magnitude;
        }
        if (lpi_set_composition(sys, 5, g) != LPI_OK) {
            ++refused;
            continue;
        }
        ++accepted;
        size_t size;
        unsigned char *buf = save(sys, &size);
        lpi_system *copy = load(buf, size);
        assert_string_equal(lpi_get_method(copy), "custom");
        size_t again_size;
        unsigned char *again = save(copy, &again_size);
        assert_int_equal(again_size, size);
        assert_memory_equal(again, buf, size);
        free(again), free(buf);
        lpi_destroy(copy);
    }
    print_message("%d compositions accepted, %d refused\n", accepted, refused);
    /* Both outcomes occur, or the weights did not probe the edge. */
    assert_true(accepted > 100 && refused > 100);
    lpi_destroy(sys);
}

/* The methods a rigid body refuses: the matrix-form baselines, which apply to
 * sine-Euler only; those that need BLAS say so in a build without it. */
static void test_resume_matrix_baselines(void **state) {
    (void)state;
    if (!lpi_test_have_sine_euler()) LPI_SKIP("built without FFTW: no sine-Euler system");
    int resumed = 0;
    for (int i = 0; i < lpi_method_count(); ++i) {
        lpi_system *body = rigid_body();
        const int sine_euler_only = lpi_set_method(body, lpi_method_name(i)) == LPI_ERR_UNSUPPORTED;
        lpi_destroy(body);
        if (!sine_euler_only) continue;
        lpi_system *sys = sine_euler(9);
        const int status = lpi_set_method(sys, lpi_method_name(i));
        if (status == LPI_ERR_UNSUPPORTED) {
            printf("%s not resumed: %s\n", lpi_method_name(i), lpi_last_error(sys));
        } else {
            assert_int_equal(status, LPI_OK);
            assert_resumes(sys, 0.01, 37, 50);
            ++resumed;
        }
        lpi_destroy(sys);
    }
    if (!resumed) LPI_SKIP("no matrix-form baseline in this build");
}

static void test_truncated_and_flipped(void **state) {
    (void)state;
    lpi_system *sys = pendulum();
    assert_int_equal(lpi_step(sys, 0.1, 10), LPI_OK);
    size_t size;
    unsigned char *buf = save(sys, &size);
    unsigned char *copy = malloc(size + 1);
    for (size_t k = 0; k < size; ++k) { /* every truncation */
        memcpy(copy, buf, k);
        assert_refused(copy, k, "truncated");
    }
    memcpy(copy, buf, size);
    copy[size] = 0;
    assert_refused(copy, size + 1, "unexpected bytes");
    const unsigned char flips[] = {0x01, 0x80, 0xFF};
    for (size_t k = 0; k < size; ++k) /* every byte, three ways */
        for (int f = 0; f < 3; ++f) {
            memcpy(copy, buf, size);
            copy[k] ^= flips[f];
            assert_refused(copy, size, NULL);
        }
    /* A flip in the payload is caught by the checksum. */
    memcpy(copy, buf, size);
    copy[size - 10] ^= 0x40;
    assert_refused(copy, size, "checksum");
    printf("checkpoint of %zu bytes: %zu truncations and %zu corruptions refused\n", size, size,
           3 * size);
    free(copy), free(buf);
    lpi_destroy(sys);
}

static void test_foreign_newer_other_order(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    size_t size;
    unsigned char *buf = save(sys, &size);
    unsigned char *copy = malloc(size);

    memcpy(copy, "Not a checkpoint file, just text....", 28);
    assert_refused(copy, 28, "magic");

    memcpy(copy, buf, size);
    const uint32_t future = 3;
    memcpy(copy + 12, &future, 4);
    reseal(copy, size);
    assert_refused(copy, size, "newer");

    memcpy(copy, buf, size);
    const unsigned char swapped[4] = {copy[11], copy[10], copy[9], copy[8]};
    memcpy(copy + 8, swapped, 4);
    reseal(copy, size);
    assert_refused(copy, size, "byte order");

    /* Consistent checksum, inconsistent contents. Payload: kind string at 24
     * ("rigid-body": u32 10 + 10 bytes), parameter count at 38, I1 at 42. */
    memcpy(copy, buf, size);
    assert_memory_equal(copy + 28, "rigid-body", 10);
    copy[28 + 9] = 'x';
    reseal(copy, size);
    assert_refused(copy, size, "unknown system kind");

    memcpy(copy, buf, size);
    const double negative = -1.0;
    memcpy(copy + 42, &negative, 8);
    reseal(copy, size);
    assert_refused(copy, size, "invalid rigid-body parameters");

    memcpy(copy, buf, size);
    const uint32_t params = 2;
    memcpy(copy + 38, &params, 4);
    reseal(copy, size);
    assert_refused(copy, size, NULL);
    free(copy), free(buf);
    lpi_destroy(sys);

    /* A crafted N far beyond the stored state is refused before anything of
     * that size is allocated. */
    sys = sine_euler(9);
    if (!sys) return;
    buf = save(sys, &size);
    copy = malloc(size);
    memcpy(copy, buf, size);
    assert_memory_equal(copy + 28, "sine-euler", 10);
    const double huge = 46339;
    memcpy(copy + 42, &huge, 8);
    reseal(copy, size);
    assert_refused(copy, size, "the state has 162 values");
    free(copy), free(buf);
    lpi_destroy(sys);
}

/* The crafted encoder writes what lpi_save_buffer writes; a crafted
 * checkpoint with a carry and a time loads with both, and re-saves to the
 * same bytes. */
static void test_layout_and_round_trip(void **state) {
    (void)state;
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_set_method(sys, "leapfrog"), LPI_OK);
    size_t size, crafted_size;
    unsigned char *real = save(sys, &size);
    crafted c = rigid_crafted();
    const double gammas[1] = {1.0};
    c.n_gammas = 1, c.gammas = gammas, c.time = 0.0, rigid_state[4] = 0.0;
    unsigned char *mine = craft(&c, &crafted_size);
    assert_int_equal(crafted_size, size);
    assert_memory_equal(mine, real, size);
    free(mine), free(real);

    c = rigid_crafted();
    c.n_gammas = 1, c.gammas = gammas;
    mine = craft(&c, &crafted_size);
    lpi_system *copy = load(mine, crafted_size);
    assert_true(lpi_time(copy) == 0.25);
    double m[3];
    assert_int_equal(lpi_get_state(copy, m, 3), LPI_OK);
    assert_true(m[0] == 0.3 && m[1] == 1.1 + 0x1p-54 && m[2] == -0.7);
    real = save(copy, &size);
    assert_int_equal(size, crafted_size);
    assert_memory_equal(real, mine, size);
    free(mine), free(real);
    lpi_destroy(copy);
    lpi_destroy(sys);
}

/* The time is kept with its carry (format version 2): a copy made after
 * many one-step calls continues with the original's times to the bit. A
 * version 1 checkpoint (no carry) loads with none, and a carry that is not
 * below half a unit of the time's last place is refused. */
static void test_time_carry(void **state) {
    (void)state;
    lpi_system *sys = pendulum();
    for (int i = 0; i < 1000; ++i) assert_int_equal(lpi_step(sys, 0.1, 1), LPI_OK);
    size_t size;
    unsigned char *buf = save(sys, &size);
    lpi_system *copy = load(buf, size);
    for (int i = 0; i < 1000; ++i) {
        assert_int_equal(lpi_step(sys, 0.1, 1), LPI_OK);
        assert_int_equal(lpi_step(copy, 0.1, 1), LPI_OK);
        assert_true(lpi_time(copy) == lpi_time(sys));
    }
    assert_true(lpi_time(sys) == 200.0);
    free(buf);
    lpi_destroy(copy);
    lpi_destroy(sys);

    crafted c = rigid_crafted();
    const double gammas[1] = {1.0};
    c.n_gammas = 1, c.gammas = gammas, c.version = 1;
    unsigned char *mine = craft(&c, &size);
    copy = load(mine, size);
    assert_true(lpi_time(copy) == 0.25);
    unsigned char *again = save(copy, &size);
    c.version = 2, c.time_carry = 0.0;
    free(mine);
    size_t crafted_size;
    mine = craft(&c, &crafted_size);
    assert_int_equal(size, crafted_size);
    assert_memory_equal(again, mine, size); /* re-saved as version 2, carry 0 */
    free(mine), free(again);
    lpi_destroy(copy);

    c.time_carry = 0x1p-56; /* a quarter unit of 0.25 in its last place: kept */
    mine = craft(&c, &size);
    copy = load(mine, size);
    again = save(copy, &crafted_size);
    assert_memory_equal(again, mine, size);
    free(mine), free(again);
    lpi_destroy(copy);
    const double refused[] = {0x1p-54, -0x1p-53, 1e-3, NAN, INFINITY};
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; ++i) {
        c.time_carry = refused[i];
        assert_crafted_refused(&c, LPI_ERR_FORMAT, "carry");
    }
}

/* Everything a setter refuses, a checkpoint may not carry either: the
 * checksum only says the bytes are those that were written. */
static void test_impossible_payloads(void **state) {
    (void)state;
    const double gammas[1] = {1.0};
    crafted c = rigid_crafted();
    c.n_gammas = 1, c.gammas = gammas;
    size_t size;
    unsigned char *fine = craft(&c, &size);
    lpi_destroy(load(fine, size)); /* the unaltered base of every case */
    free(fine);

    /* Compensation carries: a remainder of rounding, not a second value. */
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
    rigid_state[3] = 1e-3;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "carry");
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
    rigid_state[0] = 0.0, rigid_state[1] = 0.0, rigid_state[2] = 0.0, rigid_state[4] = 0x1p-1074;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "carry");
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
    rigid_state[0] = 1.5e308, rigid_state[3] = 1.5e308;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "overflows");
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
    rigid_state[5] = NAN;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "not finite");

    /* Implicit settings, as lpi_set_implicit_options checks them. */
    const double tolerances[] = {0.0, -1e-10, NAN, INFINITY};
    for (int i = 0; i < 4; ++i) {
        c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
        c.tolerance = tolerances[i];
        assert_crafted_refused(&c, LPI_ERR_FORMAT, "tolerance");
    }
    const int32_t iterations[] = {0, -5, INT32_MIN};
    for (int i = 0; i < 3; ++i) {
        c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
        c.iterations = iterations[i];
        assert_crafted_refused(&c, LPI_ERR_FORMAT, "max_iterations");
    }
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
    c.time = INFINITY;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "time");

    /* Methods: the registry's name with the registry's weights, or a custom
     * composition that passes lpi_set_composition. */
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas, c.method = "strang";
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "alias");
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas, c.method = "no-such-method";
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "unknown method");
    c = rigid_crafted(), c.n_gammas = 0, c.gammas = NULL;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "other weights");
    /* A method no system of this kind can run: no save writes it, so the
     * file is bad (FORMAT), not one for another build (UNSUPPORTED). */
    c = rigid_crafted(), c.n_gammas = 0, c.gammas = NULL, c.method = "isomp";
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "sine-Euler systems only");
    c = rigid_crafted(), c.n_gammas = 0, c.gammas = NULL, c.method = "direct-eq5";
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "sine-Euler systems only");
    const double lopsided[3] = {0.5, 0.25, 0.25};
    c = rigid_crafted(), c.method = "custom", c.n_gammas = 3, c.gammas = lopsided;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "symmetric");

    /* Names: printable ASCII, no NUL inside, bounded lengths. */
    static const char kind_with_nul[] = "rigid-body\0x";
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas, c.split = "casimir\tshift";
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "printable");
    {
        /* "rigid-body\0x": the name is compared whole, NUL and all. */
        size_t n;
        c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
        unsigned char *buf = craft(&c, &n);
        unsigned char *longer = malloc(n + 2);
        memcpy(longer, buf, 24);
        const uint32_t len = 12;
        memcpy(longer + 24, &len, 4);
        memcpy(longer + 28, kind_with_nul, 12);
        memcpy(longer + 40, buf + 38, n - 38);
        const uint64_t total = n + 2;
        memcpy(longer + 16, &total, 8);
        reseal(longer, n + 2);
        assert_refused(longer, n + 2, "printable");
        free(buf), free(longer);
    }
    char *absurd = calloc(1, 258);
    memset(absurd, 'a', 257);
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas, c.method = absurd;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "at most 256");
    free(absurd);

    /* Counts whose byte size overflows 64 bits, or far beyond the payload. */
    c = rigid_crafted(), c.n_gammas = 1, c.gammas = gammas;
    c.n_state = UINT64_C(1) << 61; /* times 8 is 2^64 = 0 */
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "state");
    c.n_state = UINT64_MAX;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "state");
    {
        /* A parameter count of 2^29 (times 8 is 2^32), three inertias after it. */
        size_t n;
        crafted honest = rigid_crafted();
        honest.n_gammas = 1, honest.gammas = gammas;
        unsigned char *buf = craft(&honest, &n);
        const uint32_t huge = 0x20000000u;
        memcpy(buf + 38, &huge, 4);
        reseal(buf, n);
        assert_refused(buf, n, "parameters");
        free(buf);
    }
}

/* Sine-Euler: the working state must pass lpi_sine_euler_set_modes
 * (Hermitian, w_0 real); a kind this build cannot make is UNSUPPORTED. */
static void test_sine_euler_payloads(void **state) {
    (void)state;
    /* N = 3, from public coordinates: w_0 = 0.5, w_(0,1) = 0.25 - 0.5 i,
     * w_(1,-1) = 1, w_(1,0) = -0.75 i, w_(1,1) = 0.125; the rest their
     * conjugates. Layout [a*N+b] = (re, im). */
    double modes[18] = {0};
    const struct {
        int a, b;
        double re, im;
    } half[] = {{0, 1, 0.25, -0.5}, {1, 2, 1.0, 0.0}, {1, 0, 0.0, -0.75}, {1, 1, 0.125, 0.0}};
    modes[0] = 0.5;
    for (int i = 0; i < 4; ++i) {
        const int m = half[i].a * 3 + half[i].b;
        const int minus = ((3 - half[i].a) % 3) * 3 + (3 - half[i].b) % 3;
        modes[2 * m] = half[i].re, modes[2 * m + 1] = half[i].im;
        modes[2 * minus] = half[i].re, modes[2 * minus + 1] = -half[i].im;
    }
    const double N = 3.0, gammas[1] = {1.0};
    crafted c = {"sine-euler", 1, &N, "directions", "leapfrog", 1, gammas, 1e-13, 100, 0.0,
                 18, 18, modes, 0, 0.0};
    size_t size;
    unsigned char *buf = craft(&c, &size);
    lpi_system *probe = NULL;
    const int available = lpi_sine_euler_create(&probe, 3);
    if (available == LPI_ERR_UNSUPPORTED) {
        /* The file is intact: this build lacks what the kind needs. */
        lpi_system *sys = (lpi_system *)0x1;
        LPI_ASSERT_FAILS(NULL, lpi_load_buffer(&sys, buf, size), LPI_ERR_UNSUPPORTED,
                         "lpi_load_buffer");
        assert_non_null(strstr(lpi_last_error(NULL), "FFTW"));
        assert_null(sys);
        free(buf);
        return;
    }
    assert_int_equal(available, LPI_OK);
    lpi_destroy(probe);
    lpi_system *sys = load(buf, size);
    double back[18];
    assert_int_equal(lpi_sine_euler_get_modes(sys, back, 18), LPI_OK);
    assert_memory_equal(back, modes, sizeof modes);
    size_t again_size;
    unsigned char *again = save(sys, &again_size);
    assert_int_equal(again_size, size);
    assert_memory_equal(again, buf, size);
    free(again), free(buf);
    lpi_destroy(sys);

    modes[2 * 1 + 1] += 1e-3; /* w_(0,1) no longer the conjugate of w_(0,2) */
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "Hermitian");
    modes[2 * 1 + 1] -= 1e-3;
    modes[1] = 0.25; /* w_0 not real */
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "real");
    modes[1] = 0.0;
    const double even = 4.0, fractional = 3.5;
    c.params = &even;
    c.n_state = c.state_values = 32;
    double zeros[32] = {0};
    c.state = zeros;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "invalid sine-euler parameters");
    c.params = &fractional;
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "not an integer");

    /* N, lambda (N^2) and f (2 N^2): twice Euler's weights, f = 0, load and
     * save back to the same bytes; parameters the library would store in
     * another form are refused, so that every accepted checkpoint does. */
    double params[1 + 9 + 18] = {3.0};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            const int ra = a > 1 ? a - 3 : a, rb = b > 1 ? b - 3 : b;
            params[1 + 3 * a + b] = a == 0 && b == 0 ? 0.0 : 2.0 / (ra * ra + rb * rb);
        }
    c.params = params;
    c.n_params = 28;
    c.n_state = c.state_values = 18;
    c.state = modes;
    buf = craft(&c, &size);
    sys = load(buf, size);
    again = save(sys, &again_size);
    assert_int_equal(again_size, size);
    assert_memory_equal(again, buf, size);
    free(again), free(buf);
    lpi_destroy(sys);
    params[1] = 5.0; /* lambda_0, which the library stores as 0 */
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "parameter 1 is not in the form");
    params[1] = 0.0;
    params[1 + 1] *= 1.0 + 1e-13; /* lambda_(0,1) != lambda_(0,2): stored as their mean */
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "parameter 2 is not in the form");
    params[1 + 1] = 2.0;
    for (int k = 1; k < 10; ++k) params[k] *= 0.5; /* Euler's own: stored as N alone */
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "not in the form this library writes");

    /* direct-eq5 refuses N > 31: a checkpoint with it at N = 33 is bad. */
    const double large = 33.0;
    static double still[2 * 33 * 33];
    c = (crafted){"sine-euler", 1, &large, "directions", "direct-eq5", 0, NULL, 1e-13, 100, 0.0,
                  2 * 33 * 33, 2 * 33 * 33, still, 0, 0.0};
    assert_crafted_refused(&c, LPI_ERR_FORMAT, "accepts N <= 31");
    c.method = "leapfrog", c.n_gammas = 1, c.gammas = gammas;
    buf = craft(&c, &size);
    lpi_destroy(load(buf, size)); /* the same file with leapfrog loads */
    free(buf);
}

/* A legitimate run is never refused: the carry frozen by a non-splitting
 * baseline after a splitting run loads and continues to the bit. */
static void test_baselines_after_splitting(void **state) {
    (void)state;
    const char *baselines[] = {"rk4", "implicit-midpoint"};
    for (int b = 0; b < 2; ++b) {
        lpi_system *sys = pendulum();
        assert_int_equal(lpi_step(sys, 0.05, 2000), LPI_OK);
        assert_int_equal(lpi_set_method(sys, baselines[b]), LPI_OK);
        assert_resumes(sys, 0.05, 2000, 100);
        lpi_destroy(sys);
    }
}

/* Sine-Euler modes after rk4, which does not keep them Hermitian to the bit,
 * load and continue to the bit. */
static void test_sine_euler_after_rk4(void **state) {
    (void)state;
    lpi_system *sys = sine_euler(9);
    if (!sys) LPI_SKIP("built without FFTW: no sine-Euler system");
    assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK);
    assert_resumes(sys, 0.02, 100, 20);
    lpi_destroy(sys);
}

/* Generic and moment systems carry user callbacks: refused, saying why. */
static int grad_x0(size_t n, const double *x, double *g, void *u) {
    (void)n, (void)x, (void)u;
    g[0] = 1.0;
    return 0;
}
static int energy_x0(size_t n, const double *x, double *h, void *u) {
    (void)n, (void)u;
    *h = x[0];
    return 0;
}

static void test_callbacks_refused(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    const int32_t i[] = {0}, j[] = {1}, k[] = {2};
    const double c[] = {1.0};
    assert_int_equal(lpi_generic_create(&sys, 3, 1, i, j, k, c), LPI_OK);
    const int32_t sigma[] = {0};
    assert_int_equal(lpi_add_piece(sys, 1, sigma, grad_x0, energy_x0, NULL), LPI_OK);
    size_t size = 7;
    LPI_ASSERT_FAILS(sys, lpi_save_buffer(sys, NULL, 0, &size), LPI_ERR_UNSUPPORTED, "lpi_save_buffer");
    assert_non_null(strstr(lpi_last_error(sys), "callbacks"));
    LPI_ASSERT_FAILS(sys, lpi_save(sys, "never-written.lpi"), LPI_ERR_UNSUPPORTED, "lpi_save");
    assert_int_equal(access("never-written.lpi", F_OK), -1);
    lpi_destroy(sys);
    assert_int_equal(lpi_moments_create(&sys), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_save_buffer(sys, NULL, 0, &size), LPI_ERR_UNSUPPORTED, "lpi_save_buffer");
    assert_non_null(strstr(lpi_last_error(sys), "moments"));
    lpi_destroy(sys);
}

/* ---- files ------------------------------------------------------------------ */

static int count_entries(const char *dir) {
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) ++n;
    closedir(d);
    return n;
}

/* The file at path holds exactly these bytes. */
static void assert_file_holds(const char *path, const unsigned char *bytes, size_t size) {
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    unsigned char *file = malloc(size + 1);
    assert_non_null(file);
    assert_int_equal(fread(file, 1, size + 1, f), size);
    fclose(f);
    assert_memory_equal(file, bytes, size);
    free(file);
}

static void test_files(void **state) {
    (void)state;
    char dir[] = "checkpoint_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256], other[256], sub[256];
    snprintf(path, sizeof path, "%s/run.lpi", dir);
    snprintf(other, sizeof other, "%s/missing/run.lpi", dir);
    snprintf(sub, sizeof sub, "%s/sub", dir);

    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_step(sys, 0.01, 100), LPI_OK);
    assert_int_equal(lpi_save(sys, path), LPI_OK);
    assert_int_equal(count_entries(dir), 1); /* no temporary file left */
    /* The file holds the same bytes as the buffer. */
    size_t size;
    unsigned char *buf = save(sys, &size);
    assert_file_holds(path, buf, size);

    /* Overwriting replaces the whole file, and loading resumes. */
    assert_int_equal(lpi_step(sys, 0.01, 100), LPI_OK);
    assert_int_equal(lpi_save(sys, path), LPI_OK);
    assert_int_equal(count_entries(dir), 1);
    lpi_system *copy = NULL;
    assert_int_equal(lpi_load(&copy, path), LPI_OK);
    assert_true(lpi_time(copy) == lpi_time(sys));
    assert_int_equal(lpi_step(sys, 0.01, 100), LPI_OK);
    assert_int_equal(lpi_step(copy, 0.01, 100), LPI_OK);
    lpi_snapshot a, b;
    lpi_take_snapshot(sys, &a);
    lpi_take_snapshot(copy, &b);
    assert_memory_equal(a.x, b.x, 3 * sizeof(double));
    lpi_destroy(copy);

    /* File-system failures: LPI_ERR_IO, nothing left behind. */
    LPI_ASSERT_FAILS(sys, lpi_save(sys, other), LPI_ERR_IO, "lpi_save");
    assert_non_null(strstr(lpi_last_error(sys), "missing"));
    assert_int_equal(mkdir(sub, 0755), 0);
    LPI_ASSERT_FAILS(sys, lpi_save(sys, sub), LPI_ERR_IO, "lpi_save"); /* a directory */
    assert_int_equal(count_entries(dir), 2);
    LPI_ASSERT_FAILS(sys, lpi_save(sys, ""), LPI_ERR_INVALID, "lpi_save");
    copy = (lpi_system *)0x1;
    LPI_ASSERT_FAILS(NULL, lpi_load(&copy, other), LPI_ERR_IO, "lpi_load");
    assert_null(copy);
    LPI_ASSERT_FAILS(NULL, lpi_load(&copy, sub), LPI_ERR_IO, "lpi_load");
    /* A truncated file. */
    FILE *f = fopen(path, "wb");
    assert_int_equal(fwrite(buf, 1, size / 2, f), size / 2);
    fclose(f);
    LPI_ASSERT_FAILS(NULL, lpi_load(&copy, path), LPI_ERR_FORMAT, "lpi_load");
    assert_non_null(strstr(lpi_last_error(NULL), "truncated"));
    assert_null(copy);

    /* An empty file. */
    f = fopen(path, "wb");
    fclose(f);
    LPI_ASSERT_FAILS(NULL, lpi_load(&copy, path), LPI_ERR_FORMAT, "lpi_load");
    assert_non_null(strstr(lpi_last_error(NULL), "truncated: 0 bytes"));

    rmdir(sub);
    unlink(path);
    assert_int_equal(rmdir(dir), 0);
    free(buf);
    lpi_destroy(sys);
}

/* Runs lpi_save with writes beyond `limit` bytes failing (EFBIG, with
 * SIGXFSZ ignored): a full disk, without one. */
static int save_with_file_limit(const lpi_system *sys, const char *path, rlim_t limit) {
    struct rlimit old, low;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
    low = old;
    low.rlim_cur = limit;
    void (*handler)(int) = signal(SIGXFSZ, SIG_IGN);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &low), 0);
    const int status = lpi_save(sys, path);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
    signal(SIGXFSZ, handler);
    return status;
}

/* What a save may replace: a regular file, keeping its permission bits, or
 * the file a symbolic link names, keeping the link; never a FIFO, a device
 * or a link to nothing; and a failed write keeps the old file. */
static void test_save_targets(void **state) {
    (void)state;
    char dir[] = "checkpoint_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char real[64], link_path[64], dangling[64], fifo[64], nowhere[64];
    snprintf(real, sizeof real, "%s/real.lpi", dir);
    snprintf(link_path, sizeof link_path, "%s/link.lpi", dir);
    snprintf(dangling, sizeof dangling, "%s/dangling.lpi", dir);
    snprintf(fifo, sizeof fifo, "%s/fifo.lpi", dir);
    snprintf(nowhere, sizeof nowhere, "%s/nowhere.lpi", dir);
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_save(sys, real), LPI_OK);
    assert_int_equal(chmod(real, 0600), 0);
    struct stat st;

    /* A private file's new contents are written private too: under the
     * usual umask its temporary was 0644 until the chmod before the rename. */
    const mode_t umask_before = umask(022);
    record_write_modes = 1;
    widest_write_mode = 0;
    assert_int_equal(lpi_save(sys, real), LPI_OK);
    record_write_modes = 0;
    umask(umask_before);
    assert_int_equal(widest_write_mode, 0600);

    /* Through a link: the file it names is replaced, the link stays. */
    assert_int_equal(symlink("real.lpi", link_path), 0);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    assert_int_equal(lpi_save(sys, link_path), LPI_OK);
    assert_int_equal(lstat(link_path, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_int_equal(stat(real, &st), 0);
    assert_int_equal(st.st_mode & 07777, 0600);
    lpi_system *back = NULL;
    assert_int_equal(lpi_load(&back, real), LPI_OK);
    assert_true(lpi_time(back) == lpi_time(sys));
    lpi_destroy(back);
    assert_int_equal(count_entries(dir), 2);

    /* A link to nothing, a FIFO: refused, left as they are. */
    assert_int_equal(symlink("nowhere.lpi", dangling), 0);
    LPI_ASSERT_FAILS(sys, lpi_save(sys, dangling), LPI_ERR_IO, "lpi_save");
    assert_non_null(strstr(lpi_last_error(sys), "symbolic link to a missing file"));
    assert_int_equal(access(nowhere, F_OK), -1);
    assert_int_equal(mkfifo(fifo, 0644), 0);
    LPI_ASSERT_FAILS(sys, lpi_save(sys, fifo), LPI_ERR_IO, "lpi_save");
    assert_non_null(strstr(lpi_last_error(sys), "not a regular file"));
    assert_int_equal(lstat(fifo, &st), 0);
    assert_true(S_ISFIFO(st.st_mode));

    /* A write that fails midway keeps the old file, bytes and mode. */
    size_t size;
    unsigned char *old = save(sys, &size);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    assert_int_equal(save_with_file_limit(sys, real, 64), LPI_ERR_IO);
    assert_non_null(strstr(lpi_last_error(sys), "cannot write"));
    assert_file_holds(real, old, size);
    assert_int_equal(stat(real, &st), 0);
    assert_int_equal(st.st_mode & 07777, 0600);
    assert_int_equal(count_entries(dir), 4); /* no temporary file left */

    free(old);
    unlink(real), unlink(link_path), unlink(dangling), unlink(fifo);
    assert_int_equal(rmdir(dir), 0);
    lpi_destroy(sys);
}

/* Peak resident memory, in KiB. */
static long peak_rss_kib(void) {
    struct rusage usage;
    assert_int_equal(getrusage(RUSAGE_SELF, &usage), 0);
    return usage.ru_maxrss;
}

/* A sparse file of `size` bytes that starts with `head`; 0 when the file
 * system cannot hold it. */
static int sparse_file(const char *path, const void *head, size_t head_size, off_t size) {
    const int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, head, head_size), (ssize_t)head_size);
    const int ok = ftruncate(fd, size) == 0;
    close(fd);
    return ok;
}

/* A file is judged by its header and size before it is read: a foreign
 * file or a lying header of gigabytes costs neither its size in memory nor
 * the time to read it, and gives FORMAT, never NO_MEMORY. */
static void test_files_read_bounded(void **state) {
    (void)state;
    char dir[] = "checkpoint_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/big", dir);
    lpi_system *sys = rigid_body(), *out = (lpi_system *)0x1;
    size_t size;
    unsigned char *buf = save(sys, &size);
    const long before = peak_rss_kib();
    const off_t sizes[] = {(off_t)1 << 30, (off_t)8 << 30};
    for (int i = 0; i < 2; ++i) {
        /* Foreign: text where the magic should be. */
        if (!sparse_file(path, "Just some text, no checkpoint at all", 36, sizes[i])) break;
        LPI_ASSERT_FAILS(NULL, lpi_load(&out, path), LPI_ERR_FORMAT, "lpi_load");
        assert_true(peak_rss_kib() - before < 64 * 1024);
        assert_non_null(strstr(lpi_last_error(NULL), "magic"));
        assert_null(out);
        /* A real header, announcing its own size: not the file's. */
        assert_true(sparse_file(path, buf, size, sizes[i]));
        LPI_ASSERT_FAILS(NULL, lpi_load(&out, path), LPI_ERR_FORMAT, "lpi_load");
        assert_true(peak_rss_kib() - before < 64 * 1024);
        assert_non_null(strstr(lpi_last_error(NULL), "unexpected bytes"));
    }
    /* A header announcing 2^62 bytes, in a small file and in a buffer. */
    unsigned char *liar = malloc(size);
    memcpy(liar, buf, size);
    const uint64_t huge = UINT64_C(1) << 62;
    memcpy(liar + 16, &huge, 8);
    assert_true(sparse_file(path, liar, size, (off_t)size));
    LPI_ASSERT_FAILS(NULL, lpi_load(&out, path), LPI_ERR_FORMAT, "lpi_load");
    assert_non_null(strstr(lpi_last_error(NULL), "truncated"));
    assert_non_null(strstr(lpi_last_error(NULL), path)); /* which file */
    assert_refused(liar, size, "truncated");
    const long grown = peak_rss_kib() - before;
    printf("peak memory grew by %ld KiB over the foreign and lying files\n", grown);
    assert_true(grown < 64 * 1024);
    unlink(path);
    assert_int_equal(rmdir(dir), 0);
    free(liar), free(buf);
    lpi_destroy(sys);
}

/* Any name the file system accepts can be saved to: the temporary file has
 * a short name of its own, not the target's name with a suffix. Failures
 * name the path and keep the old file. */
static void test_save_names_and_failures(void **state) {
    (void)state;
    char dir[] = "checkpoint_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char longest[512], missing[512];
    const long name_max = pathconf(dir, _PC_NAME_MAX);
    assert_true(name_max >= 14 && name_max < 400);
    int n = snprintf(longest, sizeof longest, "%s/", dir);
    memset(longest + n, 'c', (size_t)name_max);
    longest[n + name_max] = '\0';
    snprintf(missing, sizeof missing, "%s/no-such-dir/run.lpi", dir);

    lpi_system *sys = rigid_body(), *copy = NULL;
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    assert_int_equal(lpi_save(sys, longest), LPI_OK);
    assert_int_equal(count_entries(dir), 1);
    assert_int_equal(lpi_load(&copy, longest), LPI_OK);
    assert_true(lpi_time(copy) == lpi_time(sys));
    lpi_destroy(copy);

    /* A missing directory: IO, naming the path. */
    LPI_ASSERT_FAILS(sys, lpi_save(sys, missing), LPI_ERR_IO, "lpi_save");
    assert_non_null(strstr(lpi_last_error(sys), missing));
    /* The target is a directory: refused, the directory intact. */
    LPI_ASSERT_FAILS(sys, lpi_save(sys, dir), LPI_ERR_IO, "lpi_save");
    assert_int_equal(count_entries(dir), 1);
    copy = (lpi_system *)0x1;
    LPI_ASSERT_FAILS(NULL, lpi_load(&copy, dir), LPI_ERR_IO, "lpi_load");
    assert_non_null(strstr(lpi_last_error(NULL), "is a directory"));
    assert_null(copy);

    /* A write that fails half-way (the file-size limit stands in for a full
     * disk): IO, the old checkpoint intact, no temporary file left. */
    size_t size;
    unsigned char *old = save(sys, &size);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    struct rlimit limit;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &limit), 0);
    const struct rlimit small = {size / 2, limit.rlim_max};
    void (*previous)(int) = signal(SIGXFSZ, SIG_IGN);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
    const int status = lpi_save(sys, longest);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &limit), 0);
    signal(SIGXFSZ, previous);
    assert_int_equal(status, LPI_ERR_IO);
    assert_non_null(strstr(lpi_last_error(sys), longest));
    assert_int_equal(count_entries(dir), 1);
    assert_file_holds(longest, old, size);

    unlink(longest);
    assert_int_equal(rmdir(dir), 0);
    free(old);
    lpi_destroy(sys);
}

/* A save past RLIMIT_FSIZE with SIGXFSZ at its default action (which ends
 * the process): the library fails with LPI_ERR_IO, the process lives on,
 * the old file is intact and no temporary file is left. Run in a child,
 * which the signal would kill. */
static void test_save_past_file_size_limit(void **state) {
    (void)state;
    char dir[] = "checkpoint_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/run.lpi", dir);
    lpi_system *sys = rigid_body();
    assert_int_equal(lpi_save(sys, path), LPI_OK);
    size_t size;
    unsigned char *old = save(sys, &size);
    assert_int_equal(lpi_step(sys, 0.01, 10), LPI_OK);
    fflush(NULL);
    const pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        signal(SIGXFSZ, SIG_DFL);
        struct rlimit limit;
        if (getrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(2);
        limit.rlim_cur = size / 2;
        if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(2);
        const int status = lpi_save(sys, path);
        const int refused = status == LPI_ERR_IO && strstr(lpi_last_error(sys), "File too large");
        lpi_destroy(sys); /* the child's copies, freed as the parent frees its own (valgrind) */
        free(old);
        _exit(refused ? 0 : 1);
    }
    int status = 0;
    assert_int_equal(waitpid(child, &status, 0), child);
    if (WIFSIGNALED(status)) fail_msg("lpi_save past the file-size limit: killed by signal %d", WTERMSIG(status));
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
    assert_file_holds(path, old, size);
    assert_int_equal(count_entries(dir), 1); /* no temporary file left */
    unlink(path);
    assert_int_equal(rmdir(dir), 0);
    free(old);
    lpi_destroy(sys);
}

static void test_null_and_sizes(void **state) {
    (void)state;
    lpi_system *sys = rigid_body(), *out = (lpi_system *)0x1;
    size_t size = 0;
    unsigned char small[16] = {0}, zero[16] = {0};
    LPI_ASSERT_FAILS(NULL, lpi_save(NULL, "x.lpi"), LPI_ERR_NULL, "lpi_save");
    LPI_ASSERT_FAILS(sys, lpi_save(sys, NULL), LPI_ERR_NULL, "lpi_save");
    LPI_ASSERT_FAILS(NULL, lpi_load(NULL, "x.lpi"), LPI_ERR_NULL, "lpi_load");
    LPI_ASSERT_FAILS(NULL, lpi_load(&out, NULL), LPI_ERR_NULL, "lpi_load");
    assert_null(out);
    LPI_ASSERT_FAILS(NULL, lpi_save_buffer(NULL, small, 16, &size), LPI_ERR_NULL, "lpi_save_buffer");
    LPI_ASSERT_FAILS(sys, lpi_save_buffer(sys, small, 16, NULL), LPI_ERR_NULL, "lpi_save_buffer");
    LPI_ASSERT_FAILS(sys, lpi_save_buffer(sys, NULL, 16, &size), LPI_ERR_NULL, "lpi_save_buffer");
    LPI_ASSERT_FAILS(sys, lpi_save_buffer(sys, small, 16, &size), LPI_ERR_SIZE, "lpi_save_buffer");
    assert_true(size > 16); /* the size needed is reported */
    assert_memory_equal(small, zero, sizeof small); /* and the buffer untouched */
    LPI_ASSERT_FAILS(NULL, lpi_load_buffer(NULL, small, 16), LPI_ERR_NULL, "lpi_load_buffer");
    out = (lpi_system *)0x1;
    LPI_ASSERT_FAILS(NULL, lpi_load_buffer(&out, NULL, 16), LPI_ERR_NULL, "lpi_load_buffer");
    assert_null(out);
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc_reference),
        cmocka_unit_test(test_resume_rigid_body),
        cmocka_unit_test(test_resume_pendulum),
        cmocka_unit_test(test_carry_is_needed),
        cmocka_unit_test(test_resume_sine_euler),
        cmocka_unit_test(test_resume_every_method),
        cmocka_unit_test(test_resume_matrix_baselines),
        cmocka_unit_test(test_composition_near_sum_tolerance),
        cmocka_unit_test(test_truncated_and_flipped),
        cmocka_unit_test(test_foreign_newer_other_order),
        cmocka_unit_test(test_layout_and_round_trip),
        cmocka_unit_test(test_time_carry),
        cmocka_unit_test(test_impossible_payloads),
        cmocka_unit_test(test_sine_euler_payloads),
        cmocka_unit_test(test_baselines_after_splitting),
        cmocka_unit_test(test_sine_euler_after_rk4),
        cmocka_unit_test(test_callbacks_refused),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_save_targets),
        cmocka_unit_test(test_files_read_bounded),
        cmocka_unit_test(test_save_names_and_failures),
        cmocka_unit_test(test_save_past_file_size_limit),
        cmocka_unit_test(test_null_and_sizes),
    };
    return lpi_run_tests(tests);
}
