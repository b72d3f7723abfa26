/*
 * liepoisson — explicit, Casimir-preserving integration of Lie-Poisson systems.
 *
 * The one public header. Every function is prefixed lpi_, every handle is the
 * opaque lpi_system. Fallible functions return an int status: LPI_OK (0), a
 * negative LPI_ERR_* code (lpi_last_error() then gives the detail), or - from
 * lpi_step only - the positive LPI_STOPPED. A failed call leaves the handle's
 * state exactly as it was. The library never prints, aborts or exits (FFTW,
 * libgomp and libgfortran can, when memory is exhausted: liepoisson(7)), and
 * no C++ exception crosses this interface (a thread that ends inside a
 * callback unwinds through it, the call rolled back: liepoisson(7)).
 *
 * Threading: one handle is used by one thread at a time; different handles
 * are independent and may be used concurrently. A call on a handle that
 * another thread is inside returns LPI_ERR_BUSY, but for the functions that
 * return no status (below), which take no hold of it: call those only while
 * no other thread is inside a call on the handle. A pthread_cancel that
 * comes while the library waits or touches files acts after the call
 * (liepoisson(7)).
 *
 * Re-entrancy: a user callback (piece gradient or energy, Casimir, moment
 * product piece, observer) runs while the library is inside a call on its
 * handle. A call on that same handle from such a callback is refused with
 * LPI_ERR_BUSY and changes nothing, with two exceptions: inside an observer
 * (lpi_set_observer) the read-only functions - those taking a const
 * lpi_system * (lpi_get_state, lpi_energy, lpi_casimirs, the sine-Euler
 * getters, lpi_save, ...) - are allowed; and lpi_dim, lpi_time,
 * lpi_casimir_count, lpi_kind, lpi_get_method, lpi_get_split and
 * lpi_last_error, which return no status, always answer. Calls on other
 * handles are not affected, except handles spread over MPI processes
 * (liepoisson_mpi.h), which a callback of another handle may not call
 * (LPI_ERR_INVALID).
 *
 * Kinds: a function defined for some kinds of system only (lpi_rigid_body_exact,
 * lpi_add_piece, lpi_add_casimir, lpi_poisson_rank,
 * lpi_moments_add_product_piece, the lpi_sine_euler_* functions, the
 * sine-Euler matrix methods) returns LPI_ERR_UNSUPPORTED, "not defined for
 * this system", for a handle of another kind (lpi_kind names it), and
 * changes nothing.
 */
#ifndef LIEPOISSON_H
#define LIEPOISSON_H

#include <stddef.h>
#include <stdint.h>

/* The single source of the version: CMake and the Makefile read these lines. */
#define LPI_VERSION_MAJOR 0
#define LPI_VERSION_MINOR 1
#define LPI_VERSION_PATCH 0
/* The version as one number that grows with every release:
 * MAJOR * 10000 + MINOR * 100 + PATCH (0.1.0 is 100). */
#define LPI_VERSION_NUMBER \
    (LPI_VERSION_MAJOR * 10000 + LPI_VERSION_MINOR * 100 + LPI_VERSION_PATCH)

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
    X(LPI_ERR_NO_CONVERGENCE, -10, "an implicit method's iteration did not converge") \
    X(LPI_ERR_IO, -11, "a file could not be opened, read, written or renamed")       \
    X(LPI_ERR_FORMAT, -12, "data is not a valid checkpoint of this library")           \
    X(LPI_ERR_BUSY, -13, "the handle is busy (in one of its callbacks, or another thread's call)") \
    X(LPI_ERR_OVERFLOW, -14, "a result of finite inputs overflows a double")          \
    X(LPI_STOPPED, 1, "the observer stopped the step loop (not an error)")

typedef enum lpi_status {
#define LPI_STATUS_ENUM_ENTRY(name, value, message) name = value,
    LPI_STATUS_LIST(LPI_STATUS_ENUM_ENTRY)
#undef LPI_STATUS_ENUM_ENTRY
} lpi_status;

