/* Sine-Euler: the explicit splitting against the matrix-form baselines a user
 * would otherwise pick (isomp, rk4-matrix), side by side in one run.
 *
 * (1) Work-precision at N = 31, 61, 127, T = 1: each method is run with step
 *     counts doubling until its final error is below 1e-9 (or a CPU budget is
 *     spent); the CPU time to reach final errors 1e-6 and 1e-9 is
 *     interpolated log-log between the bracketing runs ("~": extrapolated
 *     along the last two runs' slope, the budget being spent first; "<": the
 *     coarsest run already reached it). Error: max |w_m(T) - w_ref_m(T)| over
 *     the modes, relative to max |w_ref_m(T)|; the reference is kahan-li-8
 *     with a much smaller step (its own error, estimated against half as many
 *     steps, is printed). Casimir drift: max |lambda_k(T) - lambda_k(0)| /
 *     max |lambda_k(0)| over the spectrum of W, in the run that first reached
 *     the target. isomp runs with the default iteration tolerance 1e-13 and,
 *     as "isomp@1e-10", with 1e-10 (fewer iterations, still far below the
 *     targets).
 * (2) Time per step against N (N = 31 ... 509; direct-eq5 only to N = 31) and
 *     the fitted exponent of step time against N.
 *
 * The field: w_m = (u_m + i v_m) / (1 + |m|^2)^(3/2) for m in the upper half
 * plane, u, v uniform in [-1/2, 1/2) from a hash of (m1, m2) (the same
 * continuum field at every N, truncated), w_-m = conj(w_m), w_0 = 0.
 *
 * CPU time is process CPU time (CLOCK_PROCESS_CPUTIME_ID). Run with
 * OPENBLAS_NUM_THREADS=1 so both sides use one core. Prints figures; asserts
 * nothing. LPI_BENCH_SECONDS sets the CPU budget of one sweep (default 6;
 * isomp sweeps get three times as much).
 * Usage: bench_sine_euler_baselines [all | work [N...] | scaling]. */
#include <liepoisson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#define BENCH_NAME "bench_sine_euler_baselines"
#include "bench_common.h"

static double cpu_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int rep(int a, int N) { return a > N / 2 ? a - N : a; }

static double hash_uniform(int m1, int m2, int which) {
    uint64_t x = (uint64_t)(uint32_t)m1 * 0x9E3779B97F4A7C15ull ^
                 (uint64_t)(uint32_t)m2 * 0xC2B2AE3D27D4EB4Full ^ (uint64_t)which * 0x165667B19E3779F9ull;
    x ^= x >> 33, x *= 0xFF51AFD7ED558CCDull, x ^= x >> 33, x *= 0xC4CEB9FE1A85EC53ull, x ^= x >> 33;
    return (double)(x >> 11) / 9007199254740992.0 - 0.5;
}

static double *make_field(int N) {
    double *w = calloc(2 * (size_t)N * N, sizeof(double));
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int r1 = rep(a, N), r2 = rep(b, N);
            if (r1 < 0 || (r1 == 0 && r2 <= 0)) continue;
            const double decay = pow(1.0 + r1 * r1 + r2 * r2, -1.5);
            const double u = hash_uniform(r1, r2, 0) * decay, v = hash_uniform(r1, r2, 1) * decay;
            const int m = a * N + b, minus = ((N - a) % N) * N + (N - b) % N;
            w[2 * m] = u, w[2 * m + 1] = v;
            w[2 * minus] = u, w[2 * minus + 1] = -v;
        }
    return w;
}

typedef struct {
    double cpu, error, drift;
    int64_t steps;
} run_result;

/* Sets "name" or "name@tolerance" (an implicit method's iteration tolerance). */
static void set_method(lpi_system *sys, const char *spec) {
    char name[64];
    snprintf(name, sizeof name, "%s", spec);
    char *at = strchr(name, '@');
    if (at) *at = '\0';
    check(lpi_set_method(sys, name), sys, spec);
    if (at) check(lpi_set_implicit_options(sys, atof(at + 1), 100), sys, spec);
}

