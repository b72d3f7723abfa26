/* What an observer costs a step loop: the rigid body (the cheapest step, so
 * the worst case for any per-step overhead) stepped with no observer, with
 * an observer that never fires (every > steps per call), and with observers
 * every 1000, 100 and 10 steps. The configurations are interleaved over
 * several rounds and the best round kept; ratios are to "none", measured in
 * the same run. Prints a table; asserts nothing. */
#include <liepoisson.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "bench_common.h"

static void die(int status, lpi_system *sys, const char *what) {
    if (status == LPI_OK) return;
    fprintf(stderr, "bench_observer: %s: %s\n", what, lpi_last_error(sys));
    exit(1);
}

static int read_energy(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)step, (void)t;
    return lpi_energy(sys, (double *)user) != LPI_OK;
}

enum { kConfigs = 5, kRounds = 7 };
static const char *const kNames[kConfigs] = {"none", "never fires", "every 1000", "every 100",
                                             "every 10"};
static const int64_t kEvery[kConfigs] = {0, INT64_MAX, 1000, 100, 10};

int main(int argc, char **argv) {
    const int64_t steps = argc > 1 ? atoll(argv[1]) : bench_quick() ? 2000 : 200000;
    const char *methods[] = {"leapfrog", "yoshida-6", "rk4"};
    const double m0[3] = {1.0, 0.5, -0.3};
    printf("Observer cost, rigid body I = (1, 2, 3), %lld steps per lpi_step call, dt = 1e-3,\n"
           "best of %d interleaved rounds; the observer reads lpi_energy\n\n",
           (long long)steps, kRounds);
    printf("%-10s", "method");
    for (int c = 0; c < kConfigs; ++c) printf(" %12s", kNames[c]);
    printf("   (ns/step, then ratio to none)\n");
    for (size_t m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
        lpi_system *sys = NULL;
        die(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), NULL, "create");
        die(lpi_set_method(sys, methods[m]), sys, methods[m]);
        double best[kConfigs], energy = 0.0;
        for (int c = 0; c < kConfigs; ++c) best[c] = 1e300;
        for (int r = 0; r < kRounds; ++r)
            for (int c = 0; c < kConfigs; ++c) {
                die(lpi_set_state(sys, m0, 3), sys, "state");
                die(lpi_set_observer(sys, kEvery[c], kEvery[c] ? read_energy : NULL, &energy), sys,
                    "observer");
                const double start = now();
                die(lpi_step(sys, 1e-3, steps), sys, "step");
                const double ns = (now() - start) * 1e9 / (double)steps;
                if (ns < best[c]) best[c] = ns;
            }
        printf("%-10s", methods[m]);
        for (int c = 0; c < kConfigs; ++c) printf(" %12.1f", best[c]);
        printf("\n%-10s", "");
        for (int c = 0; c < kConfigs; ++c) printf(" %12.3f", best[c] / best[0]);
        printf("\n");
        lpi_destroy(sys);
    }
    return 0;
}