/* An integrated system: algebra, Hamiltonian split, method, state and time. */
typedef struct lpi_system lpi_system;

/* ---- Version, status codes, methods (no handle needed) ------------------- */

LPI_API const char *lpi_version_string(void);        /* "MAJOR.MINOR.PATCH" */
/* LPI_VERSION_NUMBER of the library that runs: compare it with the macro (the
 * header a program was built against), or a binding's minimum, as numbers. */
LPI_API int lpi_version_number(void);
LPI_API const char *lpi_status_name(int status);     /* "LPI_ERR_SIZE"; "LPI_UNKNOWN_STATUS" otherwise */
LPI_API const char *lpi_status_message(int status);  /* one-line description */

/* Methods are chosen by name. i runs over 0 .. lpi_method_count()-1;
 * out-of-range i gives NULL (name) or -1 (order). */
LPI_API int lpi_method_count(void);
LPI_API const char *lpi_method_name(int i);
LPI_API int lpi_method_order(int i);
/* 1 if method i is a Poisson map (keeps every Casimir to round-off), 0 for the
 * baselines (rk4, implicit-midpoint, ...), -1 out of range. */
LPI_API int lpi_method_is_poisson(int i);

/* ---- Systems ------------------------------------------------------------- */

/* Free rigid body, so(3): H = sum m_k^2 / (2 I_k), Casimir |m|^2.
 * I1, I2, I3 must be finite and > 0. Splits: "casimir-shift" (default; two
 * rotations, the paper's), "axes" (three rotations, one per axis). */
LPI_API int lpi_rigid_body_create(lpi_system **out, double I1, double I2, double I3);

/* The exact free rigid-body solution (Jacobi elliptic functions): out = m at
 * time lpi_time(sys) + t, starting from the current state, which is not
 * changed. Every case: either side of the separatrix, the separatrix,
 * symmetric bodies (closed form), near and on the axes; a steady rotation
 * comes back unchanged. Error a few 1e-15 |m|, growing like the round-off
 * times the number of turns. LPI_ERR_UNSUPPORTED for other systems;
 * LPI_ERR_NONFINITE where t times the body's rates (about |m| / I) overflows,
 * LPI_ERR_OVERFLOW for inertias more than 2^1022 apart. */
LPI_API int lpi_rigid_body_exact(const lpi_system *sys, double t, double *out);

/* Planar pendulum on e(2): H = x3^2/2 + x2, Casimir x1^2 + x2^2.
 * Split: "standard-map" (the only one). */
LPI_API int lpi_pendulum_create(lpi_system **out);

/* Releases the handle; NULL is a no-op (LPI_OK). Called from one of the
 * handle's own callbacks it frees nothing and returns LPI_ERR_BUSY. */
LPI_API int lpi_destroy(lpi_system *sys);

LPI_API int lpi_set_method(lpi_system *sys, const char *name);
LPI_API int lpi_set_split(lpi_system *sys, const char *name);

/* What a system is and how it is integrated, as names; NULL for a NULL
 * handle. lpi_kind: "rigid-body", "pendulum", "generic", "moments" or
 * "sine-euler", valid as long as the handle. lpi_get_method: the method's
 * name as lpi_set_method takes it ("leapfrog" for a new system; "custom" after
 * lpi_set_composition; an alias is resolved: "strang" gives "leapfrog").
 * lpi_get_split: the split in use (the default for a new system). The string
 * belongs to the handle, like lpi_last_error's: valid until the next
 * lpi_set_method, lpi_set_composition or lpi_set_split on it (for
 * lpi_get_split: lpi_set_split) or lpi_destroy; copy it to keep it. */
LPI_API const char *lpi_kind(const lpi_system *sys);
LPI_API const char *lpi_get_method(const lpi_system *sys);
LPI_API const char *lpi_get_split(const lpi_system *sys);