/* One run of `steps` steps over [0, T]; error against ref (if any). */
static run_result run(int N, const double *w0, const char *method, double T, int64_t steps,
                      const double *ref, double *out) {
    const size_t n = 2 * (size_t)N * N;
    lpi_system *sys = NULL;
    check(lpi_sine_euler_create(&sys, N), NULL, "create");
    check(lpi_sine_euler_set_modes(sys, w0, n), sys, "set_modes");
    set_method(sys, method);
    double *before = malloc(sizeof(double) * N), *after = malloc(sizeof(double) * N);
    /* Untimed warm-up step (the splitting plans its FFTs on its first
     * step), then back to the initial field. */
    int status = lpi_step(sys, T / (double)steps, 1);
    if (status != LPI_ERR_NO_CONVERGENCE) check(status, sys, method);
    check(lpi_sine_euler_set_modes(sys, w0, n), sys, "set_modes");
    check(lpi_casimirs(sys, before, (size_t)N), sys, "casimirs");
    const double t0 = cpu_now();
    if (status == LPI_OK) status = lpi_step(sys, T / (double)steps, steps);
    run_result r = {cpu_now() - t0, NAN, 0.0, steps};
    if (status == LPI_ERR_NO_CONVERGENCE) { /* isomp at too large a step: no result */
        lpi_destroy(sys);
        free(before), free(after);
        r.error = INFINITY;
        return r;
    }
    check(status, sys, method);
    check(lpi_casimirs(sys, after, (size_t)N), sys, "casimirs");
    double scale = 0.0;
    for (int k = 0; k < N; ++k) {
        r.drift = fmax(r.drift, fabs(after[k] - before[k]));
        scale = fmax(scale, fabs(before[k]));
    }
    r.drift /= scale;
    check(lpi_sine_euler_get_modes(sys, out, n), sys, "get_modes");
    if (ref) {
        double d = 0.0, m = 0.0;
        for (size_t i = 0; i < n; ++i) d = fmax(d, fabs(out[i] - ref[i])), m = fmax(m, fabs(ref[i]));
        r.error = d / m;
    }
    lpi_destroy(sys);
    free(before), free(after);
    return r;
}

enum { kMaxRuns = 24 };
typedef struct {
    const char *method;
    run_result runs[kMaxRuns];
    int count;
    int64_t failed; /* the largest step count whose iteration did not converge */
} sweep;

/* CPU time to reach `target`; *mark: ' ' interpolated, '<' reached by the
 * coarsest run, '~' extrapolated. drift: that of the run that reached it. */
static double cpu_at(const sweep *s, double target, char *mark, double *drift) {
    *mark = ' ';
    *drift = NAN;
    if (s->count == 0) return NAN;
    if (s->runs[0].error <= target) {
        *mark = '<';
        *drift = s->runs[0].drift;
        return s->runs[0].cpu;
    }
    for (int i = 1; i < s->count; ++i)
        if (s->runs[i].error <= target) {
            const run_result *a = &s->runs[i - 1], *b = &s->runs[i];
            const double t = log(target / a->error) / log(b->error / a->error);
            *drift = b->drift;
            return exp(log(a->cpu) + t * log(b->cpu / a->cpu));
        }
    if (s->count < 2) return NAN;
    const run_result *a = &s->runs[s->count - 2], *b = &s->runs[s->count - 1];
    const double slope = log(b->cpu / a->cpu) / log(b->error / a->error);
    if (!(slope < 0) || !(b->error < a->error)) return NAN;
    *mark = '~';
    return b->cpu * pow(target / b->error, slope);
}

static sweep run_sweep(int N, const double *w0, const char *method, int64_t first, double T,
                       const double *ref, double ref_error, double budget, double *scratch) {
    sweep s = {method, {{0}}, 0, 0};
    double spent = 0.0;
    for (int64_t steps = first; s.count < kMaxRuns; steps *= 2) {
        const run_result r = run(N, w0, method, T, steps, ref, scratch);
        if (isinf(r.error)) {
            s.failed = steps;
            continue;
        }
        s.runs[s.count++] = r;
        spent += r.cpu;
        /* Done below 1e-9, at the reference's floor, or when the next run
         * (about twice this one) would overspend the budget. */
        if (r.error < 0.5e-9 || r.error < 30 * ref_error || spent + 2 * r.cpu > budget) break;
    }
    return s;
}

static void print_cpu(double c, char mark) {
    if (isnan(c))
        printf(" %11s", "-");
    else
        printf(" %c%9.3e s", mark, c);
}

