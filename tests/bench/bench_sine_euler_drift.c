/* Sine-Euler: how the Casimirs (the spectrum of W) drift over long runs of
 * the explicit splitting, for prime and composite N and several composition
 * methods, dt = 0.05. The drift after n steps is the largest change of an
 * eigenvalue relative to the largest |eigenvalue|, as a root mean square over
 * a few random smooth fields; the exponent is the least-squares slope of
 * log(drift) against log(n). Unbiased round-off grows like sqrt(n) (exponent
 * 0.5); a systematic rescaling of the field per flow grows like n (exponent 1).
 * LPI_BENCH_DRIFT_STEPS sets the longest run (default 10^5). Prints figures;
 * asserts nothing. */
#include <liepoisson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lpi_test.h"

enum { kFields = 3, kMaxPoints = 8 };

static void check(int status, lpi_system *sys, const char *what) {
    if (status != LPI_OK) {
        fprintf(stderr, "bench_sine_euler_drift: %s: %s\n", what, lpi_last_error(sys));
        exit(1);
    }
}

static double spectrum_change(int N, const double *before, const double *after) {
    double scale = 0, change = 0;
    for (int i = 0; i < N; ++i) {
        scale = fmax(scale, fabs(before[i]));
        change = fmax(change, fabs(after[i] - before[i]));
    }
    return change / scale;
}

/* Fills drift[p] (root mean square over the fields) at the step counts
 * points[0] < points[1] < ... of one continued run per field. */
static void measure(int N, const char *method, const int64_t *points, int count, double *drift) {
    const size_t n = 2 * (size_t)N * N;
    double *w = malloc(sizeof(double) * n);
    double *before = malloc(sizeof(double) * N), *after = malloc(sizeof(double) * N);
    for (int p = 0; p < count; ++p) drift[p] = 0;
    for (int f = 0; f < kFields; ++f) {
        lpi_system *sys = NULL;
        check(lpi_sine_euler_create(&sys, N), NULL, "create");
        lpi_test_random_field(N, 0x5EED0000u + 977u * (unsigned)f + (unsigned)N, 1.0, w);
        check(lpi_sine_euler_set_modes(sys, w, n), sys, "set_modes");
        check(lpi_set_method(sys, method), sys, method);
        check(lpi_casimirs(sys, before, N), sys, "casimirs");
        int64_t done = 0;
        for (int p = 0; p < count; ++p) {
            check(lpi_step(sys, 0.05, points[p] - done), sys, "step");
            done = points[p];
            check(lpi_casimirs(sys, after, N), sys, "casimirs");
            const double change = spectrum_change(N, before, after);
            drift[p] += change * change / kFields;
        }
        lpi_destroy(sys);
    }
    for (int p = 0; p < count; ++p) drift[p] = sqrt(drift[p]);
    free(w);
    free(before);
    free(after);
}

int main(void) {
    lpi_system *probe = NULL;
    if (lpi_sine_euler_create(&probe, 3) != LPI_OK) {
        printf("bench_sine_euler_drift: %s\n", lpi_last_error(NULL));
        return 0;
    }
    double spectrum[3];
    if (lpi_casimirs(probe, spectrum, 3) != LPI_OK) {
        printf("bench_sine_euler_drift: %s\n", lpi_last_error(probe));
        lpi_destroy(probe);
        return 0;
    }
    lpi_destroy(probe);
    const char *setting = getenv("LPI_BENCH_DRIFT_STEPS");
    const int64_t longest = setting ? atoll(setting) : 100000;
    /* Log-spaced step counts, 10^3 (or fewer) up to `longest`. */
    int64_t points[kMaxPoints];
    int count = 0;
    for (double n = longest; n >= 1000 * 0.999 && count < kMaxPoints; n /= sqrt(10.0))
        points[count++] = (int64_t)llround(n);
    if (count == 0) points[count++] = longest > 0 ? longest : 1;
    for (int i = 0; i < count / 2; ++i) { /* ascending */
        const int64_t t = points[i];
        points[i] = points[count - 1 - i];
        points[count - 1 - i] = t;
    }
    printf("sine-Euler spectrum drift, dt = 0.05, rms over %d random smooth fields "
           "(exponent 0.5: unbiased round-off; 1: a systematic drift)\n",
           kFields);
    printf("%4s %-14s", "N", "method");
    for (int p = 0; p < count; ++p) printf(" %9lld", (long long)points[p]);
    printf(" %9s\n", "exponent");
    const int Ns[] = {25, 27, 31};
    const char *methods[] = {"leapfrog", "triple-jump-4", "mclachlan-4"};
    for (size_t i = 0; i < sizeof Ns / sizeof Ns[0]; ++i)
        for (size_t m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
            double steps[kMaxPoints], drift[kMaxPoints];
            measure(Ns[i], methods[m], points, count, drift);
            printf("%4d %-14s", Ns[i], methods[m]);
            for (int p = 0; p < count; ++p) {
                steps[p] = (double)points[p];
                printf(" %9.2e", drift[p]);
            }
            printf(" %9.2f\n", count > 1 ? lpi_fit_order(steps, drift, count) : NAN);
            fflush(stdout);
        }
    return 0;
}