/* Dimension of the state vector; 0 for NULL. */
LPI_API size_t lpi_dim(const lpi_system *sys);

/* n must equal lpi_dim(sys). */
LPI_API int lpi_set_state(lpi_system *sys, const double *x, size_t n);
LPI_API int lpi_get_state(const lpi_system *sys, double *x, size_t n);

/* Advances nsteps steps of size dt (dt finite and nonzero; negative dt
 * integrates backwards; nsteps >= 0). The time becomes lpi_time + dt * nsteps
 * (LPI_ERR_OVERFLOW when that, or dt times a flow weight of the method,
 * overflows; with nsteps == 0 nothing is stepped, and only that dt is finite
 * and nonzero is checked). A step whose result is not finite, or whose
 * callback fails, is rolled back to the state before the call:
 * LPI_ERR_NONFINITE or LPI_ERR_CALLBACK with a message naming the step and
 * the time. With an
 * observer whose callback returns non-zero, LPI_STOPPED (positive): the
 * state and time are those of a call of that many steps. */
LPI_API int lpi_step(lpi_system *sys, double dt, int64_t nsteps);

/* An observer of lpi_step: called with the steps completed in the current
 * call (every, 2 every, ...) and the time reached; the handle then holds
 * exactly the state a call of that many steps would leave, and observing does
 * not change the trajectory to the bit. It may read the handle (the functions
 * taking const lpi_system *); mutating calls on it return LPI_ERR_BUSY. A
 * non-zero return stops lpi_step after that step (LPI_STOPPED). */
typedef int (*lpi_observer_fn)(const lpi_system *sys, int64_t step, double t, void *user);

/* Sets the observer of lpi_step (every >= 1), or removes it when fn is NULL
 * (every is then ignored). Not stored in checkpoints. */
LPI_API int lpi_set_observer(lpi_system *sys, int64_t every, lpi_observer_fn fn, void *user);

/* Current time; NaN for NULL. Reset to 0 by lpi_set_state. */
LPI_API double lpi_time(const lpi_system *sys);

/* Energy of the current state; LPI_ERR_OVERFLOW when it overflows a double. */
LPI_API int lpi_energy(const lpi_system *sys, double *out);

/* Number of Casimirs lpi_casimirs reports; n must equal it. A Casimir that
 * overflows a double gives LPI_ERR_OVERFLOW naming it, out untouched. */
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
 * their absolute values and within 1e-10, and be symmetric, gammas[i] =
 * gammas[n-1-i] within a relative 1e-14 (else LPI_ERR_INVALID); weights whose
 * sum of absolute values overflows a double are refused with LPI_ERR_OVERFLOW.
 * Mirrored pairs are replaced by their mean, so the composition is exactly
 * symmetric. The array is copied. */
LPI_API int lpi_set_composition(lpi_system *sys, size_t n, const double *gammas);

/* Exact piece flows per step in a long run of the current method, after the
 * flows of the same piece that meet at stage seams and across steps are
 * merged (for rk4: vector-field evaluations per step). */
LPI_API int lpi_flows_per_step(const lpi_system *sys, size_t *out);

/* Settings of the implicit baselines (implicit-midpoint; isomp for sine-Euler):
 * the fixed-point iteration stops when max|change| <= tolerance * max|x| (or
 * at the noise of subnormal arithmetic, where the vector field underflows)
 * and fails with LPI_ERR_NO_CONVERGENCE (state rolled back) after
 * max_iterations. Defaults: 1e-13 and 100. Kept across lpi_set_method. */
LPI_API int lpi_set_implicit_options(lpi_system *sys, double tolerance, int32_t max_iterations);
/* ---- Generic Lie-Poisson systems and the moment algebra ------------------ */

