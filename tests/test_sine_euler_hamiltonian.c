/* The sine-bracket family: sine-Euler with any Hamiltonian
 * H = 1/2 sum lambda_n |w_n|^2 + sum conj(f_n) w_n, against an independent
 * matrix-form integration written from the definitions
 * (sine_euler_hamiltonian_reference.h: J_m built entry by entry,
 * P = sum psi_n J_n with psi = lambda w + f, classical RK4 with tiny steps):
 * SQG and Euler over a topography, prime and composite N, measured orders,
 * every method, the Casimirs, steady single-line fields, the default to the
 * bit, checkpoints, the diagnostics and the API contract. */
#include "lpi_test.h"
#include "sine_euler_hamiltonian_reference.h"

static void set_hamiltonian(lpi_system *sys, const hamiltonian *H) {
    assert_int_equal(lpi_sine_euler_set_hamiltonian(sys, H->lambda, (size_t)H->N * H->N,
                                                    (const double *)H->f, 2 * (size_t)H->N * H->N),
                     LPI_OK);
}

static lpi_system *system_with(const hamiltonian *H, const double *w, const char *method) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_sine_euler_create(&sys, H->N), LPI_OK);
    set_hamiltonian(sys, H);
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * (size_t)H->N * H->N), LPI_OK);
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    return sys;
}

static void run(const hamiltonian *H, const char *method, const double *w0, double T,
                int64_t steps, double *out) {
    lpi_system *sys = system_with(H, w0, method);
    assert_int_equal(lpi_step(sys, T / (double)steps, steps), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, out, 2 * (size_t)H->N * H->N), LPI_OK);
    lpi_destroy(sys);
}

typedef void (*hamiltonian_maker)(int N, hamiltonian *H);
static const struct {
    const char *name;
    hamiltonian_maker make;
} kFamilies[] = {{"SQG", sqg}, {"topography", topography}};

#define REQUIRE_SINE_EULER() \
    if (!lpi_test_have_sine_euler()) LPI_SKIP("built without FFTW: no sine-Euler")

/* ---- the tests ----------------------------------------------------------- */

/* The reference is checked before it is trusted: with Euler's lambda it is the
 * rate of eq. 5 summed term by term (the paper's form). */
static void test_reference_is_eq5_for_euler(void **state) {
    (void)state;
    const int N = 7;
    hamiltonian H;
    euler(N, &H);
    double w[2 * kMaxModes];
    lpi_test_random_field(N, 21, 1.0, w);
    cplx W[kMaxModes], dW[kMaxModes], rate[kMaxModes];
    to_matrix(N, (const cplx *)w, W);
    matrix_rate(&H, W, dW);
    from_matrix(N, dW, rate);
    const cplx *z = (const cplx *)w;
    const double eps = 2 * M_PI / N;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            cplx sum = 0;
            for (int n = 1; n < N * N; ++n) {
                const int n1 = n / N, n2 = n % N;
                const double cross = (double)lpi_test_centred(a, N) * lpi_test_centred(n2, N) -
                                     (double)lpi_test_centred(b, N) * lpi_test_centred(n1, N);
                sum += sin(eps * cross) / (eps * norm2(n1, n2, N)) *
                       z[lpi_test_mod(a + n1, N) * N + lpi_test_mod(b + n2, N)] * z[mirror(n, N)];
            }
            assert_true(cabs(sum - rate[a * N + b]) < 1e-13);
        }
}

/* Global orders 2 (leapfrog) and 4 (triple-jump-4) against the matrix-form
 * RK4, for SQG and for Euler over a topography, prime and composite N. */
