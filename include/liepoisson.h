/*
 * liepoisson — explicit, Casimir-preserving integration of Lie-Poisson systems.
 *
 * The one public header. Every function is prefixed lpi_, every handle is the
 * opaque lpi_system. Fallible functions return an int status: LPI_OK (0) or a
 * negative LPI_ERR_* code; lpi_last_error() then gives the detail. A failed call
 * leaves the handle's state exactly as it was. The library never prints,
 * aborts or exits, and no C++ exception crosses this interface.
 *
 * Threading: one handle is used by one thread at a time; different handles
 * are independent and may be used concurrently.
 */
#ifndef LIEPOISSON_H
#define LIEPOISSON_H

#include <stddef.h>
#include <stdint.h>

/* The single source of the version: CMake and the Makefile read these lines. */
#define LPI_VERSION_MAJOR 0
#define LPI_VERSION_MINOR 1
#define LPI_VERSION_PATCH 0

#if defined(LPI_BUILDING_LIBRARY) && defined(__GNUC__)
#define LPI_API __attribute__((visibility("default")))
#else
#define LPI_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Status codes, defined once. X(name, value, message): the enum, lpi_status_name()
 * and lpi_status_message() are all generated from this list, so they cannot drift.
 * New codes are only ever appended (the values are part of the ABI).
 */
#define LPI_STATUS_LIST(X)                                                          \
    X(LPI_OK, 0, "success")                                                         \
    X(LPI_ERR_NULL, -1, "a required pointer argument is NULL")                      \
    X(LPI_ERR_INVALID, -2, "an argument is outside its valid range")                \
    X(LPI_ERR_SIZE, -3, "a buffer length does not match what the system needs")     \
    X(LPI_ERR_NONFINITE, -4, "an input or a result is NaN or infinite")             \
    X(LPI_ERR_NOT_ABELIAN, -5, "a piece's index set is not abelian")                \
    X(LPI_ERR_UNSUPPORTED, -6, "not built in, or not defined for this system")      \
    X(LPI_ERR_NO_MEMORY, -7, "out of memory")                                       \
    X(LPI_ERR_INTERNAL, -8, "internal error (please report it)")                   \
    X(LPI_ERR_CALLBACK, -9, "a user callback reported failure")                     \
    X(LPI_ERR_NO_CONVERGENCE, -10, "an implicit method's iteration did not converge")

typedef enum lpi_status {
#define LPI_STATUS_ENUM_ENTRY(name, value, message) name = value,
    LPI_STATUS_LIST(LPI_STATUS_ENUM_ENTRY)
#undef LPI_STATUS_ENUM_ENTRY
} lpi_status;

/* An integrated system: algebra, Hamiltonian split, method, state and time. */
typedef struct lpi_system lpi_system;

/* ---- Version, status codes, methods (no handle needed) ------------------- */

LPI_API const char *lpi_version_string(void);        /* "MAJOR.MINOR.PATCH" */
LPI_API const char *lpi_status_name(int status);     /* "LPI_ERR_SIZE"; "LPI_UNKNOWN_STATUS" otherwise */
LPI_API const char *lpi_status_message(int status);  /* one-line description */

/* Methods are chosen by name. i runs over 0 .. lpi_method_count()-1;
 * out-of-range i gives NULL (name) or -1 (order). */
LPI_API int lpi_method_count(void);
LPI_API const char *lpi_method_name(int i);
LPI_API int lpi_method_order(int i);

/* ---- Systems ------------------------------------------------------------- */

/* Free rigid body, so(3): H = sum m_k^2 / (2 I_k), Casimir |m|^2.
 * I1, I2, I3 must be finite and > 0. Splits: "casimir-shift" (default; two
 * rotations, the paper's), "axes" (three rotations, one per axis). */
LPI_API int lpi_rigid_body_create(lpi_system **out, double I1, double I2, double I3);

/* The exact free rigid-body solution (Jacobi elliptic functions): out = m at
 * time lpi_time(sys) + t, starting from the current state, which is not
 * changed. Every case: either side of the separatrix, the separatrix,
 * symmetric bodies, steady rotation. LPI_ERR_UNSUPPORTED for other systems. */
LPI_API int lpi_rigid_body_exact(const lpi_system *sys, double t, double *out);

/* Planar pendulum on e(2): H = x3^2/2 + x2, Casimir x1^2 + x2^2.
 * Split: "standard-map" (the only one). */
LPI_API int lpi_pendulum_create(lpi_system **out);

/* Releases the handle. NULL is a no-op. */
LPI_API void lpi_destroy(lpi_system *sys);

LPI_API int lpi_set_method(lpi_system *sys, const char *name);
LPI_API int lpi_set_split(lpi_system *sys, const char *name);

/* Dimension of the state vector; 0 for NULL. */
LPI_API size_t lpi_dim(const lpi_system *sys);

/* n must equal lpi_dim(sys). */
LPI_API int lpi_set_state(lpi_system *sys, const double *x, size_t n);
LPI_API int lpi_get_state(const lpi_system *sys, double *x, size_t n);

/* Advances nsteps steps of size dt (dt finite and nonzero; negative dt
 * integrates backwards; nsteps >= 0). A step whose result is not finite is
 * rolled back to the state before the call and LPI_ERR_NONFINITE returned. */
LPI_API int lpi_step(lpi_system *sys, double dt, int64_t nsteps);

/* Current time; NaN for NULL. Reset to 0 by lpi_set_state. */
LPI_API double lpi_time(const lpi_system *sys);

LPI_API int lpi_energy(const lpi_system *sys, double *out);

/* Number of Casimirs lpi_casimirs reports; n must equal it. */
LPI_API size_t lpi_casimir_count(const lpi_system *sys);
LPI_API int lpi_casimirs(const lpi_system *sys, double *out, size_t n);

/* The message of the most recent failed call on sys ("" if none). With
 * sys == NULL: the most recent failure of a call that had no handle to report
 * on (a failed *_create, a NULL handle) on the calling thread. Never NULL;
 * valid until the next call on the same handle (or thread). */
LPI_API const char *lpi_last_error(const lpi_system *sys);

/* ---- Composition methods ------------------------------------------------- */

/* Leapfrog stages per step of method i (1 for the sequences and rk4) and the
 * publication it comes from; -1 / NULL for i out of range. Besides the listed
 * methods, lpi_set_method accepts "triple-jump-<p>" and "suzuki-<p>" for even
 * p from 2 to 16 (recursive compositions with 3^(p/2-1) and 5^(p/2-1) stages). */
LPI_API int lpi_method_stages(int i);
LPI_API const char *lpi_method_reference(int i);

/* Makes the method a symmetric composition of leapfrog with the n >= 1 weights
 * gammas (step i takes gammas[i] * dt), named "custom". The weights must be
 * finite (else LPI_ERR_NONFINITE), sum to 1 within 1e-14 times the sum of
 * their absolute values and be symmetric, gammas[i] = gammas[n-1-i] within a
 * relative 1e-14 (else LPI_ERR_INVALID). Mirrored pairs are replaced by their
 * mean, so the composition is exactly symmetric. The array is copied. */
LPI_API int lpi_set_composition(lpi_system *sys, size_t n, const double *gammas);

/* Exact piece flows per step in a long run of the current method, after the
 * flows of the same piece that meet at stage seams and across steps are
 * merged (for rk4: vector-field evaluations per step). */
LPI_API int lpi_flows_per_step(const lpi_system *sys, size_t *out);

#ifdef __cplusplus
}
#endif

#endif /* LIEPOISSON_H */