/* Callbacks of user-defined systems. Each returns 0 on success; any other
 * value (or a non-finite result) makes the calling function fail with
 * LPI_ERR_CALLBACK, a message naming the piece or Casimir, and - for a step -
 * the state rolled back. x_sigma and grad are in the order of the piece's
 * indices; n is their count; grad holds zeros on every call. */
typedef int (*lpi_gradient_fn)(size_t n, const double *x_sigma, double *grad, void *user);
typedef int (*lpi_energy_fn)(size_t n, const double *x_sigma, double *h, void *user);
/* One Casimir C(x) of the full state x (length dim), written to *out. */
typedef int (*lpi_casimir_fn)(size_t dim, const double *x, double *out, void *user);
/* A scalar function of one variable (H(u) or H'(u) of the moment product piece). */
typedef int (*lpi_scalar_fn)(double u, double *out, void *user);

/* A Lie-Poisson system with {x_i, x_j} = sum c * x_k over the nnz entries
 * (i[e], j[e], k[e], c[e]), 0-based indices below dim. Either order of i, j
 * may be given; {x_j, x_i} = -{x_i, x_j} is implied, and entries that
 * contradict it (or each other) are refused, as are constants violating the
 * Jacobi identity (the message names the failing triple). The arrays may be
 * NULL when nnz is 0. The system starts with no pieces and no Casimirs. */
LPI_API int lpi_generic_create(lpi_system **out, size_t dim, size_t nnz, const int32_t *i,
                               const int32_t *j, const int32_t *k, const double *c);

/* Appends the piece H_k(x_sigma), sigma = indices[0..n-1] (distinct, 0-based,
 * abelian: every bracket within sigma is zero, else LPI_ERR_NOT_ABELIAN naming
 * the pair). Its flow is exact: x' = A x with A_il = sum_{j in sigma} c_ij^l
 * g_j, g = grad H_k, solved by a finite series when A is nilpotent and a
 * scaling-and-squaring Pade exponential otherwise. Pieces are composed in the
 * order added. grad and energy are required; user is passed through. Works on
 * systems from lpi_generic_create and lpi_moments_create. */
LPI_API int lpi_add_piece(lpi_system *sys, size_t n, const int32_t *indices,
                          lpi_gradient_fn grad, lpi_energy_fn energy, void *user);

/* Declares one more Casimir, reported by lpi_casimirs after those already
 * declared (lpi_casimir_count grows by one). */
LPI_API int lpi_add_casimir(lpi_system *sys, lpi_casimir_fn fn, void *user);

/* Numerical rank of the Poisson matrix J(x) (n = dim): singular values above
 * dim * DBL_EPSILON * the largest. dim - rank is the number of independent
 * Casimirs to expect near a generic x. */
LPI_API int lpi_poisson_rank(const lpi_system *sys, const double *x, size_t n, size_t *rank);

/* The 8-dimensional algebra of second and fourth moments (McLachlan 1993):
 * x = (<q^2>, <qp>, <p^2>, <q^4>, <q^3 p>, <q^2 p^2>, <q p^3>, <p^4>), indices
 * 0..7. Casimirs built in: I = x4 x8 - 4 x5 x7 + 3 x6^2 and
 * K = det [[x4,x5,x6],[x5,x6,x7],[x6,x7,x8]] (1-based names as in the paper).
 * Abelian index sets for lpi_add_piece: {0,3}, {1,5}, {2,7}, {3,4,5,6,7}. */
LPI_API int lpi_moments_create(lpi_system **out);

/* Appends the piece H(x1 x3) (indices 0 and 2, not abelian) with its closed-form
 * flow; h and dh give H(u) and H'(u) at u = x1 x3. */
LPI_API int lpi_moments_add_product_piece(lpi_system *sys, lpi_scalar_fn h, lpi_scalar_fn dh,
                                          void *user);