static void test_measured_orders(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int Ns[] = {7, 9};
    const struct {
        const char *method;
        int order;
        int64_t steps[4];
    } cases[] = {{"leapfrog", 2, {8, 16, 32, 64}}, {"triple-jump-4", 4, {4, 8, 16, 32}}};
    for (int t = 0; t < 2; ++t)
        for (int fam = 0; fam < 2; ++fam) {
            const int N = Ns[t];
            const size_t n = 2 * (size_t)N * N;
            hamiltonian H;
            kFamilies[fam].make(N, &H);
            double w0[2 * kMaxModes], ref[2 * kMaxModes], ours[2 * kMaxModes];
            lpi_test_random_field(N, 3 + (uint64_t)N, 3.0, w0);
            const double T = 1.0;
            matrix_rk4(&H, w0, T, 1000, ref);
            for (int c = 0; c < 2; ++c) {
                double hs[4], errs[4];
                for (int i = 0; i < 4; ++i) {
                    run(&H, cases[c].method, w0, T, cases[c].steps[i], ours);
                    hs[i] = T / (double)cases[c].steps[i];
                    errs[i] = max_abs_diff(ours, ref, n);
                }
                const double order = lpi_fit_order(hs, errs, 4);
                printf("N = %d %-10s %-14s errors %.2e .. %.2e, measured order %.2f\n", N,
                       kFamilies[fam].name, cases[c].method, errs[0], errs[3], order);
                assert_true(fabs(order - cases[c].order) < 0.3);
            }
        }
}

/* Every method integrates the Hamiltonian it is given: over T = 0.1 each
 * agrees with the reference to its own accuracy, far below the O(T) that
 * Euler's lambda in place of SQG's, or a missing f, would leave. */
static void test_every_method_uses_the_hamiltonian(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int N = 7;
    const size_t n = 2 * (size_t)N * N;
    hamiltonian H;
    topography(N, &H);
    hamiltonian S; /* the SQG lambda with the topography's f */
    sqg(N, &S);
    memcpy(H.lambda, S.lambda, sizeof H.lambda);
    double w0[2 * kMaxModes], ref[2 * kMaxModes], ours[2 * kMaxModes], euler_ref[2 * kMaxModes];
    lpi_test_random_field(N, 77, 3.0, w0);
    const double T = 0.1;
    matrix_rk4(&H, w0, T, 200, ref);
    hamiltonian E;
    euler(N, &E);
    matrix_rk4(&E, w0, T, 200, euler_ref);
    const double wrong = max_abs_diff(ref, euler_ref, n);
    const char *methods[] = {"leapfrog", "triple-jump-4", "rk4", "implicit-midpoint",
                             "isomp", "rk4-matrix", "direct-eq5"};
    for (size_t m = 0; m < sizeof methods / sizeof *methods; ++m) {
        lpi_system *sys = system_with(&H, w0, methods[m]);
        const int status = lpi_step(sys, T / 20, 20);
        if (status == LPI_ERR_UNSUPPORTED) { /* the matrix methods without BLAS */
            printf("%-18s unsupported in this build: %s\n", methods[m], lpi_last_error(sys));
            lpi_destroy(sys);
            continue;
        }
        assert_int_equal(status, LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(sys, ours, n), LPI_OK);
        const double err = max_abs_diff(ours, ref, n);
        printf("%-18s error %.2e (Euler's lambda and no f: %.2e)\n", methods[m], err, wrong);
        assert_true(err < 1e-5);
        assert_true(err < 1e-3 * wrong);
        lpi_destroy(sys);
    }
}

/* lpi_energy is this H, and the splitting keeps it to O(dt^2). */
static void test_energy_is_h(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int N = 9;
    for (int fam = 0; fam < 2; ++fam) {
        hamiltonian H;
        kFamilies[fam].make(N, &H);
        double w[2 * kMaxModes];
        lpi_test_random_field(N, 5, 1.0, w);
        lpi_system *sys = system_with(&H, w, "leapfrog");
        double E0, E1;
        assert_int_equal(lpi_energy(sys, &E0), LPI_OK);
        assert_true(fabs(E0 - energy_of(&H, w)) <= 1e-14 * fabs(E0));
        assert_int_equal(lpi_step(sys, 0.01, 200), LPI_OK);
        assert_int_equal(lpi_energy(sys, &E1), LPI_OK);
        printf("%-10s H = %.6f, relative change over 200 steps %.1e\n", kFamilies[fam].name, E0,
               fabs(E1 - E0) / fabs(E0));
        assert_true(fabs(E1 - E0) <= 1e-4 * fabs(E0));
        lpi_destroy(sys);
    }
}

/* The spectrum of W is kept as for Euler: the same steps from the same field
 * move it by no more than the Euler run's bound (test_sine_euler: 1e-12). */
