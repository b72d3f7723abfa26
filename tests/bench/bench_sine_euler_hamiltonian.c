/* The sine-bracket family at unchanged cost: time per leapfrog step of
 * sine-Euler with a general lambda and f (SQG's lambda = 1/|n| and the f of a
 * topography) against Euler's default, measured side by side in one run
 * (passes alternate between the two systems, best pass of each kept: the
 * machine may be shared). Prints figures; asserts nothing. */
#include <liepoisson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#define BENCH_NAME "bench_sine_euler_hamiltonian"
#include "bench_common.h"

static int centred(int a, int N) { return a > N / 2 ? a - N : a; }

/* The same field, every mode O(1/(1 + |m|^2)) (no mode near the subnormal
 * range, whose arithmetic is slow and would time the field, not the method);
 * with `general`, lambda = 1/|n| and f = -h/|n|^2 for the topography
 * h = 0.4 cos(x + 2y) (modes (1,2) and (-1,-2), 0.2 each). */
static lpi_system *make(int N, int general) {
    lpi_system *sys = NULL;
    const size_t n = (size_t)N * N;
    check(lpi_sine_euler_create(&sys, N), NULL, "create");
    double *modes = calloc(2 * n, sizeof(double)), *lambda = calloc(n, sizeof(double)),
           *f = calloc(2 * n, sizeof(double));
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int m1 = centred(a, N), m2 = centred(b, N);
            const double m_squared = (double)m1 * m1 + (double)m2 * m2;
            if (!(a || b)) continue;
            /* even real part, odd imaginary part: w_{-m} = conj(w_m) */
            modes[2 * (a * N + b)] = cos(1.3 * m1 + 2.1 * m2) / (1 + m_squared);
            modes[2 * (a * N + b) + 1] = sin(0.7 * m1 - 1.9 * m2) / (1 + m_squared);
            lambda[a * N + b] = 1.0 / sqrt(m_squared);
        }
    f[2 * (1 * N + 2)] = f[2 * ((N - 1) * N + N - 2)] = -0.2 / 5.0;
    if (general) check(lpi_sine_euler_set_hamiltonian(sys, lambda, n, f, 2 * n), sys, "set_hamiltonian");
    check(lpi_sine_euler_set_modes(sys, modes, 2 * n), sys, "set_modes");
    check(lpi_step(sys, 1e-3, 2), sys, "step"); /* warm-up: the first step plans */
    free(modes), free(lambda), free(f);
    return sys;
}

static double seconds_per_step(lpi_system *sys, int64_t reps) {
    const double t0 = now();
    check(lpi_step(sys, 1e-3, reps), sys, "step");
    return (now() - t0) / (double)reps;
}

int main(void) {
    const int sizes[] = {63, 127, 255};
    lpi_system *probe = NULL;
    if (lpi_sine_euler_create(&probe, 3) != LPI_OK) {
        printf("bench_sine_euler_hamiltonian: skipped: %s\n", lpi_last_error(NULL));
        return 0;
    }
    lpi_destroy(probe);
    printf("sine-Euler, leapfrog: a general lambda and f (SQG over a topography) against Euler\n");
    printf("%5s %14s %14s %9s\n", "N", "Euler ms/step", "general", "ratio");
    const int count = bench_quick() ? 1 : 3;
    const double budget = bench_quick() ? 0.005 : 0.2;
    for (int i = 0; i < count; ++i) {
        const int N = sizes[i];
        lpi_system *euler = make(N, 0), *general = make(N, 1);
        const double one = seconds_per_step(euler, 1);
        const int64_t reps = one > budget ? 1 : (int64_t)(budget / one) + 1;
        double best_euler = INFINITY, best_general = INFINITY;
        for (int pass = 0; pass < 7; ++pass) {
            best_euler = fmin(best_euler, seconds_per_step(euler, reps));
            best_general = fmin(best_general, seconds_per_step(general, reps));
        }
        printf("%5d %14.3f %14.3f %9.3f\n", N, 1e3 * best_euler, 1e3 * best_general,
               best_general / best_euler);
        lpi_destroy(euler);
        lpi_destroy(general);
    }
    return 0;
}