/* ---- Sine-Euler (Zeitlin's su(N) model of 2D Euler; needs FFTW3) ------- *
 * Modes w_m, m in Z_N x Z_N, N odd >= 3, eps = 2 pi / N, w_{-m} = conj(w_m):
 *   dw_m/dt = sum_{n != 0} sin(eps m x n) / (eps |n|^2) w_{m+n} w_{-n}
 * (McLachlan 1993, eq. 5), H = 1/2 sum_{n != 0} |w_n|^2 / |n|^2, |n| from the
 * representative of n in -M..M (N = 2M+1). Integrated by exact flows of one
 * piece per direction of the projective line over Z_N (N + 1 directions for
 * prime N); every Casimir (the spectrum of W = sum_m w_m J_m) is kept to
 * round-off. See lpi_sine_euler_create(3). */

/* Built without FFTW3: LPI_ERR_UNSUPPORTED. N even or < 3: LPI_ERR_INVALID.
 * A system needing more bytes (about 42 N^2, 58 N^2 for composite N) than
 * the machine's physical memory: LPI_ERR_NO_MEMORY, before anything is
 * allocated. */
LPI_API int lpi_sine_euler_create(lpi_system **out, int32_t N);
/* N of a sine-Euler system (LPI_ERR_UNSUPPORTED for another kind of system). */
LPI_API int lpi_sine_euler_size(const lpi_system *sys, int32_t *N);

/* Modes, n = 2*N*N doubles: entry [a*N + b] is mode (a, b) mod N (FFT order)
 * as interleaved re, im. set checks finiteness and Hermitian symmetry
 * (tolerance 1e-10 * max |w_m|) and stores the symmetrised field; resets the
 * time to 0. The inert mode w_0 keeps its real part (its imaginary part must
 * be 0 within the tolerance, and is dropped). */
LPI_API int lpi_sine_euler_set_modes(lpi_system *sys, const double *re_im, size_t n);
LPI_API int lpi_sine_euler_get_modes(const lpi_system *sys, double *re_im, size_t n);
/* Real vorticity on the grid, n = N*N: entry [a*N + b] is
 * w(2 pi a / N, 2 pi b / N) = sum_m w_m exp(i (m1 x + m2 y)). Setting modes
 * or a grid whose conversion overflows a double gives LPI_ERR_OVERFLOW.
 * Setting a grid, as setting modes, resets the time to 0. */
LPI_API int lpi_sine_euler_set_grid(lpi_system *sys, const double *w, size_t n);
LPI_API int lpi_sine_euler_get_grid(const lpi_system *sys, double *w, size_t n);

/* Enstrophy 1/2 sum_m |w_m|^2 (w_0 included) = tr(W^2) / (2N). Here and in
 * the getters below, a value that overflows a double gives LPI_ERR_OVERFLOW
 * naming it (the output is then untouched). */
LPI_API int lpi_sine_euler_enstrophy(const lpi_system *sys, double *out);
/* out[k-1] = (1/N) tr W^k for k = 1 .. kmax (kmax >= 1; O(kmax N^3), less
 * where a trace overflows, which ends the call there, or a power of W is zero,
 * after which every trace is 0). */
LPI_API int lpi_sine_euler_casimir_traces(const lpi_system *sys, int32_t kmax, double *out);

/* Measures the FFT floor: FFTW executing, with this system's plans, buffers
 * and thread count, the transforms of nsteps x lpi_flows_per_step flows of
 * the current method (and nothing else): those of nsteps steps in a long run
 * (one lpi_step call runs one flow more, its first). Gives seconds per step
 * and transforms per step.
 * A diagnostic: the time per step over this floor is what the library adds to
 * FFTW on this machine and thread count, the figure to judge its overhead by
 * (and to compare thread counts or wisdom). The state is not touched.
 * LPI_ERR_OVERFLOW when the flow count nsteps x flows per step overflows. */
LPI_API int lpi_sine_euler_fft_floor(lpi_system *sys, int64_t nsteps, double *seconds_per_step,
                                     double *transforms_per_step);

