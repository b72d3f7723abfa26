/* What the C benchmarks share: a monotonic clock, and a check that ends the
 * benchmark, naming it (BENCH_NAME, defined before this header) and the
 * library's message, when a call fails. */
#ifndef LPI_BENCH_COMMON_H
#define LPI_BENCH_COMMON_H

#include <liepoisson.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static inline double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
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
