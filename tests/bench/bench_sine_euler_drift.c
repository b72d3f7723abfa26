/* Sine-Euler: how the Casimirs (the spectrum of W) drift over long runs of
 * the explicit splitting, for prime and composite N and several composition
 * methods, dt = 0.05. The drift after n steps is the largest change of an
 * eigenvalue relative to the largest |eigenvalue|, as a root mean square over
 * a few random smooth fields; the exponent is the least-squares slope of
 * log(drift) against log(n). Unbiased round-off grows like sqrt(n) (exponent
 * 0.5); a systematic rescaling of the field per flow grows like n (exponent 1).
 * The runs are independent and deterministic: they go to child processes, as
 * many at once as there are processors. LPI_BENCH_DRIFT_STEPS sets the
 * longest run (default 10^5; 10^3 in the quick mode, bench_common.h). Prints
 * figures; asserts nothing. */
#include <liepoisson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../lpi_test.h"
#define BENCH_NAME "bench_sine_euler_drift"
#include "bench_common.h"

enum { kFields = 4, kMaxPoints = 8 };

static double spectrum_change(int N, const double *before, const double *after) {
    double scale = 0, change = 0;
    for (int i = 0; i < N; ++i) {
        scale = fmax(scale, fabs(before[i]));
        change = fmax(change, fabs(after[i] - before[i]));
    }
    return change / scale;
}

/* Writes change[p], the spectrum change of one random field after points[p]
 * steps of one continued run. */
static void measure(int N, const char *method, int field, const int64_t *points, int count,
                    double *change) {
    const size_t n = 2 * (size_t)N * N;
    double *w = malloc(sizeof(double) * n);
    double *before = malloc(sizeof(double) * N), *after = malloc(sizeof(double) * N);
    lpi_system *sys = NULL;
    check(lpi_sine_euler_create(&sys, N), NULL, "create");
    lpi_test_random_field(N, 0x5EED0000u + 977u * (unsigned)field + (unsigned)N, 1.0, w);
    check(lpi_sine_euler_set_modes(sys, w, n), sys, "set_modes");
    check(lpi_set_method(sys, method), sys, method);
    check(lpi_casimirs(sys, before, N), sys, "casimirs");
    int64_t done = 0;
    for (int p = 0; p < count; ++p) {
        check(lpi_step(sys, 0.05, points[p] - done), sys, "step");
        done = points[p];
        check(lpi_casimirs(sys, after, N), sys, "casimirs");
        change[p] = spectrum_change(N, before, after);
    }
    lpi_destroy(sys);
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
    const int64_t longest = setting ? atoll(setting) : bench_quick() ? 1000 : 100000;
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
    enum { kNs = sizeof Ns / sizeof Ns[0], kMethods = sizeof methods / sizeof methods[0] };
    const int jobs = kNs * kMethods * kFields;
    /* change[job][p], written by the children into shared memory. */
    double *change = mmap(NULL, sizeof(double) * jobs * kMaxPoints, PROT_READ | PROT_WRITE,
                          MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (change == MAP_FAILED) {
        perror("bench_sine_euler_drift: mmap");
        return 1;
    }
    const long processors = sysconf(_SC_NPROCESSORS_ONLN);
    const int workers = processors > 0 ? (int)processors : 1;
    int running = 0;
    for (int job = 0; job < jobs; ++job) {
        if (running == workers) {
            int status = 0;
            wait(&status);
            if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 1;
            --running;
        }
        const pid_t child = fork();
        if (child < 0) {
            perror("bench_sine_euler_drift: fork");
            return 1;
        }
        if (child == 0) {
            const int field = job % kFields, m = job / kFields % kMethods, i = job / kFields / kMethods;
            measure(Ns[i], methods[m], field, points, count, change + (size_t)job * kMaxPoints);
            _exit(0);
        }
        ++running;
    }
    for (; running > 0; --running) {
        int status = 0;
        wait(&status);
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 1;
    }
    for (int i = 0; i < kNs; ++i)
        for (int m = 0; m < kMethods; ++m) {
            double steps[kMaxPoints], drift[kMaxPoints];
            printf("%4d %-14s", Ns[i], methods[m]);
            for (int p = 0; p < count; ++p) {
                drift[p] = 0;
                for (int f = 0; f < kFields; ++f) {
                    const double c = change[((size_t)(i * kMethods + m) * kFields + f) * kMaxPoints + p];
                    drift[p] += c * c / kFields;
                }
                drift[p] = sqrt(drift[p]);
                steps[p] = (double)points[p];
                printf(" %9.2e", drift[p]);
            }
            printf(" %9.2f\n", count > 1 ? lpi_fit_order(steps, drift, count) : NAN);
        }
    munmap(change, sizeof(double) * jobs * kMaxPoints);
    return 0;
}
