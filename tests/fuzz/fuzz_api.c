/* libFuzzer harness: the input bytes are a program of public API calls with
 * arguments, run on a few handles of every kind of system: the whole API,
 * checkpoints (buffers and files, round trips and damaged bytes), FFTW wisdom
 * (strings and files), threads and the FFT floor included. Checked after
 * every call: no crash or sanitizer report, the status is a documented
 * code, a failed call names its function in lpi_last_error and leaves the
 * handle's state and time unchanged bit for bit, and a checkpoint loads back
 * to the same state and time bit for bit. Build and run with
 * tests/fuzz/run.sh. */
#include <liepoisson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { kSlots = 4, kMaxCalls = 64, kMaxSteps = 40 };

typedef struct {
    const uint8_t *p;
    size_t left;
} reader;

static uint8_t byte(reader *r) {
    if (!r->left) return 0;
    --r->left;
    return *r->p++;
}

static int32_t small_int(reader *r, int32_t lo, int32_t hi) {
    return lo + (int32_t)(byte(r) % (uint32_t)(hi - lo + 1));
}

/* State and time of a handle, to compare bit for bit around a call. */
typedef struct {
    double *x;
    size_t n;
    double time;
} snapshot;

static void take(const lpi_system *sys, snapshot *s) {
    s->x = NULL;
    s->n = sys ? lpi_dim(sys) : 0;
    if (!sys) return;
    s->x = malloc((s->n ? s->n : 1) * sizeof(double));
    if (!s->x || lpi_get_state(sys, s->x, s->n) != LPI_OK) abort();
    s->time = lpi_time(sys);
}

/* Mostly meaningful values, sometimes raw bits (NaN payloads, subnormals). */
static double number(reader *r) {
    static const double table[] = {0.0, 1.0, -1.0, 0.5, 2.0, 3.0, 0.1, -0.3, 1e-8, 1e3,
                                   1e300, -1e300, 1e-300, 7.0, 1e150, 1e-150};
    const uint8_t mode = byte(r);
    if (mode < 200) return table[mode % (sizeof table / sizeof table[0])];
    if (mode < 210) return NAN;
    if (mode < 220) return mode & 1 ? INFINITY : -INFINITY;
    double d = 0.0;
    uint8_t raw[8];
    for (int i = 0; i < 8; ++i) raw[i] = byte(r);
    memcpy(&d, raw, sizeof d);
    return d;
}

/* Documented: a name in the header's status list. No observer is set, so no
 * call may return a positive status. */
static void check_status(int status) {
    if (status > 0 || strcmp(lpi_status_name(status), "LPI_UNKNOWN_STATUS") == 0) {
        fprintf(stderr, "undocumented status %d\n", status);
        abort();
    }
}

/* A private directory for checkpoint and wisdom files, made once. */
static char scratch[64];
static void remove_scratch(void) {
    static const char *const names[] = {"run.lpi", "wisdom", "garbage"};
    char path[128];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        snprintf(path, sizeof path, "%s/%s", scratch, names[i]);
        unlink(path);
    }
    rmdir(scratch);
}
static const char *scratch_path(const char *name, char *path, size_t size) {
    if (!scratch[0]) {
        snprintf(scratch, sizeof scratch, "/tmp/lpi-fuzz-XXXXXX");
        if (!mkdtemp(scratch)) abort();
        atexit(remove_scratch);
    }
    snprintf(path, size, "%s/%s", scratch, name);
    return path;
}

static void write_file(const char *path, const uint8_t *data, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (n) fwrite(data, 1, n, f);
    fclose(f);
}

/* A loaded handle must hold the saved state and time to the bit. */
static void check_same(const lpi_system *a, const lpi_system *b) {
    snapshot sa, sb;
    take(a, &sa);
    take(b, &sb);
    if (sa.n != sb.n || memcmp(sa.x, sb.x, sa.n * sizeof(double)) != 0 ||
        memcmp(&sa.time, &sb.time, sizeof(double)) != 0) {
        fprintf(stderr, "a checkpoint did not load back to the saved state\n");
        abort();
    }
    free(sa.x);
    free(sb.x);
}

/* A failed load leaves *out NULL with a message; a loaded handle is checked
 * against `source` (when the bytes were not damaged) and released. */