static void test_spectrum_kept(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int Ns[] = {9, 15};
    for (int t = 0; t < 2; ++t) {
        const int N = Ns[t];
        /* SQG's lambda with f = -h/|n|^2, h a smooth field. */
        double lambda[225], w[450], f[450], before[15], after[15];
        lpi_test_random_field(N, 0xB0770Bull, 2.0, f);
        for (int i = 0; i < N * N; ++i) {
            lambda[i] = i ? 1.0 / sqrt((double)norm2(i / N, i % N, N)) : 0;
            f[2 * i] *= -lambda[i] * lambda[i], f[2 * i + 1] *= -lambda[i] * lambda[i];
        }
        lpi_test_random_field(N, 11, 1.0, w);
        lpi_system *sys = NULL;
        assert_int_equal(lpi_sine_euler_create(&sys, N), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_hamiltonian(sys, lambda, (size_t)N * N, f, 2 * (size_t)N * N), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * (size_t)N * N), LPI_OK);
        int status = lpi_casimirs(sys, before, N);
        if (status == LPI_ERR_UNSUPPORTED) {
            lpi_destroy(sys);
            LPI_SKIP("built without LAPACK: no Casimir spectrum to check");
        }
        assert_int_equal(status, LPI_OK);
        assert_int_equal(lpi_step(sys, 0.05, 4000), LPI_OK);
        assert_int_equal(lpi_casimirs(sys, after, N), LPI_OK);
        double scale = 0, drift = 0;
        for (int i = 0; i < N; ++i) {
            scale = fmax(scale, fabs(before[i]));
            drift = fmax(drift, fabs(after[i] - before[i]));
        }
        printf("N = %d: spectrum drift over 4000 leapfrog steps %.2e relative\n", N, drift / scale);
        assert_true(drift / scale <= 1e-12);
        lpi_destroy(sys);
    }
}

/* A field on one line through the origin is steady for any lambda and an f on
 * the same line (every mode commutes with every other), prime and composite
 * N; random lambda of both signs. Such a shear flow is often unstable (with
 * this lambda, round-off grows by e^4 per unit time), so the run is short. */
static void test_single_line_steady_for_any_lambda(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int Ns[] = {31, 15};
    for (int t = 0; t < 2; ++t) {
        const int N = Ns[t];
        const size_t n = 2 * (size_t)N * N;
        double *lambda = calloc((size_t)N * N, sizeof(double)), *f = calloc(n, sizeof(double)),
               *w = calloc(n, sizeof(double)), *out = malloc(n * sizeof(double));
        for (int i = 1; i < N * N; ++i) {
            const int j = i < mirror(i, N) ? i : mirror(i, N);
            lambda[i] = sin(1.7 * j) * 3.0;
        }
        const int k[2] = {1, 3};
        for (int s = 1; s <= N / 2; ++s) {
            const int i = lpi_test_mod(s * k[0], N) * N + lpi_test_mod(s * k[1], N), j = mirror(i, N);
            w[2 * i] = w[2 * j] = cos(s);
            w[2 * i + 1] = sin(3.0 * s) / s, w[2 * j + 1] = -w[2 * i + 1];
            f[2 * i] = f[2 * j] = 0.5 / s;
            f[2 * i + 1] = 0.25 * s, f[2 * j + 1] = -f[2 * i + 1];
        }
        lpi_system *sys = NULL;
        assert_int_equal(lpi_sine_euler_create(&sys, N), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_hamiltonian(sys, lambda, (size_t)N * N, f, n), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_modes(sys, w, n), LPI_OK);
        assert_int_equal(lpi_step(sys, 0.01, 100), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(sys, out, n), LPI_OK);
        const double change = max_abs_diff(out, w, n);
        printf("N = %d single-line field, any lambda: max change over 100 steps %.2e\n", N, change);
        assert_true(change <= 1e-13);
        lpi_destroy(sys);
        free(lambda), free(f), free(w), free(out);
    }
}

/* lambda = 1/|n|^2 and f = 0 given explicitly (f as NULL or as zeros) change
 * no bit of any result: modes, energy and checkpoint bytes, every method. */
