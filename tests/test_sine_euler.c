/* Sine-Euler against an independent matrix-form integration, invariants,
 * orders, steady states, the paper's Figure 2 run, and the API contract.
 * The references here are written from the mathematics (DESIGN.md section 1)
 * and share no code with the library. */
#include <complex.h>
#include <float.h>
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "lpi_test.h"

typedef double complex cplx;

/* A reproducible Hermitian field with w_0 = 0 and spectrum ~ 1/|m|^2 decay. */
static void random_field(int N, unsigned seed, double *w) {
    lpi_test_random_field(N, 0x9E3779B97F4A7C15ull ^ seed, 1.0, w);
}

static double seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double max_abs_diff(const double *a, const double *b, size_t n) {
    double d = 0;
    for (size_t i = 0; i < n; ++i) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

/* ---- independent references ------------------------------------------- */

/* Eq. 5 of the paper, summed directly: O(N^4). */
static void eq5_rate(int N, const cplx *w, cplx *rate) {
    const double eps = 2 * M_PI / N;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            cplx sum = 0;
            for (int n1 = 0; n1 < N; ++n1)
                for (int n2 = 0; n2 < N; ++n2) {
                    const int r1 = lpi_test_centred(n1, N), r2 = lpi_test_centred(n2, N);
                    if (r1 == 0 && r2 == 0) continue;
                    const double cross = (double)lpi_test_centred(a, N) * r2 - (double)lpi_test_centred(b, N) * r1;
                    sum += sin(eps * cross) / (eps * (r1 * r1 + r2 * r2)) *
                           w[lpi_test_mod(a + n1, N) * N + lpi_test_mod(b + n2, N)] * w[lpi_test_mod(-n1, N) * N + lpi_test_mod(-n2, N)];
                }
            rate[a * N + b] = sum;
        }
}

/* W = sum_m w_m J_m, J_m = exp(2 pi i m1 m2/N) g^m1 h^m2, g = diag(q^a),
 * q = exp(4 pi i/N), h e_a = e_{a-1}: built entry by entry from the definition. */
static void to_matrix(int N, const cplx *w, cplx *W) {
    memset(W, 0, sizeof(cplx) * N * N);
    for (int m1 = 0; m1 < N; ++m1)
        for (int m2 = 0; m2 < N; ++m2) {
            const cplx phase = cexp(2 * M_PI * I * m1 * m2 / N);
            for (int b = 0; b < N; ++b) {
                const int a = lpi_test_mod(b - m2, N); /* h^m2 e_b = e_{b-m2}, then g^m1 */
                W[a * N + b] += w[m1 * N + m2] * phase * cexp(4 * M_PI * I * (double)m1 * a / N);
            }
        }
}

/* w_m = tr(W J_m^dagger) / N. */
static void from_matrix(int N, const cplx *W, cplx *w) {
    for (int m1 = 0; m1 < N; ++m1)
        for (int m2 = 0; m2 < N; ++m2) {
            const cplx phase = cexp(2 * M_PI * I * m1 * m2 / N);
            cplx sum = 0;
            for (int b = 0; b < N; ++b) {
                const int a = lpi_test_mod(b - m2, N);
                sum += W[a * N + b] * conj(phase * cexp(4 * M_PI * I * (double)m1 * a / N));
            }
            w[m1 * N + m2] = sum / N;
        }
}

/* dW/dt = (i / (2 eps)) [P, W], P = sum_{n != 0} w_n / |n|^2 J_n. */
static void matrix_rate(int N, const cplx *W, cplx *dW) {
    cplx *w = malloc(sizeof(cplx) * N * N), *P = malloc(sizeof(cplx) * N * N);
    from_matrix(N, W, w);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int n2 = lpi_test_centred(a, N) * lpi_test_centred(a, N) + lpi_test_centred(b, N) * lpi_test_centred(b, N);
            w[a * N + b] = n2 ? w[a * N + b] / n2 : 0;
        }
    to_matrix(N, w, P);
    const double eps = 2 * M_PI / N;
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
            cplx c = 0;
            for (int k = 0; k < N; ++k) c += P[i * N + k] * W[k * N + j] - W[i * N + k] * P[k * N + j];
            dW[i * N + j] = I / (2 * eps) * c;
        }
    free(w);
    free(P);
}

/* RK4 on the matrix form from modes w0 for time T in `steps` steps. */
static void matrix_rk4(int N, const double *w0, double T, int steps, double *w_out) {
    const size_t n = (size_t)N * N;
    cplx *W = malloc(sizeof(cplx) * n), *Y = malloc(sizeof(cplx) * n), *k[4];
    for (int i = 0; i < 4; ++i) k[i] = malloc(sizeof(cplx) * n);
    to_matrix(N, (const cplx *)w0, W);
    const double h = T / steps;
    for (int s = 0; s < steps; ++s) {
        matrix_rate(N, W, k[0]);
        for (size_t i = 0; i < n; ++i) Y[i] = W[i] + 0.5 * h * k[0][i];
        matrix_rate(N, Y, k[1]);
        for (size_t i = 0; i < n; ++i) Y[i] = W[i] + 0.5 * h * k[1][i];
        matrix_rate(N, Y, k[2]);
        for (size_t i = 0; i < n; ++i) Y[i] = W[i] + h * k[2][i];
        matrix_rate(N, Y, k[3]);
        for (size_t i = 0; i < n; ++i) W[i] += h / 6 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
    }
    from_matrix(N, W, (cplx *)w_out);
    free(W);
    free(Y);
    for (int i = 0; i < 4; ++i) free(k[i]);
}

static lpi_system *sine_euler(int N, const double *w) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_sine_euler_create(&sys, N), LPI_OK);
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * (size_t)N * N), LPI_OK);
    return sys;
}

/* Integrates from w0 with `steps` steps of `method` to time T; modes to out. */
static void run(int N, const char *method, const double *w0, double T, int64_t steps, double *out) {
    lpi_system *sys = sine_euler(N, w0);
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    assert_int_equal(lpi_step(sys, T / (double)steps, steps), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, out, 2 * (size_t)N * N), LPI_OK);
    lpi_destroy(sys);
}

/* ---- the formulas ------------------------------------------------------ */

