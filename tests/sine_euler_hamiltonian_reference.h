/* The independent reference of test_sine_euler_hamiltonian.c, written from
 * the definitions and sharing no code with the library: a Hamiltonian
 * H = 1/2 sum lambda_n |w_n|^2 + sum conj(f_n) w_n as the test holds it (SQG,
 * Euler, a topography), Zeitlin's J_m built entry by entry, the matrix-form
 * rate dW/dt = (i / (2 eps)) [P, W] with P = sum (lambda w + f)_n J_n, and
 * classical RK4 on it. Needs lpi_test.h first. */
#ifndef SINE_EULER_HAMILTONIAN_REFERENCE_H
#define SINE_EULER_HAMILTONIAN_REFERENCE_H

#include <complex.h>

typedef double complex cplx;

enum { kMaxN = 9, kMaxModes = kMaxN * kMaxN };

/* A Hamiltonian as the test holds it: lambda (N^2) and f (N^2 complex). */
typedef struct {
    int N;
    double lambda[kMaxModes];
    cplx f[kMaxModes];
} hamiltonian;

static int norm2(int a, int b, int N) {
    const int ra = lpi_test_centred(a, N), rb = lpi_test_centred(b, N);
    return ra * ra + rb * rb;
}
static int mirror(int i, int N) { return lpi_test_mod(-(i / N), N) * N + lpi_test_mod(-(i % N), N); }

static double max_abs_diff(const double *a, const double *b, size_t n) {
    double d = 0;
    for (size_t i = 0; i < n; ++i) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

/* Euler: 1/|n|^2. SQG: 1/|n|. Topography h (a smooth Hermitian field): Euler's
 * lambda and f_n = -h_n / |n|^2. */
static void euler(int N, hamiltonian *H) {
    memset(H, 0, sizeof *H);
    H->N = N;
    for (int i = 1; i < N * N; ++i) H->lambda[i] = 1.0 / norm2(i / N, i % N, N);
}
static void sqg(int N, hamiltonian *H) {
    euler(N, H);
    for (int i = 1; i < N * N; ++i) H->lambda[i] = 1.0 / sqrt((double)norm2(i / N, i % N, N));
}
static void topography(int N, hamiltonian *H) {
    euler(N, H);
    double h[2 * kMaxModes];
    lpi_test_random_field(N, 0xB0770Bull + (uint64_t)N, 2.0, h);
    for (int i = 1; i < N * N; ++i) H->f[i] = -(h[2 * i] + I * h[2 * i + 1]) * H->lambda[i];
}

/* ---- the independent matrix form ---------------------------------------- */

/* Entry (a, b) of J_m is exp(2 pi i m1 m2 / N) q^(m1 a), q = exp(4 pi i / N),
 * when b - a = m2 (mod N): J_m = exp(2 pi i m1 m2/N) g^m1 h^m2 as in Zeitlin. */
static cplx unit_root(int k, int N) { return cexp(2 * M_PI * I * lpi_test_mod(k, N) / N); }

static void to_matrix(int N, const cplx *w, cplx *W) {
    memset(W, 0, sizeof(cplx) * N * N);
    for (int m1 = 0; m1 < N; ++m1)
        for (int m2 = 0; m2 < N; ++m2)
            for (int b = 0; b < N; ++b) {
                const int a = lpi_test_mod(b - m2, N);
                W[a * N + b] += w[m1 * N + m2] * unit_root(m1 * m2 + 2 * m1 * a, N);
            }
}

/* w_m = tr(W J_m^dagger) / N. */
static void from_matrix(int N, const cplx *W, cplx *w) {
    for (int m1 = 0; m1 < N; ++m1)
        for (int m2 = 0; m2 < N; ++m2) {
            cplx sum = 0;
            for (int b = 0; b < N; ++b) {
                const int a = lpi_test_mod(b - m2, N);
                sum += W[a * N + b] * conj(unit_root(m1 * m2 + 2 * m1 * a, N));
            }
            w[m1 * N + m2] = sum / N;
        }
}

/* dW/dt = (i / (2 eps)) [P, W], P = sum_{n != 0} (lambda_n w_n + f_n) J_n. */
static void matrix_rate(const hamiltonian *H, const cplx *W, cplx *dW) {
    const int N = H->N;
    cplx w[kMaxModes], P[kMaxModes];
    from_matrix(N, W, w);
    for (int i = 0; i < N * N; ++i) w[i] = i ? H->lambda[i] * w[i] + H->f[i] : 0;
    to_matrix(N, w, P);
    const double eps = 2 * M_PI / N;
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
            cplx c = 0;
            for (int k = 0; k < N; ++k) c += P[i * N + k] * W[k * N + j] - W[i * N + k] * P[k * N + j];
            dW[i * N + j] = I / (2 * eps) * c;
        }
}

static void matrix_rk4(const hamiltonian *H, const double *w0, double T, int steps, double *w_out) {
    const int n = H->N * H->N;
    cplx W[kMaxModes], Y[kMaxModes], k[4][kMaxModes];
    to_matrix(H->N, (const cplx *)w0, W);
    const double h = T / steps;
    for (int s = 0; s < steps; ++s) {
        matrix_rate(H, W, k[0]);
        for (int i = 0; i < n; ++i) Y[i] = W[i] + 0.5 * h * k[0][i];
        matrix_rate(H, Y, k[1]);
        for (int i = 0; i < n; ++i) Y[i] = W[i] + 0.5 * h * k[1][i];
        matrix_rate(H, Y, k[2]);
        for (int i = 0; i < n; ++i) Y[i] = W[i] + h * k[2][i];
        matrix_rate(H, Y, k[3]);
        for (int i = 0; i < n; ++i) W[i] += h / 6 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
    }
    from_matrix(H->N, W, (cplx *)w_out);
}

/* H(w) summed here from its definition. */
static double energy_of(const hamiltonian *H, const double *modes) {
    const cplx *w = (const cplx *)modes;
    double sum = 0;
    for (int i = 1; i < H->N * H->N; ++i)
        sum += 0.5 * H->lambda[i] * creal(w[i] * conj(w[i])) + creal(conj(H->f[i]) * w[i]);
    return sum;
}

#endif