static void test_explicit_default_is_the_default(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int N = 9;
    const size_t n = 2 * (size_t)N * N;
    hamiltonian E;
    euler(N, &E);
    double w[2 * kMaxModes], zeros[2 * kMaxModes] = {0};
    lpi_test_random_field(N, 8, 2.0, w);
    const char *methods[] = {"leapfrog", "rk4", "isomp", "rk4-matrix", "direct-eq5"};
    for (size_t m = 0; m < sizeof methods / sizeof *methods; ++m) {
        lpi_system *sys[3];
        double modes[3][2 * kMaxModes], energy[3];
        unsigned char bytes[3][8192];
        size_t length[3];
        int status[3];
        for (int v = 0; v < 3; ++v) {
            sys[v] = NULL;
            assert_int_equal(lpi_sine_euler_create(&sys[v], N), LPI_OK);
            if (v > 0)
                assert_int_equal(lpi_sine_euler_set_hamiltonian(sys[v], E.lambda, (size_t)N * N,
                                                                v == 1 ? NULL : zeros, v == 1 ? 0 : n),
                                 LPI_OK);
            assert_int_equal(lpi_sine_euler_set_modes(sys[v], w, n), LPI_OK);
            assert_int_equal(lpi_set_method(sys[v], methods[m]), LPI_OK);
            status[v] = lpi_step(sys[v], 0.01, 5);
            assert_int_equal(status[v], status[0]);
            assert_int_equal(lpi_sine_euler_get_modes(sys[v], modes[v], n), LPI_OK);
            assert_int_equal(lpi_energy(sys[v], &energy[v]), LPI_OK);
            assert_int_equal(lpi_save_buffer(sys[v], bytes[v], sizeof bytes[v], &length[v]), LPI_OK);
        }
        for (int v = 1; v < 3; ++v) {
            assert_memory_equal(modes[v], modes[0], n * sizeof(double));
            assert_memory_equal(&energy[v], &energy[0], sizeof(double));
            assert_int_equal(length[v], length[0]);
            assert_memory_equal(bytes[v], bytes[0], length[0]);
        }
        for (int v = 0; v < 3; ++v) lpi_destroy(sys[v]);
    }
}

/* A checkpoint carries lambda and f: the loaded system has the same energy and
 * continues the trajectory to the bit. */
static void test_checkpoint_carries_the_hamiltonian(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int N = 9;
    const size_t n = 2 * (size_t)N * N;
    hamiltonian H;
    topography(N, &H);
    hamiltonian S;
    sqg(N, &S);
    memcpy(H.lambda, S.lambda, sizeof H.lambda);
    double w[2 * kMaxModes], a[2 * kMaxModes], b[2 * kMaxModes];
    lpi_test_random_field(N, 9, 2.0, w);
    lpi_system *sys = system_with(&H, w, "triple-jump-4"), *loaded = NULL;
    assert_int_equal(lpi_step(sys, 0.02, 10), LPI_OK);
    size_t length = 0;
    assert_int_equal(lpi_save_buffer(sys, NULL, 0, &length), LPI_OK);
    unsigned char *bytes = malloc(length + 1);
    assert_int_equal(lpi_save_buffer(sys, bytes, length + 1, &length), LPI_OK);
    assert_int_equal(lpi_load_buffer(&loaded, bytes, length), LPI_OK);
    double E0, E1;
    assert_int_equal(lpi_energy(sys, &E0), LPI_OK);
    assert_int_equal(lpi_energy(loaded, &E1), LPI_OK);
    assert_memory_equal(&E0, &E1, sizeof E0);
    assert_int_equal(lpi_step(sys, 0.02, 10), LPI_OK);
    assert_int_equal(lpi_step(loaded, 0.02, 10), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, a, n), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(loaded, b, n), LPI_OK);
    assert_memory_equal(a, b, n * sizeof(double));
    /* A default system's checkpoint stores N alone: 3 N^2 doubles fewer. */
    lpi_system *plain = NULL;
    size_t plain_length = 0;
    assert_int_equal(lpi_sine_euler_create(&plain, N), LPI_OK);
    assert_int_equal(lpi_set_method(plain, "triple-jump-4"), LPI_OK);
    assert_int_equal(lpi_save_buffer(plain, NULL, 0, &plain_length), LPI_OK);
    assert_int_equal(length - plain_length, 3 * (size_t)N * N * sizeof(double));
    lpi_destroy(plain);
    lpi_destroy(sys);
    lpi_destroy(loaded);
    free(bytes);
}