/* The matrix form used as the reference is eq. 5 (checked before it is trusted). */
static void test_matrix_form_is_eq5(void **state) {
    (void)state;
    const int Ns[] = {5, 7, 9};
    for (int t = 0; t < 3; ++t) {
        const int N = Ns[t];
        const size_t n = (size_t)N * N;
        double w[2 * 81];
        random_field(N, 7 + N, w);
        cplx W[81], dW[81], rate_matrix[81], rate_direct[81];
        to_matrix(N, (const cplx *)w, W);
        /* W is Hermitian and the map inverts. */
        cplx back[81];
        from_matrix(N, W, back);
        for (int i = 0; i < N; ++i)
            for (int j = 0; j < N; ++j) assert_true(cabs(W[i * N + j] - conj(W[j * N + i])) < 1e-14);
        assert_true(max_abs_diff((const double *)back, w, 2 * n) < 1e-15);
        matrix_rate(N, W, dW);
        from_matrix(N, dW, rate_matrix);
        eq5_rate(N, (const cplx *)w, rate_direct);
        assert_true(max_abs_diff((const double *)rate_matrix, (const double *)rate_direct, 2 * n) < 1e-14);
    }
}

/* One step of size h against the matrix-form RK4 with tiny steps: the local
 * error falls like h^(p+1) for a method of order p, prime and composite N. */
static void test_one_step_against_matrix_rk4(void **state) {
    (void)state;
    const int Ns[] = {7, 9, 15};
    const struct {
        const char *method;
        int order;
    } methods[] = {{"leapfrog", 2}, {"triple-jump-4", 4}};
    for (int t = 0; t < 3; ++t) {
        const int N = Ns[t];
        const size_t n = 2 * (size_t)N * N;
        double w0[2 * 225], ours[2 * 225], ref[2 * 225];
        random_field(N, 100 + N, w0);
        for (int m = 0; m < 2; ++m) {
            double err[2];
            const double hs[2] = {0.2, 0.1};
            for (int i = 0; i < 2; ++i) {
                run(N, methods[m].method, w0, hs[i], 1, ours);
                matrix_rk4(N, w0, hs[i], 40, ref);
                err[i] = max_abs_diff(ours, ref, n);
            }
            const double order = log(err[0] / err[1]) / log(2.0) - 1;
            printf("N = %2d %-14s one-step errors %.3e %.3e, local order + 1 = %.2f\n", N,
                   methods[m].method, err[0], err[1], order + 1);
            assert_true(fabs(order - methods[m].order) < 0.35);
            assert_true(err[1] < 1e-3);
        }
    }
}

/* Measured global orders at N = 7: leapfrog 2, triple jump 4. */
static void test_measured_orders(void **state) {
    (void)state;
    const int N = 7;
    const size_t n = 2 * N * N;
    double w0[2 * 49], ref[2 * 49], ours[2 * 49];
    random_field(N, 3, w0);
    for (size_t i = 0; i < n; ++i) w0[i] *= 4.0; /* O(1) dynamics over T = 1 */
    const double T = 1.0;
    matrix_rk4(N, w0, T, 2000, ref);
    const struct {
        const char *method;
        int order;
        int64_t steps[4];
    } cases[] = {{"leapfrog", 2, {8, 16, 32, 64}}, {"triple-jump-4", 4, {4, 8, 16, 32}}};
    for (int c = 0; c < 2; ++c) {
        double hs[4], errs[4];
        for (int i = 0; i < 4; ++i) {
            run(N, cases[c].method, w0, T, cases[c].steps[i], ours);
            hs[i] = T / (double)cases[c].steps[i];
            errs[i] = max_abs_diff(ours, ref, n);
        }
        const double order = lpi_fit_order(hs, errs, 4);
        printf("%-14s errors %.2e .. %.2e, measured order %.2f\n", cases[c].method, errs[0],
               errs[3], order);
        assert_true(fabs(order - cases[c].order) < 0.3);
    }
}

/* N = 111 = 3 x 37: composite with a large factor, so besides the row and
 * column directions it has general ones (both components non-units), and
 * M = 55 lines make three full blocks of 16 and a remainder. One leapfrog
 * step against the matrix-form RK4 has local order 3: every mode of every
 * line is moved, and moved right. */
static void test_one_step_composite_large_factor(void **state) {
    (void)state;
    const int N = 111;
    const size_t n = 2 * (size_t)N * N;
    double *w0 = malloc(sizeof(double) * n), *ours = malloc(sizeof(double) * n),
           *ref = malloc(sizeof(double) * n);
    random_field(N, 5, w0);
    double err[2];
    const double hs[2] = {0.1, 0.05};
    for (int i = 0; i < 2; ++i) {
        run(N, "leapfrog", w0, hs[i], 1, ours);
        matrix_rk4(N, w0, hs[i], 5, ref);
        err[i] = max_abs_diff(ours, ref, n);
    }
    const double order = log(err[0] / err[1]) / log(2.0);
    printf("N = 111 leapfrog one-step errors %.3e %.3e, local order %.2f\n", err[0], err[1], order);
    assert_true(fabs(order - 3) < 0.3);
    free(w0);
    free(ours);
    free(ref);
}

/* ---- invariants -------------------------------------------------------- */

/* Long enough that a bias of 3e-17 per flow (63 flows a step at N = 31)
 * would move the spectrum by 8e-12, eight times the bound below. */
#define LPI_LONG_RUN_STEPS 4000

/* Largest change of an eigenvalue of W over `steps` steps of `method`,
 * relative to the largest |eigenvalue|; skips when built without LAPACK. */
static double spectrum_drift(int N, int64_t steps, double dt, const char *method) {
    const size_t n = 2 * (size_t)N * N;
    double *w = malloc(sizeof(double) * n);
    double before[64], after[64];
    random_field(N, 11 * N, w);
    lpi_system *sys = sine_euler(N, w);
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    assert_int_equal(lpi_casimir_count(sys), (size_t)N);
    int status = lpi_casimirs(sys, before, N);
    if (status == LPI_ERR_UNSUPPORTED) {
        assert_non_null(strstr(lpi_last_error(sys), "LAPACK"));
        lpi_destroy(sys);
        free(w);
        LPI_SKIP("built without LAPACK: no Casimir spectrum to check");
    }
    assert_int_equal(status, LPI_OK);
    double H0, H1;
    assert_int_equal(lpi_energy(sys, &H0), LPI_OK);
    assert_int_equal(lpi_step(sys, dt, steps), LPI_OK);
    assert_int_equal(lpi_casimirs(sys, after, N), LPI_OK);
    assert_int_equal(lpi_energy(sys, &H1), LPI_OK);
    double scale = 0, drift = 0;
    for (int i = 0; i < N; ++i) {
        scale = fmax(scale, fabs(before[i]));
        drift = fmax(drift, fabs(after[i] - before[i]));
        if (i) assert_true(after[i] >= after[i - 1]); /* sorted */
    }
    printf("N = %d, %lld %s steps of %g: spectrum drift %.2e relative, %.2e per step; energy "
           "error %.1e\n",
           N, (long long)steps, method, dt, drift / scale, drift / scale / (double)steps,
           fabs(H1 - H0) / H0);
    lpi_destroy(sys);
    free(w);
    return drift / scale;
}

