/* Composition methods on the free rigid body (I = 1, 2, 3, m(0) = (1, 0.5,
 * -0.3)): each method's error at T = 100 for a fixed budget of piece flows,
 * and the time per step and per flow. Prints a table; asserts nothing. */
#include <liepoisson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bench_common.h"

static const double kT = 100.0;
static const double kM0[3] = {1.0, 0.5, -0.3};

static void die(int status, lpi_system *sys, const char *what) {
    if (status == LPI_OK) return;
    fprintf(stderr, "bench_compositions: %s: %s\n", what, lpi_last_error(sys));
    exit(1);
}

/* Reference: RK4 in long double with h = 1e-4 (written here, independent of
 * the library), cross-checked against the library's kahan-li-8 at a small step. */
static void reference(long double *m) {
    const long n = 1000000;
    const long double h = kT / n;
    long double k[4][3], y[3];
    for (int i = 0; i < 3; ++i) m[i] = kM0[i];
    for (long s = 0; s < n; ++s) {
        for (int st = 0; st < 4; ++st) {
            const long double c = st == 0 ? 0 : st == 3 ? h : h / 2;
            for (int i = 0; i < 3; ++i) y[i] = m[i] + (st ? c * k[st - 1][i] : 0);
            const long double w0 = y[0], w1 = y[1] / 2, w2 = y[2] / 3;
            k[st][0] = y[1] * w2 - y[2] * w1;
            k[st][1] = y[2] * w0 - y[0] * w2;
            k[st][2] = y[0] * w1 - y[1] * w0;
        }
        for (int i = 0; i < 3; ++i) m[i] += h / 6 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
    }
}

static double distance(const double *x, const double *r) {
    return sqrt((x[0] - r[0]) * (x[0] - r[0]) + (x[1] - r[1]) * (x[1] - r[1]) +
                (x[2] - r[2]) * (x[2] - r[2]));
}

int main(int argc, char **argv) {
    const long budget = argc > 1 ? atol(argv[1]) : bench_quick() ? 2000 : 20000;
    long double ref_l[3];
    reference(ref_l);
    const double ref[3] = {(double)ref_l[0], (double)ref_l[1], (double)ref_l[2]};

    lpi_system *sys = NULL;
    die(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), NULL, "create");
    double check[3];
    die(lpi_set_method(sys, "kahan-li-8"), sys, "method");
    die(lpi_set_state(sys, kM0, 3), sys, "state");
    die(lpi_step(sys, kT / 20000, 20000), sys, "step");
    die(lpi_get_state(sys, check, 3), sys, "state");

    printf("Composition methods, rigid body I = (1, 2, 3), m(0) = (1, 0.5, -0.3), split casimir-shift\n");
    printf("error = |m(T) - m_ref(T)| at T = %g with a budget of %ld piece flows (rk4: field evaluations)\n",
           kT, budget);
    printf("reference: long-double RK4, h = 1e-4; it differs from kahan-li-8 with dt = 0.005 by %.1e\n\n",
           distance(check, ref));
    printf("%-22s %5s %6s %10s %7s %9s %11s %9s %9s\n", "method", "order", "stages", "flows/step",
           "steps", "dt", "error", "ns/step", "ns/flow");

    const char *extra[] = {"triple-jump-6", "suzuki-6", "triple-jump-8"};
    const int count = lpi_method_count() + 3;
    for (int i = 0; i < count; ++i) {
        const char *name = i < lpi_method_count() ? lpi_method_name(i) : extra[i - lpi_method_count()];
        /* The sine-Euler matrix-form baselines refuse other systems: named, not timed. */
        const int chosen = lpi_set_method(sys, name);
        if (chosen == LPI_ERR_UNSUPPORTED) {
            printf("%-22s not timed: %s\n", name, lpi_last_error(sys));
            continue;
        }
        die(chosen, sys, name);
        size_t flows = 0;
        die(lpi_flows_per_step(sys, &flows), sys, "flows");
        const long steps = budget / (long)flows;
        double x[3];
        die(lpi_set_state(sys, kM0, 3), sys, "state");
        die(lpi_step(sys, kT / steps, steps), sys, "step");
        die(lpi_get_state(sys, x, 3), sys, "state");
        const double error = distance(x, ref);

        /* Time: repeat a 10^5-step run until 0.2 s have passed; best of 3. */
        const long run = bench_quick() ? 1000 : 100000;
        double best = 1e30;
        for (int rep = 0; rep < 3; ++rep) {
            long done = 0;
            const double t0 = now();
            double t1;
            do {
                die(lpi_set_state(sys, kM0, 3), sys, "state");
                die(lpi_step(sys, 1e-3, run), sys, "step");
                done += run;
            } while ((t1 = now()) - t0 < 0.2 && !bench_quick());
            const double ns = 1e9 * (t1 - t0) / done;
            if (ns < best) best = ns;
        }
        int order = 2, stages = 0;
        for (int j = 0; j < lpi_method_count(); ++j)
            if (strcmp(lpi_method_name(j), name) == 0) {
                order = lpi_method_order(j);
                stages = lpi_method_stages(j);
            }
        if (i >= lpi_method_count()) {
            order = atoi(strrchr(name, '-') + 1);
            stages = (int)(flows / 2);
        }
        printf("%-22s %5d %6d %10zu %7ld %9.4g %11.3e %9.1f %9.2f\n", name, order, stages, flows,
               steps, kT / steps, error, best, best / flows);
    }
    lpi_destroy(sys);
    return 0;
}