/* How FFTW chooses the plans of a sine-Euler system's line transforms:
 * "estimate" (the default), "measure" or "patient". Estimate is
 * deterministic: a run gives the same bits in every process on the same
 * machine and FFTW build, so a checkpoint resumed in another process continues
 * bit for bit. Measure and patient time candidate plans (up to seconds per
 * N): the transforms are often faster (1.0-1.7x for N = 61 .. 1021 here), but
 * another process may choose other plans, which changes results at
 * round-off. Every rigor uses the wisdom the process holds for a transform
 * (imported, or planned earlier at that rigor or higher): importing the same
 * wisdom first makes measured plans, and their results, the same in every
 * process. set_planning plans at once (on failure the old plans stay);
 * get_planning sets *rigor to a static string. Not stored in checkpoints (a
 * property of the process, like wisdom and threads). Other kinds:
 * LPI_ERR_UNSUPPORTED; an unknown name: LPI_ERR_INVALID. */
LPI_API int lpi_sine_euler_set_planning(lpi_system *sys, const char *rigor);
LPI_API int lpi_sine_euler_get_planning(const lpi_system *sys, const char **rigor);

/* ---- The sine-bracket family: any quadratic Hamiltonian ------------------ *
 * The same bracket and splitting integrate every Hamiltonian quadratic and
 * diagonal in the modes plus a linear term,
 *   H(w) = 1/2 sum_{n != 0} lambda_n |w_n|^2 + sum_{n != 0} conj(f_n) w_n,
 * with the flow dW/dt = (i / (2 eps)) [P, W], P = sum_{n != 0} psi_n J_n and
 * the stream function psi_n = lambda_n w_n + f_n. Euler is lambda_n = 1/|n|^2,
 * f = 0, the default; SQG is lambda_n = 1/|n|, QG with deformation wavenumber
 * k_d is 1/(|n|^2 + k_d^2), Euler over a topography h (q = w + h) is
 * lambda_n = 1/|n|^2, f_n = -h_n/|n|^2. See lpi_sine_euler_set_hamiltonian(3). */

/* Sets lambda (n_lambda = N*N reals) and f (n_f = 2*N*N doubles, interleaved
 * re, im; or f = NULL and n_f = 0 for f = 0), both in the modes' layout (entry
 * [a*N + b] is mode (a, b) mod N). lambda must be finite and symmetric
 * (lambda_{-n} = lambda_n), f finite and Hermitian (f_{-n} = conj(f_n)), each
 * within 1e-10 times its largest entry (the mean of each pair is stored); the
 * zero mode's entries are ignored. Every method, lpi_energy (which is this H),
 * the diagnostics and checkpoints use it from the next call on; the state and
 * the time are kept. Bad input changes nothing: LPI_ERR_NULL, LPI_ERR_SIZE,
 * LPI_ERR_NONFINITE, LPI_ERR_INVALID. */
LPI_API int lpi_sine_euler_set_hamiltonian(lpi_system *sys, const double *lambda, size_t n_lambda,
                                           const double *f, size_t n_f);
/* The stream function on the grid, n = N*N: entry [a*N + b] is
 * psi(2 pi a / N, 2 pi b / N) = sum_{n != 0} psi_n exp(i (n1 x + n2 y)). */
LPI_API int lpi_sine_euler_get_stream(const lpi_system *sys, double *psi, size_t n);
/* Shell sums of the energy and enstrophy spectra: the mode n (representative
 * in -M..M) lies in shell k = floor(|n| + 1/2); energy[k-1] sums the terms
 * 1/2 lambda_n |w_n|^2 + Re(conj(f_n) w_n) of H over the shell (the shells add
 * up to H) and enstrophy[k-1] sums 1/2 |w_n|^2 (adding up to the enstrophy
 * less 1/2 w_0^2), k = 1 .. K, K = floor(M sqrt 2 + 1/2). *shells is set to K;
 * with both buffers NULL and n = 0 the call only queries K (LPI_OK), otherwise
 * n < K gives LPI_ERR_SIZE (*shells still set). */
