/* What the benchmarks share: a monotonic clock, the quick mode, and (C, with
 * BENCH_NAME defined before this header) a check that ends the benchmark,
 * naming it and the library's message, when a call fails. */
#ifndef LPI_BENCH_COMMON_H
#define LPI_BENCH_COMMON_H

#include <liepoisson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static inline double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* LPI_BENCH_QUICK set (not to 0), as `make bench-quick` sets it: each
 * benchmark runs every path it has on its smallest sizes and shortest runs,
 * and fails as it would in a full run; the figures it prints mean nothing.
 * CI runs it, so that `make bench` cannot break unnoticed. */
static inline int bench_quick(void) {
    const char *quick = getenv("LPI_BENCH_QUICK");
    return quick && *quick && strcmp(quick, "0") != 0;
}

#ifdef BENCH_NAME
static inline void check(int status, const lpi_system *sys, const char *what) {
    if (status != LPI_OK) {
        fprintf(stderr, BENCH_NAME ": %s: %s\n", what, lpi_last_error(sys));
        exit(1);
    }
}
#endif

#endif