/* The stream function on the grid is the DFT of psi = lambda w + f, and the
 * shell spectra add up to H and the enstrophy, shell by shell as counted here. */
static void test_stream_function_and_spectrum(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int N = 9, M = 4;
    const size_t n = 2 * (size_t)N * N;
    hamiltonian H;
    topography(N, &H);
    double w[2 * kMaxModes], psi[kMaxModes];
    lpi_test_random_field(N, 12, 1.0, w);
    w[0] = 0.5;
    lpi_system *sys = system_with(&H, w, "leapfrog");
    assert_int_equal(lpi_sine_euler_get_stream(sys, psi, (size_t)N * N), LPI_OK);
    const cplx *z = (const cplx *)w;
    for (int x = 0; x < N * N; ++x) {
        cplx sum = 0;
        for (int m = 1; m < N * N; ++m)
            sum += (H.lambda[m] * z[m] + H.f[m]) * unit_root((m / N) * (x / N) + (m % N) * (x % N), N);
        assert_true(fabs(creal(sum) - psi[x]) < 1e-13 && fabs(cimag(sum)) < 1e-13);
    }
    const size_t K = (size_t)floor(M * sqrt(2.0) + 0.5);
    double energy[16], enstrophy[16], expected_energy[16] = {0}, expected_enstrophy[16] = {0};
    size_t shells = 0;
    /* A query of K succeeds and leaves no message. */
    assert_string_equal(lpi_last_error(sys), "");
    assert_int_equal(lpi_sine_euler_spectrum(sys, NULL, NULL, 0, &shells), LPI_OK);
    assert_int_equal(shells, K);
    assert_string_equal(lpi_last_error(sys), "");
    for (int i = 0; i < 16; ++i) energy[i] = -1.0;
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_spectrum(sys, energy, enstrophy, K - 1, &shells),
                     LPI_ERR_SIZE, "lpi_sine_euler_spectrum");
    assert_true(energy[0] == -1.0);
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_spectrum(sys, energy, NULL, K, &shells), LPI_ERR_NULL,
                     "lpi_sine_euler_spectrum");
    assert_int_equal(lpi_sine_euler_spectrum(sys, energy, enstrophy, 16, &shells), LPI_OK);
    for (int m = 1; m < N * N; ++m) {
        const int k = (int)floor(sqrt((double)norm2(m / N, m % N, N)) + 0.5);
        expected_energy[k - 1] += 0.5 * H.lambda[m] * creal(z[m] * conj(z[m])) + creal(conj(H.f[m]) * z[m]);
        expected_enstrophy[k - 1] += 0.5 * creal(z[m] * conj(z[m]));
    }
    double total = 0, total_enstrophy = 0, E, Z;
    for (size_t k = 0; k < K; ++k) {
        assert_true(fabs(energy[k] - expected_energy[k]) < 1e-14);
        assert_true(fabs(enstrophy[k] - expected_enstrophy[k]) < 1e-14);
        total += energy[k], total_enstrophy += enstrophy[k];
    }
    assert_int_equal(lpi_energy(sys, &E), LPI_OK);
    assert_int_equal(lpi_sine_euler_enstrophy(sys, &Z), LPI_OK);
    assert_true(fabs(total - E) < 1e-13);
    assert_true(fabs(total_enstrophy + 0.5 * 0.25 - Z) < 1e-13);
    (void)n;
    lpi_destroy(sys);
}

/* Bad lambda and f are refused with their status and change nothing: the
 * state, the energy (so lambda and f) and what a step does. */