LPI_API int lpi_sine_euler_spectrum(const lpi_system *sys, double *energy, double *enstrophy,
                                    size_t n, size_t *shells);

/* Threads used inside one step (OpenMP over the lines of a direction);
 * 1 <= n <= 4 x the processors available (omp_get_num_procs), else
 * LPI_ERR_INVALID. Results are identical to the bit for every n. Models that
 * integrate on one thread accept only n = 1 (LPI_ERR_UNSUPPORTED otherwise), as
 * does a build without OpenMP. Before a parallel region could need new
 * threads on the calling thread (here, and in lpi_step when the thread or the
 * count changed), the library first starts and joins n - 1 threads of its own:
 * when the system refuses one (process or memory limits), the call fails with
 * LPI_ERR_NO_MEMORY and the count is unchanged, instead of the OpenMP runtime
 * ending the process. See lpi_set_threads(3) for what this cannot cover. */
LPI_API int lpi_set_threads(lpi_system *sys, int32_t n);

/* FFTW wisdom (shared by the whole process; planning is serialised inside the
 * library, and with the host's own plans through FFTW's planner hooks, which
 * the library sets as it loads; wisdom calls of the host's own are not). Built without FFTW3: LPI_ERR_UNSUPPORTED. export_string writes at
 * most size bytes including the NUL and sets *length to the length without
 * it; with buf == NULL and size == 0 it only queries the length (LPI_OK),
 * otherwise size <= *length gives LPI_ERR_SIZE with buf untouched.
 * A file that cannot be opened, read or written: LPI_ERR_IO (the message
 * gives the path and the reason); text that is not wisdom, or an empty path:
 * LPI_ERR_INVALID. */
LPI_API int lpi_fftw_wisdom_import_file(const char *path);
LPI_API int lpi_fftw_wisdom_export_file(const char *path);
LPI_API int lpi_fftw_wisdom_import_string(const char *wisdom);
LPI_API int lpi_fftw_wisdom_export_string(char *buf, size_t size, size_t *length);

/* ---- Checkpoints ---------------------------------------------------------- *
 * A checkpoint holds everything that determines a system's future: its kind
 * and parameters, split, method (a custom composition's weights included),
 * implicit settings, time and full working state (with the compensated
 * carry), so a loaded system continues the trajectory to the bit. It is a
 * versioned binary format with magic bytes, a byte-order marker and a CRC-32;
 * a truncated, corrupted, foreign, other-byte-order or newer-version checkpoint
 * is refused with LPI_ERR_FORMAT and a message saying which. The thread count
 * is not stored (results do not depend on it); a loaded system uses 1.
 * Rigid body, pendulum and sine-Euler can be saved; generic and moment systems
 * cannot (their pieces are user callbacks): LPI_ERR_UNSUPPORTED. See lpi_save(3). */

/* Writes the checkpoint to path atomically (a temporary file in the same
 * directory, fsync, rename): path holds either its old contents or the whole
 * new checkpoint. LPI_ERR_IO with the reason when the file system refuses. */
LPI_API int lpi_save(const lpi_system *sys, const char *path);
/* Creates a new system from a checkpoint file (*out NULL on failure). */
LPI_API int lpi_load(lpi_system **out, const char *path);
/* The checkpoint in memory: *size is set to its length in bytes. With
 * buf == NULL and capacity == 0 this only queries the size; otherwise
 * capacity < *size gives LPI_ERR_SIZE with buf untouched. */
LPI_API int lpi_save_buffer(const lpi_system *sys, void *buf, size_t capacity, size_t *size);
LPI_API int lpi_load_buffer(lpi_system **out, const void *buf, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* LIEPOISSON_H */