/* The flows are unitary and applied without a systematic rescaling, so the
 * Casimirs only wander with round-off of either sign: over 4000 leapfrog
 * steps the spectrum moves by at most 1e-12 (a bias of 3e-17 per flow, 63
 * flows a step, would move it by 8e-12). Prime and composite N. */
static void test_spectrum_kept_n31(void **state) {
    (void)state;
    assert_true(spectrum_drift(31, LPI_LONG_RUN_STEPS, 0.05, "leapfrog") <= 1e-12);
}

static void test_spectrum_kept_n25_composite(void **state) {
    (void)state;
    assert_true(spectrum_drift(25, LPI_LONG_RUN_STEPS, 0.05, "leapfrog") <= 1e-12);
}

/* Modes all on one line through the origin: every piece is then either the
 * line's own (which leaves it fixed) or sees b = 0: a steady state. */
static void test_single_line_is_steady(void **state) {
    (void)state;
    const int N = 31;
    const size_t n = 2 * N * N;
    double w[2 * 961], out[2 * 961];
    memset(w, 0, sizeof w);
    const int k[2] = {2, 5};
    for (int s = 1; s <= N / 2; ++s) {
        const int a = lpi_test_mod(s * k[0], N), b = lpi_test_mod(s * k[1], N);
        const double re = cos(s), im = sin(3.0 * s) / s;
        w[2 * (a * N + b)] = re, w[2 * (a * N + b) + 1] = im;
        w[2 * (lpi_test_mod(-a, N) * N + lpi_test_mod(-b, N))] = re, w[2 * (lpi_test_mod(-a, N) * N + lpi_test_mod(-b, N)) + 1] = -im;
    }
    w[0] = 0.25; /* the inert mean is kept as given */
    lpi_system *sys = sine_euler(N, w);
    assert_int_equal(lpi_step(sys, 0.1, 100), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, out, n), LPI_OK);
    const double change = max_abs_diff(out, w, n);
    printf("single-line field after 100 steps: max change %.2e\n", change);
    assert_true(change == 0); /* every increment is exactly zero */
    assert_true(out[0] == 0.25 && out[1] == 0.0);
    lpi_destroy(sys);
}

/* McLachlan 1993, Figure 2: N = 7, dt = 0.05, 10^5 steps, |w| = 1 and
 * H(0) = 0.75. |w| is the norm over one mode of each pair +-m (w_0 = 0):
 * over all modes sum |w_m|^2 = 2, and then H <= 1 allows H(0) = 0.75 (with the
 * norm over all modes H <= 1/2 and the paper's H(0) could not be reached).
 * The field mixes the |m| = 1 modes and the others in the proportion that
 * gives H(0) = 0.75 exactly. */
static void figure2_field(double *w) {
    const int N = 7;
    double low[2 * 49], high[2 * 49];
    random_field(N, 2024, w);
    memcpy(low, w, sizeof low);
    memcpy(high, w, sizeof high);
    double low_norm = 0, high_norm = 0, high_energy = 0; /* over the half plane */
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int n2 = lpi_test_centred(a, N) * lpi_test_centred(a, N) + lpi_test_centred(b, N) * lpi_test_centred(b, N);
            const int i = a * N + b;
            const double p = w[2 * i] * w[2 * i] + w[2 * i + 1] * w[2 * i + 1];
            if (n2 == 1) {
                high[2 * i] = high[2 * i + 1] = 0;
                low_norm += 0.5 * p;
            } else {
                low[2 * i] = low[2 * i + 1] = 0;
                if (n2) high_norm += 0.5 * p, high_energy += 0.5 * p / n2;
            }
        }
    /* alpha^2 + beta^2 = 1 and alpha^2 * 1 + beta^2 * e_high = 0.75 */
    const double e_high = high_energy / high_norm;
    const double alpha2 = (0.75 - e_high) / (1 - e_high);
    const double alpha = sqrt(alpha2 / low_norm), beta = sqrt((1 - alpha2) / high_norm);
    for (int i = 0; i < 2 * 49; ++i) w[i] = alpha * low[i] + beta * high[i];
}

static void test_paper_figure2(void **state) {
    (void)state;
    const int N = 7;
    double w[2 * 49];
    figure2_field(w);
    lpi_system *sys = sine_euler(N, w);
    double H0, enstrophy, traces[2];
    assert_int_equal(lpi_energy(sys, &H0), LPI_OK);
    assert_int_equal(lpi_sine_euler_enstrophy(sys, &enstrophy), LPI_OK);
    assert_true(fabs(H0 - 0.75) < 1e-14);
    assert_true(fabs(enstrophy - 1.0) < 1e-14); /* 1/2 sum over all = sum over half */
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 2, traces), LPI_OK);
    const double C2_start = traces[1];
    assert_true(fabs(C2_start - 2.0) < 1e-13); /* (1/N) tr W^2 = sum |w_m|^2 */
    double lambda0[7], lambda1[7];
    const int have_spectrum = lpi_casimirs(sys, lambda0, N) == LPI_OK;

    const int chunks = 100, per_chunk = 1000;
    double worst[2] = {0, 0}; /* max |dH/H| over the first and the second half */
    for (int c = 0; c < chunks; ++c) {
        assert_int_equal(lpi_step(sys, 0.05, per_chunk), LPI_OK);
        double H;
        assert_int_equal(lpi_energy(sys, &H), LPI_OK);
        const double rel = fabs(H - H0) / H0;
        worst[c < chunks / 2] = fmax(worst[c < chunks / 2], rel);
    }
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 2, traces), LPI_OK);
    const double steps = (double)chunks * per_chunk;
    const double c2_per_step = fabs(traces[1] - C2_start) / C2_start / steps;
    double spectrum_per_step = 0;
    if (have_spectrum) {
        assert_int_equal(lpi_casimirs(sys, lambda1, N), LPI_OK);
        double scale = 0, drift = 0;
        for (int i = 0; i < N; ++i)
            scale = fmax(scale, fabs(lambda0[i])), drift = fmax(drift, fabs(lambda1[i] - lambda0[i]));
        spectrum_per_step = drift / scale / steps;
    }
    printf("Figure 2 (N = 7, dt = 0.05, 1e5 steps, |w| = 1, H(0) = 0.75): max |dH/H| first half "
           "%.3e, second half %.3e; C2 drift %.2e per step, spectrum drift %.2e per step\n",
           worst[1], worst[0], c2_per_step, spectrum_per_step);
    assert_true(worst[1] > 0 && worst[1] < 0.05);
    assert_true(worst[0] < 1.5 * worst[1]); /* bounded: no secular growth */
    assert_true(c2_per_step < 5e-16); /* the paper saw about 5e-15 */
    assert_true(spectrum_per_step < 5e-16);
    lpi_destroy(sys);
}

