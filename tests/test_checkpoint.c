/* Checkpoints: a loaded system continues the trajectory to the bit (every
 * saveable kind, every registered method, custom compositions, implicit
 * settings, the compensated carry); every truncation, every flipped byte, a
 * foreign, other-byte-order, newer-version or inconsistent checkpoint is
 * refused; files are written atomically and leave no temporary files. */
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "lpi_test.h"

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
        if (!sys) skip();
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

/* Every registered method, a recursive one, a custom composition and the
 * implicit baseline with non-default settings. */
static void test_resume_every_method(void **state) {
    (void)state;
    for (int i = 0; i < lpi_method_count(); ++i) {
        lpi_system *sys = rigid_body();
        int status = lpi_set_method(sys, lpi_method_name(i));
        if (status == LPI_ERR_UNSUPPORTED) {
            /* The matrix-form baselines apply to sine-Euler only. */
            lpi_destroy(sys);
            sys = sine_euler(9);
            if (!sys) continue; /* built without FFTW */
            status = lpi_set_method(sys, lpi_method_name(i));
            if (status == LPI_ERR_UNSUPPORTED) { /* built without BLAS */
                lpi_destroy(sys);
                continue;
            }
        }
        assert_int_equal(status, LPI_OK);
        assert_resumes(sys, 0.01, 37, 50);
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
    const uint32_t future = 2;
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
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    unsigned char *file = malloc(size + 1);
    assert_int_equal(fread(file, 1, size + 1, f), size);
    fclose(f);
    assert_memory_equal(file, buf, size);

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
    f = fopen(path, "wb");
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
    free(file), free(buf);
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
        cmocka_unit_test(test_truncated_and_flipped),
        cmocka_unit_test(test_foreign_newer_other_order),
        cmocka_unit_test(test_callbacks_refused),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_null_and_sizes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