static void test_bad_hamiltonian_is_refused(void **state) {
    (void)state;
    REQUIRE_SINE_EULER();
    const int N = 7;
    const size_t n2 = (size_t)N * N, n = 2 * n2;
    hamiltonian H;
    topography(N, &H);
    double w[2 * kMaxModes], lambda[kMaxModes], f[2 * kMaxModes], E0, E1;
    lpi_test_random_field(N, 13, 1.0, w);
    lpi_system *sys = system_with(&H, w, "leapfrog");
    assert_int_equal(lpi_energy(sys, &E0), LPI_OK);
    const char *fn = "lpi_sine_euler_set_hamiltonian";
#define RESET() (memcpy(lambda, H.lambda, sizeof lambda), memcpy(f, H.f, sizeof f))
#define REFUSED(call, status)                          \
    do {                                               \
        LPI_ASSERT_FAILS(sys, call, status, fn);       \
        assert_int_equal(lpi_energy(sys, &E1), LPI_OK); \
        assert_memory_equal(&E0, &E1, sizeof E0);      \
        RESET();                                       \
    } while (0)
    RESET();
    LPI_ASSERT_FAILS(NULL, lpi_sine_euler_set_hamiltonian(NULL, lambda, n2, f, n), LPI_ERR_NULL, fn);
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, NULL, n2, f, n), LPI_ERR_NULL);
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, NULL, n), LPI_ERR_NULL);
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2 - 1, f, n), LPI_ERR_SIZE);
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n2), LPI_ERR_SIZE);
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, SIZE_MAX, f, n), LPI_ERR_SIZE);
    lambda[10] = NAN;
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_NONFINITE);
    lambda[mirror(10, N)] = INFINITY;
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_NONFINITE);
    f[2 * 10 + 1] = -INFINITY;
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_NONFINITE);
    lambda[10] *= 1.5; /* lambda_{-n} != lambda_n */
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_INVALID);
    f[2 * 10 + 1] += 0.5; /* f_{-n} != conj(f_n) */
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_INVALID);
    f[2 * 10] = f[2 * mirror(10, N)] = 0;
    f[2 * 10 + 1] = f[2 * mirror(10, N) + 1] = 1.0; /* f_{-n} = f_n, not its conjugate */
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_INVALID);
    /* The zero mode's entries are ignored, whatever they hold. */
    lambda[0] = 1e300, f[0] = -7, f[1] = 3;
    assert_int_equal(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_OK);
    assert_int_equal(lpi_energy(sys, &E1), LPI_OK);
    assert_memory_equal(&E0, &E1, sizeof E0);
    /* Ignored, but still numbers: a NaN or an infinity there is refused like
     * any other (it was taken silently). */
    lambda[0] = NAN;
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_NONFINITE);
    assert_non_null(strstr(lpi_last_error(sys), "lambda of mode (0, 0)"));
    f[1] = -INFINITY;
    REFUSED(lpi_sine_euler_set_hamiltonian(sys, lambda, n2, f, n), LPI_ERR_NONFINITE);
    /* Another kind of system. */
    lpi_system *rigid = NULL;
    assert_int_equal(lpi_rigid_body_create(&rigid, 1, 2, 3), LPI_OK);
    LPI_ASSERT_FAILS(rigid, lpi_sine_euler_set_hamiltonian(rigid, lambda, n2, f, n),
                     LPI_ERR_UNSUPPORTED, fn);
    double psi[kMaxModes], e[8], z[8];
    size_t shells;
    LPI_ASSERT_FAILS(rigid, lpi_sine_euler_get_stream(rigid, psi, n2), LPI_ERR_UNSUPPORTED,
                     "lpi_sine_euler_get_stream");
    LPI_ASSERT_FAILS(rigid, lpi_sine_euler_spectrum(rigid, e, z, 8, &shells), LPI_ERR_UNSUPPORTED,
                     "lpi_sine_euler_spectrum");
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_get_stream(sys, psi, n2 + 1), LPI_ERR_SIZE,
                     "lpi_sine_euler_get_stream");
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_get_stream(sys, NULL, n2), LPI_ERR_NULL,
                     "lpi_sine_euler_get_stream");
    lpi_destroy(rigid);
    lpi_destroy(sys);
#undef REFUSED
#undef RESET
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_is_eq5_for_euler),
        cmocka_unit_test(test_measured_orders),
        cmocka_unit_test(test_every_method_uses_the_hamiltonian),
        cmocka_unit_test(test_energy_is_h),
        cmocka_unit_test(test_spectrum_kept),
        cmocka_unit_test(test_single_line_steady_for_any_lambda),
        cmocka_unit_test(test_explicit_default_is_the_default),
        cmocka_unit_test(test_checkpoint_carries_the_hamiltonian),
        cmocka_unit_test(test_stream_function_and_spectrum),
        cmocka_unit_test(test_bad_hamiltonian_is_refused),
    };
    return lpi_run_tests(tests);
}