/* ---- state, grid, diagnostics ------------------------------------------- */

static void test_modes_grid_and_state_round_trips(void **state) {
    (void)state;
    const int N = 9;
    const size_t n = (size_t)N * N;
    double w[2 * 81], back[2 * 81], grid[81], x[81], x2[81], direct[81];
    random_field(N, 5, w);
    w[0] = -0.5;
    lpi_system *sys = sine_euler(N, w);
    assert_int_equal(lpi_dim(sys), n);
    assert_int_equal(lpi_sine_euler_get_modes(sys, back, 2 * n), LPI_OK);
    assert_memory_equal(back, w, sizeof back);
    /* the real parametrisation: get_state then set_state restores the modes */
    assert_int_equal(lpi_get_state(sys, x, n), LPI_OK);
    assert_true(x[0] == -0.5 && x[1] == w[2 * 1] && x[2] == w[2 * 1 + 1]); /* w_0, then w_(0,1) */
    assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK);
    assert_int_equal(lpi_set_state(sys, x, n), LPI_OK);
    assert_int_equal(lpi_get_state(sys, x2, n), LPI_OK);
    assert_memory_equal(x, x2, sizeof x);
    assert_int_equal(lpi_sine_euler_get_modes(sys, back, 2 * n), LPI_OK);
    assert_memory_equal(back, w, sizeof back);
    /* the grid is sum_m w_m exp(i (m1 x + m2 y)) */
    assert_int_equal(lpi_sine_euler_get_grid(sys, grid, n), LPI_OK);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            cplx s = 0;
            for (int m1 = 0; m1 < N; ++m1)
                for (int m2 = 0; m2 < N; ++m2)
                    s += ((const cplx *)w)[m1 * N + m2] * cexp(I * 2 * M_PI * (m1 * a + m2 * b) / N);
            direct[a * N + b] = creal(s);
        }
    assert_true(max_abs_diff(grid, direct, n) < 1e-14);
    assert_int_equal(lpi_sine_euler_set_grid(sys, grid, n), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, back, 2 * n), LPI_OK);
    assert_true(max_abs_diff(back, w, 2 * n) < 1e-15);
    int32_t size = 0;
    assert_int_equal(lpi_sine_euler_size(sys, &size), LPI_OK);
    assert_int_equal(size, N);
    /* Modes the library gave back are taken back, however large: a mode
     * and its mirror near DBL_MAX are averaged without overflow. */
    for (size_t i = 0; i < n; ++i) x[i] = i % 3 == 1 ? 1.7e308 : i % 3 == 2 ? -DBL_MAX : 0.0;
    assert_int_equal(lpi_set_state(sys, x, n), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_modes(sys, back, 2 * n), LPI_OK);
    assert_int_equal(lpi_sine_euler_set_modes(sys, back, 2 * n), LPI_OK);
    assert_int_equal(lpi_get_state(sys, x2, n), LPI_OK);
    assert_memory_equal(x, x2, sizeof x);
    lpi_destroy(sys);
}

static void test_traces_match_spectrum(void **state) {
    (void)state;
    const int N = 11;
    double w[2 * 121], lambda[11], traces[5];
    random_field(N, 9, w);
    w[0] = 0.3;
    lpi_system *sys = sine_euler(N, w);
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 5, traces), LPI_OK);
    assert_true(fabs(traces[0] - 0.3) < 1e-15); /* (1/N) tr W = w_0 */
    const int have_spectrum = lpi_casimirs(sys, lambda, N) == LPI_OK;
    if (have_spectrum) {
        for (int k = 1; k <= 5; ++k) {
            double s = 0;
            for (int i = 0; i < N; ++i) s += pow(lambda[i], k);
            assert_true(fabs(s / N - traces[k - 1]) < 1e-13 * (1 + fabs(traces[k - 1])));
        }
    } else {
        assert_non_null(strstr(lpi_last_error(sys), "LAPACK"));
    }
    lpi_destroy(sys);
    if (!have_spectrum) LPI_SKIP("built without LAPACK: no spectrum to compare the traces with");
}

/* Past a power of W that is exactly zero every trace is 0, and a trace that
 * overflows stops the call there, naming it, with out untouched: neither
 * needs the later powers (each N^3 operations) nor a list of kmax values. */
static void test_traces_past_zero_and_overflow(void **state) {
    (void)state;
    const int N = 5;
    static double traces[1 << 16], first[5];
    double w[2 * 25];
    random_field(N, 4, w);
    for (int i = 0; i < 2 * 25; ++i) w[i] *= 1e-3;
    w[0] = 0.0;
    lpi_system *sys = sine_euler(N, w);
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 5, first), LPI_OK);
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 400, traces), LPI_OK);
    assert_memory_equal(traces, first, sizeof first);
    assert_true(traces[1] > 0.0); /* (1/N) tr W^2 = 2 x enstrophy / N */
    int zero_from = 400;
    while (zero_from > 0 && traces[zero_from - 1] == 0.0) --zero_from;
    assert_true(zero_from > 5 && zero_from < 200); /* |W| ~ 1e-3: W^k underflows near k = 108 */
    for (int k = zero_from; k < 400; ++k) assert_true(traces[k] == 0.0 && !signbit(traces[k]));
    /* W = 0: every trace 0. */
    for (int i = 0; i < 2 * 25; ++i) w[i] = 0.0;
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * 25), LPI_OK);
    traces[7] = 1.0;
    assert_int_equal(lpi_sine_euler_casimir_traces(sys, 1 << 16, traces), LPI_OK);
    for (int k = 0; k < 1 << 16; ++k) assert_true(traces[k] == 0.0);
    /* w_0 = 1e300: (1/N) tr W = 1e300, tr W^2 overflows. */
    random_field(N, 4, w);
    w[0] = 1e300;
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * 25), LPI_OK);
    for (int k = 0; k < 1 << 16; ++k) traces[k] = -7.0;
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_casimir_traces(sys, 1 << 16, traces), LPI_ERR_OVERFLOW,
                     "lpi_sine_euler_casimir_traces");
    assert_non_null(strstr(lpi_last_error(sys), "tr W^2 "));
    for (int k = 0; k < 1 << 16; ++k) assert_true(traces[k] == -7.0);
    lpi_destroy(sys);
}