static void check_loaded(int status, lpi_system *loaded, const lpi_system *source, const char *function) {
    check_status(status);
    if (status != LPI_OK) {
        if (loaded) abort();
        if (!strstr(lpi_last_error(NULL), function)) {
            fprintf(stderr, "%s failed with message '%s'\n", function, lpi_last_error(NULL));
            abort();
        }
        return;
    }
    if (!loaded) abort();
    if (source) check_same(source, loaded);
    lpi_destroy(loaded);
}


static void compare(const lpi_system *sys, snapshot *before, int status, const char *function) {
    check_status(status);
    if (status != LPI_OK) {
        const char *msg = lpi_last_error(sys);
        if (!msg || !strstr(msg, function)) {
            fprintf(stderr, "%s failed with message '%s'\n", function, msg ? msg : "(null)");
            abort();
        }
        if (sys) {
            snapshot after;
            take(sys, &after);
            if (after.n != before->n ||
                memcmp(after.x, before->x, before->n * sizeof(double)) != 0 ||
                memcmp(&after.time, &before->time, sizeof(double)) != 0) {
                fprintf(stderr, "failed %s changed the state\n", function);
                abort();
            }
            free(after.x);
        }
    }
    free(before->x);
    before->x = NULL;
}

/* User callbacks whose behaviour the input chooses: 0 well behaved, 1
 * returns an error, 2 gives NaN, 3 gives a huge value. */
static const int kBehaviour[4] = {0, 1, 2, 3};

static double misbehave(int how, double value) {
    return how == 2 ? NAN : how == 3 ? 1e300 : value;
}
static int fuzz_grad(size_t n, const double *x, double *g, void *user) {
    const int how = *(const int *)user;
    for (size_t i = 0; i < n; ++i) g[i] = misbehave(how, 0.5 + x[i]);
    return how == 1;
}
static int fuzz_energy(size_t n, const double *x, double *h, void *user) {
    const int how = *(const int *)user;
    *h = 0;
    for (size_t i = 0; i < n; ++i) *h += 0.5 * x[i] + 0.5 * x[i] * x[i];
    *h = misbehave(how, *h);
    return how == 1;
}
static int fuzz_casimir(size_t dim, const double *x, double *out, void *user) {
    const int how = *(const int *)user;
    *out = 0;
    for (size_t i = 0; i < dim; ++i) *out += x[i] * x[i];
    *out = misbehave(how, *out);
    return how == 1;
}
static int fuzz_scalar(double u, double *out, void *user) {
    const int how = *(const int *)user;
    *out = misbehave(how, 0.02 + 0.01 * u);
    return how == 1;
}

static const char *const kMethods[] = {"leapfrog", "lie-trotter", "yoshida-6", "kahan-li-8",
                                       "rk4", "implicit-midpoint", "triple-jump-6", "suzuki-4",
                                       "no-such-method", "", "triple-jump-3", "strang"};
static const char *const kSplits[] = {"casimir-shift", "axes", "standard-map", "pieces", "bogus"};