static void work_precision(int N, double budget) {
    const double T = 1.0;
    const size_t n = 2 * (size_t)N * N;
    double *w0 = make_field(N), *ref = malloc(sizeof(double) * n),
           *half = malloc(sizeof(double) * n), *scratch = malloc(sizeof(double) * n);
    const int64_t ref_steps = 16;
    const run_result rr = run(N, w0, "kahan-li-8", T, ref_steps, NULL, ref);
    const run_result rh = run(N, w0, "kahan-li-8", T, ref_steps / 2, ref, half);
    const double ref_error = rh.error / 256.0; /* order 8: the finer run's error */
    printf("\nN = %d, T = %g: reference kahan-li-8, dt = 1/%lld (%.1f s CPU); |ref(dt) - "
           "ref(2 dt)| = %.1e, so its own error ~%.0e\n", N, T, (long long)ref_steps, rr.cpu,
           rh.error, ref_error);
    const struct {
        const char *method;
        int64_t first;
    } methods[] = {
        {"leapfrog", 4},    {"triple-jump-4", 2}, {"mclachlan-4", 2}, {"kahan-li-6", 1},
        {"kahan-li-8", 1},  {"isomp", 4},         {"isomp@1e-10", 4}, {"rk4-matrix", 4},
    };
    enum { kMethods = sizeof methods / sizeof methods[0] };
    sweep sweeps[kMethods];
    printf("%-14s %8s %12s %12s %12s\n", "method", "steps", "cpu", "error", "Casimir drift");
    for (int i = 0; i < kMethods; ++i) {
        /* isomp gets three times the budget, so that it reaches 1e-6 by
         * measurement at every N (1e-9 may still be extrapolated). */
        const double share = strncmp(methods[i].method, "isomp", 5) == 0 ? 3.0 : 1.0;
        sweeps[i] = run_sweep(N, w0, methods[i].method, methods[i].first, T, ref, ref_error,
                              share * budget, scratch);
        if (sweeps[i].failed)
            printf("%-14s %8lld   (no convergence of the iteration: skipped)\n", methods[i].method,
                   (long long)sweeps[i].failed);
        for (int k = 0; k < sweeps[i].count; ++k) {
            const run_result *r = &sweeps[i].runs[k];
            printf("%-14s %8lld %10.3e s %12.3e %12.3e\n", methods[i].method, (long long)r->steps,
                   r->cpu, r->error, r->drift);
        }
        fflush(stdout);
    }
    const double targets[2] = {1e-6, 1e-9};
    printf("CPU time to reach a final error (Casimir drift of that run):\n");
    printf("%-14s %12s %10s %12s %10s\n", "method", "1e-6", "drift", "1e-9", "drift");
    /* The best splitting: '<' times (reached by a single step over T) are
     * upper bounds, so the baseline ratios built on them are lower bounds. */
    double best[2] = {INFINITY, INFINITY}, isomp[2] = {NAN, NAN}, loose[2] = {NAN, NAN},
           rk4m[2] = {NAN, NAN};
    char best_mark[2] = {' ', ' '};
    const char *best_name[2] = {"", ""};
    for (int i = 0; i < kMethods; ++i) {
        printf("%-14s", methods[i].method);
        const char *name = methods[i].method;
        for (int t = 0; t < 2; ++t) {
            char mark;
            double drift;
            const double c = cpu_at(&sweeps[i], targets[t], &mark, &drift);
            print_cpu(c, mark);
            if (isnan(drift))
                printf(" %10s", "-");
            else
                printf(" %10.1e", drift);
            const int splitting = strncmp(name, "isomp", 5) != 0 && strcmp(name, "rk4-matrix") != 0;
            if (splitting && mark != '~' && c < best[t])
                best[t] = c, best_name[t] = name, best_mark[t] = mark;
            if (!strcmp(name, "isomp")) isomp[t] = c;
            if (!strcmp(name, "isomp@1e-10")) loose[t] = c;
            if (!strcmp(name, "rk4-matrix")) rk4m[t] = c;
        }
        printf("\n");
    }
    for (int t = 0; t < 2; ++t) {
        if (isinf(best[t])) { /* no ratio to print: every splitting ran out of budget first */
            printf("N = %d, error %.0e: no splitting method reached it within the budget\n", N, targets[t]);
            continue;
        }
        const char *bound = best_mark[t] == '<' ? ">=" : "";
        printf("N = %d, error %.0e: best splitting %s %s%.3e s; isomp / splitting = %s%.2f "
               "(isomp@1e-10: %s%.2f); rk4-matrix / splitting = %s%.2f\n", N, targets[t],
               best_name[t], best_mark[t] == '<' ? "<=" : "", best[t], bound, isomp[t] / best[t],
               bound, loose[t] / best[t], bound, rk4m[t] / best[t]);
    }
    free(w0), free(ref), free(half), free(scratch);
}

/* Least-squares slope of log(time) against log(N). */
static double fit_exponent(const int *Ns, const double *times, int count) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (int i = 0; i < count; ++i) {
        if (isnan(times[i])) continue;
        const double x = log((double)Ns[i]), y = log(times[i]);
        sx += x, sy += y, sxx += x * x, sxy += x * y, ++k;
    }
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