/* A Hermitian field given by a formula, so that a large one can be checked
 * entry by entry without a second copy: w(a, b) = conj(w(-a, -b)). */
static double formula_part(int a, int b, int N, int imaginary) {
    const uint64_t key = ((uint64_t)a * 2654435761u + (uint64_t)b * 40503u + (uint64_t)N) * 2 +
                         (uint64_t)imaginary;
    return (double)((key * 0x9E3779B97F4A7C15ull) >> 11) / 9007199254740992.0 - 0.5;
}
static void formula_mode(int a, int b, int N, double *re, double *im) {
    const int ma = a ? N - a : 0, mb = b ? N - b : 0;
    *re = formula_part(a, b, N, 0) + formula_part(ma, mb, N, 0);
    *im = formula_part(a, b, N, 1) - formula_part(ma, mb, N, 1);
}

/* An N whose system needs more bytes than the machine has is refused with
 * LPI_ERR_NO_MEMORY, naming the bytes, before anything is allocated (it would
 * be zero-filled: the out-of-memory killer, not an error). N = 4097 =
 * 17 x 241 (composite, a large factor; 2 x 268 MB of working states) is
 * created at once and its modes round-trip to the bit. No step: too slow. */
static void test_large_n(void **state) {
    (void)state;
    const double physical = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    const int32_t huge[] = {100001, 1000001, INT32_MAX};
    for (size_t i = 0; i < sizeof huge / sizeof huge[0]; ++i) {
        const double needs = 32.0 * huge[i] * huge[i]; /* two states of 2 N^2 doubles */
        if (physical > 0 && needs <= physical) {
            printf("N = %d: this machine has %.3g bytes, enough; not tried\n", huge[i], physical);
            continue;
        }
        lpi_system *sys = (lpi_system *)0x1;
        const double t0 = seconds();
        LPI_ASSERT_FAILS(NULL, lpi_sine_euler_create(&sys, huge[i]), LPI_ERR_NO_MEMORY,
                         "lpi_sine_euler_create");
        printf("N = %d refused in %.1e s: %s\n", huge[i], seconds() - t0,
               lpi_last_error(NULL));
        assert_null(sys);
        assert_non_null(strstr(lpi_last_error(NULL), "bytes"));
    }

    const int N = 4097;
    const size_t n = 2 * (size_t)N * N;
    lpi_system *sys = NULL;
    const double t0 = seconds();
    assert_int_equal(lpi_sine_euler_create(&sys, N), LPI_OK);
    printf("N = %d created in %.2f s\n", N, seconds() - t0);
    double *w = malloc(sizeof(double) * n);
    assert_non_null(w);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) formula_mode(a, b, N, &w[2 * ((size_t)a * N + b)], &w[2 * ((size_t)a * N + b) + 1]);
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, n), LPI_OK);
    memset(w, 0, sizeof(double) * n);
    assert_int_equal(lpi_sine_euler_get_modes(sys, w, n), LPI_OK);
    size_t wrong = 0;
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            double re, im;
            formula_mode(a, b, N, &re, &im);
            wrong += w[2 * ((size_t)a * N + b)] != re || w[2 * ((size_t)a * N + b) + 1] != im;
        }
    assert_int_equal(wrong, 0);
    free(w);
    lpi_destroy(sys);
}

/* Results do not depend on the thread count, to the bit: N = 61 (prime: Row
 * directions, two blocks of lines), N = 45 (Row, Column and General
 * directions) and N = 135 (five blocks, a ring of buffers that wraps), on 2
 * to 6 threads: one thread moving the blocks the others transform (up to 4),
 * each thread its own blocks (5 and 6, where the machine allows them), and
 * more threads than blocks. */
static void test_threads_bitwise(void **state) {
    (void)state;
    int refused = 0;
    const int sizes[] = {61, 45, 135};
    for (int k = 0; k < 3 && !refused; ++k) {
        const int N = sizes[k];
        const size_t n = 2 * (size_t)N * N;
        double *w = malloc(sizeof(double) * n), *one = malloc(sizeof(double) * n),
               *many = malloc(sizeof(double) * n);
        random_field(N, 1, w);
        lpi_system *a = sine_euler(N, w);
        assert_int_equal(lpi_step(a, 0.05, 3), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(a, one, n), LPI_OK);
        for (int threads = 2; threads <= 6 && !refused; ++threads) {
            lpi_system *b = sine_euler(N, w);
            const int status = lpi_set_threads(b, threads);
            refused = status == LPI_ERR_UNSUPPORTED;
            if (status == LPI_ERR_INVALID && threads > 4) {  /* beyond this machine's bound */
                lpi_destroy(b);
                break;
            }
            if (refused) {
                assert_non_null(strstr(lpi_last_error(b), "OpenMP"));
            } else {
                assert_int_equal(status, LPI_OK);
                assert_int_equal(lpi_step(b, 0.05, 3), LPI_OK);
                assert_int_equal(lpi_sine_euler_get_modes(b, many, n), LPI_OK);
                assert_memory_equal(one, many, sizeof(double) * n);
            }
            lpi_destroy(b);
        }
        lpi_destroy(a);
        free(w);
        free(one);
        free(many);
    }
    if (refused) LPI_SKIP("built without OpenMP: one thread only, nothing to compare");
}

/* Separate handles on separate threads (plans are made concurrently; the
 * library serialises FFTW's planner) give the same result as one thread, to
 * round-off (FFTW_MEASURE may pick another plan when timings differ). */
typedef struct {
    int N;
    double *out;
} worker_job;

static void *worker(void *arg) {
    worker_job *job = arg;
    const size_t n = 2 * (size_t)job->N * job->N;
    double *w = malloc(sizeof(double) * n);
    random_field(job->N, 77, w);
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, job->N) == LPI_OK && lpi_sine_euler_set_modes(sys, w, n) == LPI_OK &&
        lpi_step(sys, 0.05, 5) == LPI_OK)
        lpi_sine_euler_get_modes(sys, job->out, n);
    lpi_destroy(sys);
    free(w);
    return NULL;
}

