/* A fault for lpi stress to catch (check_lpi_stress_fault.sh): loaded with
 * LD_PRELOAD into lpi, it doubles the state after every successful lpi_step,
 * as a method that loses its Casimirs and grows without bound would. The
 * checker must fail such runs (exit status 1), unbounded as they are. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "liepoisson.h"

int lpi_step(lpi_system *sys, double dt, int64_t nsteps) {
    typedef int (*step_function)(lpi_system *, double, int64_t);
    static step_function next;
    if (!next) next = (step_function)dlsym(RTLD_NEXT, "lpi_step");
    const int status = next(sys, dt, nsteps);
    if (status != LPI_OK) return status;
    const size_t n = lpi_dim(sys);
    double *x = malloc(n * sizeof *x);
    if (!x) return LPI_ERR_NO_MEMORY;
    int changed = lpi_get_state(sys, x, n);
    if (changed == LPI_OK) {
        for (size_t i = 0; i < n; ++i) x[i] *= 2.0;
        changed = lpi_set_state(sys, x, n);  /* and the time to 0, which stress reads only on a failure */
    }
    free(x);
    return changed;
}