/* Seconds of CPU per step: enough steps for ~budget seconds, best of two passes. */
static double step_time(int N, const char *method, double dt, double budget, size_t *evaluations) {
    double *w0 = make_field(N);
    lpi_system *sys = NULL;
    check(lpi_sine_euler_create(&sys, N), NULL, "create");
    check(lpi_sine_euler_set_modes(sys, w0, 2 * (size_t)N * N), sys, "set_modes");
    check(lpi_set_method(sys, method), sys, method);
    check(lpi_step(sys, dt, 1), sys, method); /* untimed: the splitting plans here */
    double t0 = cpu_now();
    check(lpi_step(sys, dt, 1), sys, method);
    double best = cpu_now() - t0;
    const int64_t reps = best > budget ? 0 : (int64_t)(budget / best);
    for (int pass = 0; pass < 2 && reps > 0; ++pass) {
        t0 = cpu_now();
        check(lpi_step(sys, dt, reps), sys, method);
        best = fmin(best, (cpu_now() - t0) / (double)reps);
    }
    check(lpi_flows_per_step(sys, evaluations), sys, "flows");
    lpi_destroy(sys);
    free(w0);
    return best;
}

static void scaling(double budget) {
    const int Ns[] = {11, 15, 21, 31, 61, 127, 251, 509};
    enum { kN = sizeof Ns / sizeof Ns[0] };
    const char *methods[] = {"leapfrog", "isomp", "rk4-matrix", "direct-eq5"};
    enum { kM = sizeof methods / sizeof methods[0] };
    double times[kM][kN];
    size_t evals[kM][kN];
    for (int m = 0; m < kM; ++m)
        for (int i = 0; i < kN; ++i) times[m][i] = NAN;
    const int sizes = bench_quick() ? 4 : kN; /* quick: N <= 31 */
    const double dt = 1e-2;
    printf("\nCPU time per step (dt = %g; isomp: iterations per step in brackets)\n%5s", dt, "N");
    for (int m = 0; m < kM; ++m) printf(" %16s", methods[m]);
    printf("\n");
    for (int i = 0; i < sizes; ++i) {
        printf("%5d", Ns[i]);
        for (int m = 0; m < kM; ++m) {
            const int direct = !strcmp(methods[m], "direct-eq5");
            if ((direct && Ns[i] > 31) || (!direct && Ns[i] < 31)) {
                printf(" %16s", "");
                continue;
            }
            times[m][i] = step_time(Ns[i], methods[m], dt, budget, &evals[m][i]);
            if (!strcmp(methods[m], "isomp"))
                printf(" %10.3e s [%zu]", times[m][i], evals[m][i]);
            else
                printf(" %14.3e s", times[m][i]);
            fflush(stdout);
        }
        printf("\n");
    }
    printf("fitted exponent of step time against N:");
    for (int m = 0; m < kM; ++m) {
        const int direct = !strcmp(methods[m], "direct-eq5");
        printf(" %s %.2f (N = %d..%d);", methods[m], fit_exponent(Ns, times[m], kN),
               direct ? 11 : 31, direct ? 31 : 509);
    }
    printf("\n");
    /* The exponent over the large sizes only, where the O(N^3) terms dominate. */
    printf("over N = 127..509 only:");
    for (int m = 0; m < 3; ++m) printf(" %s %.2f;", methods[m], fit_exponent(Ns + 5, times[m] + 5, 3));
    printf("\n");
}

int main(int argc, char **argv) {
    lpi_system *probe = NULL;
    if (lpi_sine_euler_create(&probe, 3) != LPI_OK) {
        printf("bench_sine_euler_baselines: %s\n", lpi_last_error(NULL));
        return 0;
    }
    if (lpi_set_method(probe, "isomp") != LPI_OK) {
        printf("bench_sine_euler_baselines: %s\n", lpi_last_error(probe));
        lpi_destroy(probe);
        return 0;
    }
    lpi_destroy(probe);
    const double budget = getenv("LPI_BENCH_SECONDS") ? atof(getenv("LPI_BENCH_SECONDS"))
                          : bench_quick()               ? 0.02
                                                        : 6.0;
    const char *only = argc > 1 ? argv[1] : "all";
    printf("sine-Euler: splitting against the matrix-form baselines (OPENBLAS_NUM_THREADS=%s)\n",
           getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    if (strcmp(only, "scaling") != 0) {
        if (argc > 2) /* bench_sine_euler_baselines work N...: those sizes only */
            for (int i = 2; i < argc; ++i) work_precision(atoi(argv[i]), budget);
        else
            for (int N = 31; N <= (bench_quick() ? 31 : 127); N = 2 * N - 1 + (N == 61 ? 6 : 0))
                work_precision(N, budget);
    }
    if (strcmp(only, "work") != 0) scaling(0.05 * budget);
    return 0;
}