static void test_handles_on_threads(void **state) {
    (void)state;
    enum { workers = 4 };
    const int Ns[workers] = {27, 29, 27, 29};
    double *outs[workers];
    pthread_t threads[workers];
    worker_job jobs[workers];
    for (int i = 0; i < workers; ++i) {
        outs[i] = calloc(2 * (size_t)Ns[i] * Ns[i], sizeof(double));
        jobs[i] = (worker_job){Ns[i], outs[i]};
        assert_int_equal(pthread_create(&threads[i], NULL, worker, &jobs[i]), 0);
    }
    for (int i = 0; i < workers; ++i) assert_int_equal(pthread_join(threads[i], NULL), 0);
    for (int i = 0; i < workers; ++i) {
        const size_t n = 2 * (size_t)Ns[i] * Ns[i];
        double *alone = calloc(n, sizeof(double));
        worker_job job = {Ns[i], alone};
        worker(&job);
        assert_true(max_abs_diff(alone, outs[i], n) < 1e-13);
        assert_true(fabs(outs[i][2]) + fabs(outs[i][3]) > 0); /* the worker did run */
        free(alone);
        free(outs[i]);
    }
}

static void test_wisdom(void **state) {
    (void)state;
    size_t length = 0;
    /* A query of the length succeeds; a buffer one byte short fails. */
    int status = lpi_fftw_wisdom_export_string(NULL, 0, &length);
    assert_int_equal(status, LPI_OK);
    assert_true(length > 0);
    char *text = malloc(length + 1);
    text[0] = 'x';
    size_t short_length = 0;
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_export_string(text, length, &short_length), LPI_ERR_SIZE,
                     "lpi_fftw_wisdom_export_string");
    assert_int_equal(short_length, length);
    assert_int_equal(text[0], 'x');
    assert_int_equal(lpi_fftw_wisdom_export_string(text, length + 1, &length), LPI_OK);
    assert_int_equal(strlen(text), length);
    assert_int_equal(lpi_fftw_wisdom_import_string(text), LPI_OK);
    free(text);
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_import_string("not wisdom"), LPI_ERR_INVALID,
                     "lpi_fftw_wisdom_import_string");
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_import_file("/nonexistent/wisdom"), LPI_ERR_IO,
                     "lpi_fftw_wisdom_import_file");
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_export_file("/nonexistent/wisdom"), LPI_ERR_IO,
                     "lpi_fftw_wisdom_export_file");
    /* A file that can be read but holds no wisdom is invalid input, not I/O. */
    char path[] = "/tmp/lpi_not_wisdom_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "not wisdom\n", 11), 11);
    close(fd);
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_import_file(path), LPI_ERR_INVALID,
                     "lpi_fftw_wisdom_import_file");
    /* A FIFO is refused, not waited on. */
    assert_int_equal(unlink(path), 0);
    assert_int_equal(mkfifo(path, 0600), 0);
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_import_file(path), LPI_ERR_IO, "lpi_fftw_wisdom_import_file");
    assert_non_null(strstr(lpi_last_error(NULL), "not a regular file"));
    assert_int_equal(unlink(path), 0);
    /* A regular file that reports 0 bytes and reads on for gigabytes is
     * refused after the 64 MiB that wisdom can take, not read to its end. */
    struct stat proc;
    if (stat("/proc/self/pagemap", &proc) == 0 && S_ISREG(proc.st_mode)) {
        LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_import_file("/proc/self/pagemap"), LPI_ERR_INVALID,
                         "lpi_fftw_wisdom_import_file");
        assert_non_null(strstr(lpi_last_error(NULL), "more than"));
    }
    /* Export is atomic: a write that fails (EFBIG past a file-size limit)
     * keeps the wisdom file that was there. */
    assert_int_equal(lpi_fftw_wisdom_export_file(path), LPI_OK);
    struct stat before;
    assert_int_equal(stat(path, &before), 0);
    struct rlimit old, low;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
    low = old;
    low.rlim_cur = 8;
    void (*handler)(int) = signal(SIGXFSZ, SIG_IGN);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &low), 0);
    status = lpi_fftw_wisdom_export_file(path);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
    signal(SIGXFSZ, handler);
    assert_int_equal(status, LPI_ERR_IO);
    struct stat after;
    assert_int_equal(stat(path, &after), 0);
    assert_int_equal(after.st_size, before.st_size);
    assert_int_equal(lpi_fftw_wisdom_import_file(path), LPI_OK);
    assert_int_equal(unlink(path), 0);
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_import_file(NULL), LPI_ERR_NULL,
                     "lpi_fftw_wisdom_import_file");
}

/* The planning rigor: "estimate" by default; "measure" plans at once without
 * touching the state, and its (other) plans give the same trajectory to
 * round-off. */
static void test_planning(void **state) {
    (void)state;
    const int Ns[] = {25, 31};
    for (size_t i = 0; i < 2; ++i) {
        const int N = Ns[i];
        const size_t n = 2 * (size_t)N * N;
        double *w = malloc(sizeof(double) * n), *a = malloc(sizeof(double) * n),
               *b = malloc(sizeof(double) * n);
        random_field(N, 11u + (unsigned)i, w);
        lpi_system *estimated = sine_euler(N, w), *measured = sine_euler(N, w);
        const char *rigor = NULL;
        assert_int_equal(lpi_sine_euler_get_planning(estimated, &rigor), LPI_OK);
        assert_string_equal(rigor, "estimate");
        assert_int_equal(lpi_step(measured, 0.05, 3), LPI_OK); /* planned already */
        assert_int_equal(lpi_sine_euler_get_modes(measured, a, n), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_planning(measured, "measure"), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(measured, b, n), LPI_OK);
        assert_memory_equal(a, b, sizeof(double) * n);
        assert_int_equal(lpi_sine_euler_get_planning(measured, &rigor), LPI_OK);
        assert_string_equal(rigor, "measure");
        assert_int_equal(lpi_step(estimated, 0.05, 3), LPI_OK);
        assert_int_equal(lpi_step(estimated, 0.05, 40), LPI_OK);
        assert_int_equal(lpi_step(measured, 0.05, 40), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(estimated, a, n), LPI_OK);
        assert_int_equal(lpi_sine_euler_get_modes(measured, b, n), LPI_OK);
        double diff = 0.0, size = 0.0;
        for (size_t k = 0; k < n; ++k) {
            diff = fmax(diff, fabs(a[k] - b[k]));
            size = fmax(size, fabs(a[k]));
        }
        assert_true(diff <= 1e-13 * size);
        lpi_destroy(estimated);
        lpi_destroy(measured);
        free(w), free(a), free(b);
    }
}

/* ---- bad input ----------------------------------------------------------- */

