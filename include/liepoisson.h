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
    X(LPI_ERR_CALLBACK, -9, "a user callback reported failure")

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

/* ---- Sine-Euler (Zeitlin's su(N) model of 2D Euler; needs FFTW3) ------- *
 * Modes w_m, m in Z_N x Z_N, N odd >= 3, eps = 2 pi / N, w_{-m} = conj(w_m):
 *   dw_m/dt = sum_{n != 0} sin(eps m x n) / (eps |n|^2) w_{m+n} w_{-n}
 * (McLachlan 1993, eq. 5), H = 1/2 sum_{n != 0} |w_n|^2 / |n|^2, |n| from the
 * representative of n in -M..M (N = 2M+1). Integrated by exact flows of one
 * piece per direction of the projective line over Z_N (N + 1 directions for
 * prime N); every Casimir (the spectrum of W = sum_m w_m J_m) is kept to
 * round-off. See lpi_sine_euler_create(3). */

/* Built without FFTW3: LPI_ERR_UNSUPPORTED. N even or < 3: LPI_ERR_INVALID. */
LPI_API int lpi_sine_euler_create(lpi_system **out, int32_t N);
/* N of a sine-Euler system (LPI_ERR_INVALID for another kind of system). */
LPI_API int lpi_sine_euler_size(const lpi_system *sys, int32_t *N);

/* Modes, n = 2*N*N doubles: entry [a*N + b] is mode (a, b) mod N (FFT order)
 * as interleaved re, im. set checks finiteness and Hermitian symmetry
 * (tolerance 1e-10 * max |w_m|) and stores the symmetrised field; resets the
 * time to 0. The inert mode w_0 is kept as given (its imaginary part must be 0
 * within the tolerance). */
LPI_API int lpi_sine_euler_set_modes(lpi_system *sys, const double *re_im, size_t n);
LPI_API int lpi_sine_euler_get_modes(const lpi_system *sys, double *re_im, size_t n);
/* Real vorticity on the grid, n = N*N: entry [a*N + b] is
 * w(2 pi a / N, 2 pi b / N) = sum_m w_m exp(i (m1 x + m2 y)). */
LPI_API int lpi_sine_euler_set_grid(lpi_system *sys, const double *w, size_t n);
LPI_API int lpi_sine_euler_get_grid(const lpi_system *sys, double *w, size_t n);

/* Enstrophy 1/2 sum_m |w_m|^2 (w_0 included) = tr(W^2) / (2N). */
LPI_API int lpi_sine_euler_enstrophy(const lpi_system *sys, double *out);
/* out[k-1] = (1/N) tr W^k for k = 1 .. kmax (kmax >= 1; O(kmax N^3)). */
LPI_API int lpi_sine_euler_casimir_traces(const lpi_system *sys, int32_t kmax, double *out);

/* Measures the FFT floor: FFTW executing, with this system's plans, buffers
 * and thread count, the transforms that nsteps steps of the current method
 * execute (and nothing else). Gives seconds per step and transforms per step.
 * A benchmark diagnostic; the state is not touched. */
LPI_API int lpi_sine_euler_fft_floor(lpi_system *sys, int64_t nsteps, double *seconds_per_step,
                                     double *transforms_per_step);

/* Threads used inside one step (OpenMP over the lines of a direction); n >= 1.
 * Results are identical to the bit for every n. Models that integrate on one
 * thread accept only n = 1 (LPI_ERR_UNSUPPORTED otherwise), as does a build
 * without OpenMP. */
LPI_API int lpi_set_threads(lpi_system *sys, int32_t n);

/* FFTW wisdom (shared by the whole process; planning is serialised inside the
 * library). Built without FFTW3: LPI_ERR_UNSUPPORTED. export_string writes at
 * most size bytes including the NUL and sets *length to the length without
 * it; LPI_ERR_SIZE when size <= *length (buf may then be NULL with size 0). */
LPI_API int lpi_fftw_wisdom_import_file(const char *path);
LPI_API int lpi_fftw_wisdom_export_file(const char *path);
LPI_API int lpi_fftw_wisdom_import_string(const char *wisdom);
LPI_API int lpi_fftw_wisdom_export_string(char *buf, size_t size, size_t *length);

#ifdef __cplusplus
}
#endif

#endif /* LIEPOISSON_H */