static void run_call(lpi_system **slot, reader *r) {
    lpi_system *sys = *slot;
    snapshot before;
    const uint8_t op = byte(r) % 31;
    int status = LPI_OK;
    switch (op) {
    case 0: case 1: case 2: case 3: case 4: { /* create into an empty slot */
        if (sys) return;
        if (op == 0) status = lpi_rigid_body_create(slot, number(r), number(r), number(r));
        if (op == 1) status = lpi_pendulum_create(slot);
        if (op == 2) {
            int32_t i[6], j[6], k[6];
            double c[6];
            const size_t dim = (size_t)small_int(r, 0, 5), nnz = (size_t)small_int(r, 0, 6);
            for (size_t e = 0; e < nnz; ++e)
                i[e] = small_int(r, -1, 5), j[e] = small_int(r, -1, 5), k[e] = small_int(r, -1, 5),
                c[e] = number(r);
            status = lpi_generic_create(slot, dim, nnz, i, j, k, c);
        }
        if (op == 3) status = lpi_moments_create(slot);
        if (op == 4) {
            status = lpi_sine_euler_create(slot, small_int(r, -1, 9));
            if (status == LPI_ERR_UNSUPPORTED) status = LPI_OK; /* built without FFTW */
        }
        check_status(status);
        if (status != LPI_OK) {
            if (*slot) abort(); /* a failed create leaves *out NULL */
            if (strlen(lpi_last_error(NULL)) == 0) abort();
        }
        return;
    }
    case 5:
        lpi_destroy(sys);
        *slot = NULL;
        return;
    default:
        break;
    }
    take(sys, &before);
    switch (op) {
    case 6:
        status = lpi_set_method(sys, kMethods[byte(r) % (sizeof kMethods / sizeof kMethods[0])]);
        compare(sys, &before, status, "lpi_set_method");
        break;
    case 7:
        status = lpi_set_split(sys, kSplits[byte(r) % (sizeof kSplits / sizeof kSplits[0])]);
        compare(sys, &before, status, "lpi_set_split");
        break;
    case 8: case 9: { /* set_state, mostly with the right length */
        const size_t dim = lpi_dim(sys);
        const size_t n = byte(r) % 8 ? dim : (size_t)small_int(r, 0, 9);
        double *x = malloc((n ? n : 1) * sizeof(double));
        for (size_t i = 0; i < n; ++i) x[i] = byte(r) % 4 ? number(r) * 0.25 : number(r);
        status = lpi_set_state(sys, x, n);
        compare(sys, &before, status, "lpi_set_state");
        free(x);
        break;
    }
    case 10: case 11: case 12:
        status = lpi_step(sys, number(r), byte(r) % 16 ? small_int(r, -1, kMaxSteps) : INT64_MIN);
        compare(sys, &before, status, "lpi_step");
        break;
    case 13: {
        double h = 0;
        const size_t nc = sys ? lpi_casimir_count(sys) : 0;
        const size_t n = byte(r) % 4 ? nc : (size_t)small_int(r, 0, 4);
        double *c = malloc((n ? n : 1) * sizeof(double));
        status = lpi_energy(sys, byte(r) % 8 ? &h : NULL);
        compare(sys, &before, status, "lpi_energy");
        take(sys, &before);
        status = lpi_casimirs(sys, c, n);
        compare(sys, &before, status, "lpi_casimirs");
        free(c);
        break;
    }
    case 14: {
        double g[5];
        const size_t n = (size_t)small_int(r, 0, 5);
        for (size_t i = 0; i < n; ++i) g[i] = number(r);
        status = lpi_set_composition(sys, n, byte(r) % 8 ? g : NULL);
        compare(sys, &before, status, "lpi_set_composition");
        break;
    }
    case 15: {
        int32_t idx[4];
        const size_t n = (size_t)small_int(r, 0, 4);
        for (size_t i = 0; i < n; ++i) idx[i] = small_int(r, -1, 8);
        status = lpi_add_piece(sys, n, idx, fuzz_grad, fuzz_energy, (void *)&kBehaviour[byte(r) % 4]);
        compare(sys, &before, status, "lpi_add_piece");
        break;
    }
    case 16:
        status = lpi_add_casimir(sys, fuzz_casimir, (void *)&kBehaviour[byte(r) % 4]);
        compare(sys, &before, status, "lpi_add_casimir");
        break;
    case 17:
        status = lpi_moments_add_product_piece(sys, fuzz_scalar, fuzz_scalar,
                                               (void *)&kBehaviour[byte(r) % 4]);
        compare(sys, &before, status, "lpi_moments_add_product_piece");
        break;
    case 18:
        status = lpi_set_implicit_options(sys, number(r), small_int(r, -1, 20));
        compare(sys, &before, status, "lpi_set_implicit_options");
        break;
    case 19: {
        int32_t N = 0;
        size_t flows = 0, rank = 0;
        const uint8_t threads = byte(r);
        status = lpi_set_threads(sys, threads % 16 == 0   ? INT32_MAX
                                      : threads % 16 == 1 ? INT32_MIN
                                                          : small_int(r, -1, 3));
        compare(sys, &before, status, "lpi_set_threads");
        take(sys, &before);
        status = lpi_flows_per_step(sys, &flows);
        compare(sys, &before, status, "lpi_flows_per_step");
        take(sys, &before);
        status = lpi_sine_euler_size(sys, &N);
        compare(sys, &before, status, "lpi_sine_euler_size");
        const size_t dim = lpi_dim(sys);
        double *x = calloc(dim ? dim : 1, sizeof(double));
        for (size_t i = 0; i < dim; ++i) x[i] = number(r);
        take(sys, &before);
        status = lpi_poisson_rank(sys, x, dim, &rank);
        compare(sys, &before, status, "lpi_poisson_rank");
        free(x);
        break;
    }
    case 20: case 21: { /* sine-Euler modes and grid, right or wrong lengths */
        int32_t N = 0;
        if (lpi_sine_euler_size(sys, &N) != LPI_OK) N = small_int(r, 1, 5);
        const int grid = op == 21;
        size_t n = (size_t)N * N * (grid ? 1 : 2);
        if (byte(r) % 8 == 0) n = (size_t)small_int(r, 0, 20);
        double *w = malloc((n ? n : 1) * sizeof(double));
        for (size_t i = 0; i < n; ++i) w[i] = byte(r) % 2 ? 0.0 : number(r) * 0.1;
        if (grid) {
            status = lpi_sine_euler_set_grid(sys, w, n);
            compare(sys, &before, status, "lpi_sine_euler_set_grid");
            take(sys, &before);
            status = lpi_sine_euler_get_grid(sys, w, n);
            compare(sys, &before, status, "lpi_sine_euler_get_grid");
        } else {
            status = lpi_sine_euler_set_modes(sys, w, n);
            compare(sys, &before, status, "lpi_sine_euler_set_modes");
            take(sys, &before);
            status = lpi_sine_euler_get_modes(sys, w, n);
            compare(sys, &before, status, "lpi_sine_euler_get_modes");
        }
        free(w);
        break;
    }
    case 22: {
        double e = 0, traces[8];
        status = lpi_sine_euler_enstrophy(sys, &e);
        compare(sys, &before, status, "lpi_sine_euler_enstrophy");
        take(sys, &before);
        status = lpi_sine_euler_casimir_traces(sys, small_int(r, -1, 8), traces);
        compare(sys, &before, status, "lpi_sine_euler_casimir_traces");
        break;
    }
    case 23: {
        double out[3];
        status = lpi_rigid_body_exact(sys, number(r), out);
        compare(sys, &before, status, "lpi_rigid_body_exact");
        break;
    }
    case 24: { /* checkpoint buffer: size query, short capacity, round trip, a damaged byte */
        size_t size = 0;
        status = lpi_save_buffer(sys, NULL, 0, &size);
        if (status == LPI_ERR_SIZE) status = LPI_OK; /* the size query */
        compare(sys, &before, status, "lpi_save_buffer");
        if (status != LPI_OK || size == 0) break;
        uint8_t *buf = malloc(size);
        const size_t capacity = byte(r) % 8 ? size : size - 1;
        take(sys, &before);
        status = lpi_save_buffer(sys, buf, capacity, &size);
        compare(sys, &before, status, "lpi_save_buffer");
        if (status == LPI_OK) {
            const int damaged = byte(r) % 4 == 0;
            if (damaged) buf[(size_t)byte(r) * 257u % size] ^= (uint8_t)(1u << (byte(r) % 8));
            lpi_system *loaded = NULL;
            const size_t length = byte(r) % 8 ? size : (size_t)byte(r) % size;
            status = lpi_load_buffer(&loaded, byte(r) % 16 ? buf : NULL, length);
            check_loaded(status, loaded, damaged || length != size ? NULL : sys, "lpi_load_buffer");
        }
        free(buf);
        break;
    }
    case 25: { /* checkpoint file: round trip, or a directory that does not exist */
        char path[128];
        scratch_path(byte(r) % 4 ? "run.lpi" : "no-such-dir/run.lpi", path, sizeof path);
        status = lpi_save(sys, byte(r) % 16 ? path : NULL);
        compare(sys, &before, status, "lpi_save");
        if (status != LPI_OK) break;
        lpi_system *loaded = NULL;
        status = lpi_load(&loaded, path);
        if (status != LPI_OK) abort(); /* what was just saved loads */
        check_loaded(status, loaded, sys, "lpi_load");
        break;
    }
    case 26: { /* checkpoint bytes from the input, as a buffer and as a file */
        free(before.x);
        const size_t n = r->left < 96 ? r->left : byte(r) % 96;
        lpi_system *loaded = NULL;
        status = lpi_load_buffer(&loaded, r->p, n);
        check_loaded(status, loaded, NULL, "lpi_load_buffer");
        char path[128];
        write_file(scratch_path("garbage", path, sizeof path), r->p, n);
        loaded = NULL;
        status = lpi_load(&loaded, path);
        check_loaded(status, loaded, NULL, "lpi_load");
        r->p += n, r->left -= n;
        return;
    }
    case 27: { /* wisdom as a string: size query, short buffer, round trip, input text */
        free(before.x);
        size_t length = 0;
        status = lpi_fftw_wisdom_export_string(NULL, 0, &length);
        check_status(status);
        if (status == LPI_ERR_UNSUPPORTED) return; /* built without FFTW */
        if (status != LPI_OK) abort(); /* a query of the length */
        const size_t size = byte(r) % 8 ? length + 1 : length;
        char *text = malloc(size ? size : 1);
        status = lpi_fftw_wisdom_export_string(text, size, &length);
        check_status(status);
        if (status == LPI_OK) {
            if (strlen(text) != length) abort();
            status = lpi_fftw_wisdom_import_string(text);
            if (status != LPI_OK) abort(); /* exported wisdom imports */
        }
        free(text);
        char input[40];
        const size_t n = (size_t)byte(r) % sizeof input;
        for (size_t i = 0; i < n; ++i) input[i] = (char)(byte(r) | 1);
        input[n] = '\0';
        status = lpi_fftw_wisdom_import_string(byte(r) % 16 ? input : NULL);
        check_status(status);
        return;
    }
    case 28: { /* wisdom files: round trip, input bytes, a missing file */
        free(before.x);
        char path[128], garbage[128];
        scratch_path("wisdom", path, sizeof path);
        status = lpi_fftw_wisdom_export_file(path);
        check_status(status);
        if (status == LPI_ERR_UNSUPPORTED) return;
        if (status != LPI_OK || lpi_fftw_wisdom_import_file(path) != LPI_OK) abort();
        const size_t n = r->left < 64 ? r->left : byte(r) % 64;
        write_file(scratch_path("garbage", garbage, sizeof garbage), r->p, n);
        r->p += n, r->left -= n;
        check_status(lpi_fftw_wisdom_import_file(garbage));
        check_status(lpi_fftw_wisdom_import_file(scratch_path("no-such-file", path, sizeof path)));
        check_status(lpi_fftw_wisdom_export_file(scratch_path("no-such-dir/wisdom", path, sizeof path)));
        check_status(lpi_fftw_wisdom_import_file(NULL));
        return;
    }
    case 29: { /* the FFTW planning rigor (estimate only: measuring is slow), read back */
        static const char *const names[] = {"estimate", "", "measure!", NULL};
        const char *rigor = NULL;
        status = lpi_sine_euler_set_planning(sys, names[byte(r) % 4]);
        compare(sys, &before, status, "lpi_sine_euler_set_planning");
        check_status(lpi_sine_euler_get_planning(sys, byte(r) % 8 ? &rigor : NULL));
        break;
    }
    default: { /* the FFT floor, a few steps' worth */
        double seconds = 0, count = 0;
        const uint8_t which = byte(r);
        status = lpi_sine_euler_fft_floor(sys, small_int(r, -1, 3), which % 8 ? &seconds : NULL,
                                          which % 8 == 1 ? NULL : &count);
        compare(sys, &before, status, "lpi_sine_euler_fft_floor");
        break;
    }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    reader r = {data, size};
    lpi_system *slots[kSlots] = {NULL, NULL, NULL, NULL};
    /* Handle-free functions with arbitrary arguments. */
    const int i = (int)(int8_t)byte(&r);
    (void)lpi_status_name(i);
    (void)lpi_status_message(i);
    (void)lpi_method_name(i);
    (void)lpi_method_order(i);
    (void)lpi_method_stages(i);
    (void)lpi_method_reference(i);
    (void)lpi_method_is_poisson(i);
    for (int call = 0; call < kMaxCalls && r.left; ++call) run_call(&slots[byte(&r) % kSlots], &r);
    for (int s = 0; s < kSlots; ++s) lpi_destroy(slots[s]);
    return 0;
}