static void test_bad_input(void **state) {
    (void)state;
    lpi_system *sys = (lpi_system *)0x1;
    const int32_t bad_N[] = {4, 2, 1, 0, -3, 100};
    for (size_t i = 0; i < sizeof bad_N / sizeof bad_N[0]; ++i) {
        sys = (lpi_system *)0x1;
        LPI_ASSERT_FAILS(NULL, lpi_sine_euler_create(&sys, bad_N[i]), LPI_ERR_INVALID,
                         "lpi_sine_euler_create");
        assert_null(sys);
    }
    LPI_ASSERT_FAILS(NULL, lpi_sine_euler_create(NULL, 7), LPI_ERR_NULL, "lpi_sine_euler_create");

    const int N = 7;
    const size_t n = (size_t)N * N;
    double w[2 * 49], bad[2 * 49], grid[49];
    random_field(N, 42, w);
    sys = sine_euler(N, w);
    assert_int_equal(lpi_step(sys, 0.1, 2), LPI_OK); /* a nonzero time to keep */

    memcpy(bad, w, sizeof w);
    bad[2 * (1 * N + 2) + 1] += 1e-3; /* w_(1,2) no longer conj(w_(-1,-2)) */
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, bad, 2 * n), LPI_ERR_INVALID,
                     "lpi_sine_euler_set_modes");
    assert_non_null(strstr(lpi_last_error(sys), "Hermitian"));
    memcpy(bad, w, sizeof w);
    bad[1] = 0.5; /* w_0 not real */
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, bad, 2 * n), LPI_ERR_INVALID,
                     "lpi_sine_euler_set_modes");
    memcpy(bad, w, sizeof w);
    bad[17] = NAN;
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, bad, 2 * n), LPI_ERR_NONFINITE,
                     "lpi_sine_euler_set_modes");
    bad[17] = INFINITY;
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, bad, 2 * n), LPI_ERR_NONFINITE,
                     "lpi_sine_euler_set_modes");
    /* a tiny asymmetry (round-off of an FFT) is accepted and symmetrised */
    memcpy(bad, w, sizeof w);
    bad[2 * (1 * N + 2)] += 1e-17;
    lpi_system *other = sine_euler(N, bad);
    /* The tolerance is 1e-10 max |w_m| (a modulus): for w_(0,1) = 1 + i,
     * sqrt(2) 1e-10. It was 1e-10 times the largest component. */
    memset(bad, 0, sizeof bad);
    bad[2 * 1] = 1.0, bad[2 * 1 + 1] = 1.0;
    bad[2 * (N - 1)] = 1.0 + 1.3e-10, bad[2 * (N - 1) + 1] = -1.0;
    assert_int_equal(lpi_sine_euler_set_modes(other, bad, 2 * n), LPI_OK);
    bad[2 * (N - 1)] = 1.0 + 1.5e-10;
    LPI_ASSERT_FAILS(other, lpi_sine_euler_set_modes(other, bad, 2 * n), LPI_ERR_INVALID,
                     "lpi_sine_euler_set_modes");
    bad[2 * (N - 1)] = 1.0, bad[1] = 1.3e-10; /* w_0's imaginary part, in the message */
    assert_int_equal(lpi_sine_euler_set_modes(other, bad, 2 * n), LPI_OK);
    bad[1] = 1.5e-10;
    LPI_ASSERT_FAILS(other, lpi_sine_euler_set_modes(other, bad, 2 * n), LPI_ERR_INVALID,
                     "lpi_sine_euler_set_modes");
    assert_non_null(strstr(lpi_last_error(other), "imaginary part is 1.5e-10 "));
    lpi_destroy(other);

    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, w, 2 * n - 1), LPI_ERR_SIZE,
                     "lpi_sine_euler_set_modes");
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, w, n), LPI_ERR_SIZE, "lpi_sine_euler_set_modes");
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_modes(sys, NULL, 2 * n), LPI_ERR_NULL,
                     "lpi_sine_euler_set_modes");
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_get_modes(sys, bad, 2 * n + 2), LPI_ERR_SIZE,
                     "lpi_sine_euler_get_modes");
    for (size_t i = 0; i < n; ++i) grid[i] = (double)i;
    grid[5] = NAN;
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_grid(sys, grid, n), LPI_ERR_NONFINITE,
                     "lpi_sine_euler_set_grid");
    /* No mode of a finite grid exceeds its largest value, though the
     * transform's unnormalised sums do: a uniform 4.2e306 (N = 7: 49 times
     * that overflows) and a uniform DBL_MAX are w_0 alone. */
    const double uniform[2] = {4.2e306, DBL_MAX};
    for (int u = 0; u < 2; ++u) {
        for (size_t i = 0; i < n; ++i) grid[i] = uniform[u];
        assert_int_equal(lpi_sine_euler_set_grid(sys, grid, n), LPI_OK);
        double big[98];
        assert_int_equal(lpi_sine_euler_get_modes(sys, big, 2 * n), LPI_OK);
        assert_true(fabs(big[0] - uniform[u]) <= 1e-15 * uniform[u]);
        for (size_t i = 1; i < 2 * n; ++i) assert_true(fabs(big[i]) <= 1e-15 * uniform[u]);
    }
    /* And back: grid values near DBL_MAX come from modes far below it,
     * through the inverse transform's sums, which reach n times them (a
     * checkerboard of +-0.75 DBL_MAX at N = 9 read back as an overflow). */
    double checkerboard[49], back[49];
    for (size_t i = 0; i < n; ++i) checkerboard[i] = (i % 2 ? -0.9 : 0.9) * DBL_MAX;
    assert_int_equal(lpi_sine_euler_set_grid(sys, checkerboard, n), LPI_OK);
    assert_int_equal(lpi_sine_euler_get_grid(sys, back, n), LPI_OK);
    for (size_t i = 0; i < n; ++i) assert_true(fabs(back[i] - checkerboard[i]) <= 1e-14 * DBL_MAX);
    assert_int_equal(lpi_sine_euler_get_stream(sys, back, n), LPI_OK);
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 2 * n), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_set_grid(sys, grid, n + 1), LPI_ERR_SIZE,
                     "lpi_sine_euler_set_grid");
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_get_grid(sys, grid, 2 * n), LPI_ERR_SIZE,
                     "lpi_sine_euler_get_grid");
    double x[49];
    assert_int_equal(lpi_get_state(sys, x, n), LPI_OK);
    x[3] = NAN;
    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, x, n), LPI_ERR_NONFINITE, "lpi_set_state");
    LPI_ASSERT_FAILS(sys, lpi_set_state(sys, x, 2 * n), LPI_ERR_SIZE, "lpi_set_state");
    double traces[3];
    LPI_ASSERT_FAILS(sys, lpi_sine_euler_casimir_traces(sys, 0, traces), LPI_ERR_INVALID,
                     "lpi_sine_euler_casimir_traces");
    LPI_ASSERT_FAILS(sys, lpi_set_threads(sys, 0), LPI_ERR_INVALID, "lpi_set_threads");
    double lambda[8];
    LPI_ASSERT_FAILS(sys, lpi_casimirs(sys, lambda, 8), LPI_ERR_SIZE, "lpi_casimirs");
    /* a non-finite step size is refused */
    LPI_ASSERT_FAILS(sys, lpi_step(sys, INFINITY, 1), LPI_ERR_NONFINITE, "lpi_step");
    lpi_destroy(sys);

    /* sine-Euler calls on another kind of system */
    lpi_system *body = NULL;
    assert_int_equal(lpi_rigid_body_create(&body, 1, 2, 3), LPI_OK);
    LPI_ASSERT_FAILS(body, lpi_sine_euler_get_modes(body, w, 2 * n), LPI_ERR_UNSUPPORTED,
                     "lpi_sine_euler_get_modes");
    assert_non_null(strstr(lpi_last_error(body), "rigid-body"));
    LPI_ASSERT_FAILS(body, lpi_set_threads(body, 2), LPI_ERR_UNSUPPORTED, "lpi_set_threads");
    assert_int_equal(lpi_set_threads(body, 1), LPI_OK);
    lpi_destroy(body);
    LPI_ASSERT_FAILS(NULL, lpi_sine_euler_enstrophy(NULL, traces), LPI_ERR_NULL,
                     "lpi_sine_euler_enstrophy");
}

/* A build without FFTW: creation reports the missing library. */
static void test_without_fftw(void **state) {
    (void)state;
    lpi_system *sys = NULL;
    LPI_ASSERT_FAILS(NULL, lpi_sine_euler_create(&sys, 7), LPI_ERR_UNSUPPORTED,
                     "lpi_sine_euler_create");
    assert_non_null(strstr(lpi_last_error(NULL), "FFTW"));
    size_t length;
    LPI_ASSERT_FAILS(NULL, lpi_fftw_wisdom_export_string(NULL, 0, &length), LPI_ERR_UNSUPPORTED,
                     "lpi_fftw_wisdom_export_string");
}

/* FFTW ends the process when one of its own allocations fails. Calls whose
 * transforms cannot have their memory (the address space limited to what is
 * mapped) are refused with LPI_ERR_NO_MEMORY instead, the state and time
 * unchanged, and work once the memory is there: the first step (its plans),
 * new plans, the grid transform. Here FFTW's own allocations may still find
 * room in freed heap (the test then skips without the library's check); in
 * test_sine_euler_mpi's address-space tests the planner's failed allocation
 * aborted 7 runs in 10 before. Last: the limit's mallopt stays. */
typedef struct {
    double *grid;
    size_t n;
} grid_arguments;
static int first_step(lpi_system *sys, const void *context) {
    (void)context;
    return lpi_step(sys, 0.01, 1);
}
static int new_plans(lpi_system *sys, const void *context) {
    (void)context;
    return lpi_sine_euler_set_planning(sys, "measure");
}
static int grid_of(lpi_system *sys, const void *context) {
    const grid_arguments *g = context;
    return lpi_sine_euler_get_grid(sys, g->grid, g->n);
}
static void test_fftw_short_of_memory(void **state) {
    (void)state;
    LPI_SKIP_UNDER_A_SANITIZER();
    const int N = 101;
    const size_t n = 2 * (size_t)N * N;
    double *w = malloc(sizeof(double) * n), *before = malloc(sizeof(double) * n),
           *after = malloc(sizeof(double) * n), *grid = malloc(sizeof(double) * N * N);
    assert_true(w && before && after && grid);
    random_field(N, 3, w);
    lpi_system *sys = sine_euler(N, w);
    const grid_arguments g = {grid, (size_t)N * N};
    const struct {
        const char *name;
        lpi_test_limited_call call;
        const void *context;
    } calls[] = {{"lpi_step", first_step, NULL},
                 {"lpi_sine_euler_set_planning", new_plans, NULL},
                 {"lpi_sine_euler_get_grid", grid_of, &g}};
    int refused = 0;
    for (int c = 0; c < 3; ++c) {
        assert_int_equal(lpi_sine_euler_get_modes(sys, before, n), LPI_OK);
        const double t = lpi_time(sys);
        const int status = lpi_test_with_address_space_limited(1, calls[c].call, sys, calls[c].context);
        if (status != LPI_OK) {
            ++refused;
            assert_int_equal(status, LPI_ERR_NO_MEMORY);
            printf("%s short of memory: %s\n", calls[c].name, lpi_last_error(sys));
            assert_non_null(strstr(lpi_last_error(sys), calls[c].name));
            assert_int_equal(lpi_sine_euler_get_modes(sys, after, n), LPI_OK);
            assert_memory_equal(before, after, sizeof(double) * n);
            assert_true(lpi_time(sys) == t);
        }
        assert_int_equal(calls[c].call(sys, calls[c].context), LPI_OK); /* and with the memory */
    }
    printf("%d of 3 calls refused\n", refused);
    lpi_destroy(sys);
    free(w), free(before), free(after), free(grid);
    if (refused == 0) LPI_SKIP("an address-space limit refused nothing");
}

int main(void) {
    if (!lpi_test_have_sine_euler()) {
        const struct CMUnitTest tests[] = {cmocka_unit_test(test_without_fftw)};
        return lpi_run_tests(tests);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matrix_form_is_eq5),
        cmocka_unit_test(test_one_step_against_matrix_rk4),
        cmocka_unit_test(test_measured_orders),
        cmocka_unit_test(test_one_step_composite_large_factor),
        cmocka_unit_test(test_spectrum_kept_n31),
        cmocka_unit_test(test_spectrum_kept_n25_composite),
        cmocka_unit_test(test_single_line_is_steady),
        cmocka_unit_test(test_paper_figure2),
        cmocka_unit_test(test_modes_grid_and_state_round_trips),
        cmocka_unit_test(test_traces_match_spectrum),
        cmocka_unit_test(test_traces_past_zero_and_overflow),
        cmocka_unit_test(test_large_n),
        cmocka_unit_test(test_threads_bitwise),
        cmocka_unit_test(test_handles_on_threads),
        cmocka_unit_test(test_wisdom),
        cmocka_unit_test(test_planning),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_fftw_short_of_memory),
    };
    return lpi_run_tests(tests);
}
