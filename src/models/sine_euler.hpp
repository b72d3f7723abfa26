// Sine-Euler: Zeitlin's su(N) truncation of 2D Euler on the torus, integrated
// by McLachlan's explicit splitting (1993, section 3) with one piece per
// direction of the projective line over Z_N. The parts are in sine_euler/:
// indexing and projective_line (the geometry, backend-independent),
// transforms (FFTW), kernels (gather, phase, scatter), coordinates, and the
// model that glues them; sine_euler_matrix.cpp holds the matrix form.
//
// Working layout: the full N x N complex mode array, 2 N^2 doubles, entry
// [a*N + b] = mode (a, b) mod N as interleaved re, im (FFT order).
// Public coordinates (lpi_set_state, dimension N^2): x[0] = w_0 (real), then
// re, im of w_m for the half plane m = (0, 1) .. (0, M), then
// (a, -M) .. (a, M) for a = 1 .. M; the other half is the conjugate.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "../core/model.hpp"
#include "sine_euler/hamiltonian.hpp"

namespace lpi {

// Seconds and FFTs per step of the transforms of a splitting alone.
struct TransformTiming {
    double seconds_per_step;
    double transforms_per_step;
};

// How FFTW chooses the plans of the line transforms. Estimate (the default)
// is deterministic: the same plans, and so the same bits, in every process
// of a machine and FFTW build. Measure and Patient time candidate plans
// while planning: faster transforms, but another process may choose others
// and round differently. Every rigor uses wisdom the process holds for the
// transform (imported, or planned earlier at that rigor or higher), so
// importing the same wisdom makes measured plans reproducible too.
enum class FftPlanning { Estimate, Measure, Patient };
const char *planning_name(FftPlanning planning);
// LPI_ERR_INVALID naming the choices for an unknown name.
FftPlanning planning_from_name(const std::string &name);

// What the C API needs of a sine-Euler model beyond lpi::Model.
class SineEulerModel : public Model {
public:
    // N of su(N): the mode array is N x N.
    virtual int truncation() const = 0;
    // Validates modes (2 N^2 doubles: finite, Hermitian within tolerance) and
    // writes the public coordinates x (N^2) of the symmetrised field.
    virtual void public_from_modes(const double *re_im, double *x) const = 0;
    // Validates a real grid (N^2, finite; LPI_ERR_OVERFLOW when its Fourier
    // transform overflows) and writes public coordinates.
    virtual void public_from_grid(const double *grid, double *x) const = 0;
    virtual void grid(const double *state, double *out) const = 0;
    virtual double enstrophy(const double *state) const = 0;
    // sine_euler_traces of the state: kmax values or fewer (see there).
    virtual std::vector<double> casimir_traces(const double *state, int kmax) const = 0;
    // The Hamiltonian every method, the energy and the diagnostics use
    // (Euler's until set; see sine_euler/hamiltonian.hpp): a copy, which a
    // model spread over processes assembles on request (none holds it whole).
    virtual sine_euler::Hamiltonian hamiltonian() const = 0;
    virtual void set_hamiltonian(sine_euler::Hamiltonian H) = 0;
    // Runs the FFTs of `steps` steps of `flows_per_step` line flows each
    // (cycling over the pieces) on the model's own plans, buffers and
    // threads, on zeros, and times them: the floor under a splitting step.
    // LPI_ERR_INVALID for steps < 1, LPI_ERR_OVERFLOW when the flow count
    // overflows.
    virtual TransformTiming time_transforms(std::size_t flows_per_step, std::int64_t steps) = 0;
    // Plans the line transforms anew at this rigor (now, so its cost and any
    // failure come here; on failure the old plans stay).
    virtual void set_planning(FftPlanning planning) = 0;
    virtual FftPlanning planning() const = 0;
};

// Throws LPI_ERR_UNSUPPORTED when built without FFTW3, LPI_ERR_INVALID for
// even N or N < 3, LPI_ERR_NO_MEMORY (before allocating anything) when the
// system would need more bytes than the machine's physical memory.
std::unique_ptr<Model> make_sine_euler(int N);

// LPI_ERR_NO_MEMORY naming `what` when `bytes` pass this machine's physical
// memory (nothing checked where the system does not say how much it has):
// zero-filling vectors larger than the machine brings the out-of-memory
// killer, not std::bad_alloc. For a system spread over processes, each
// process asks for its own share.
void require_physical_memory(double bytes, const std::string &what);

// The FFTW planner is not thread-safe: every plan creation, destruction and
// wisdom operation in the library holds this lock, and through FFTW's planner
// hooks every plan and destroy_plan of the host's too. Re-entrant (the hooks
// take it again inside the library's plans); a fork(2) waits for it.
class FftwPlannerLock {
public:
    void lock();
    void unlock();
};
FftwPlannerLock &fftw_planner_lock();

// FFTW ends the process when one of its own allocations fails (its
// malloc_plain asserts on the result): in a planner, in wisdom, or in an
// execution that allocates buffers (Rader's, buffered loops). So before each,
// the memory FFTW may take is mapped and given back at once; where it cannot
// be had, the call fails here with LPI_ERR_NO_MEMORY, the state unchanged, as
// for an allocation of ours. What FFTW takes for transforms of length N:
// planning (plans, twiddles, Bluestein's padded buffers, the planner's own
// tables) 2048 N bytes, at least 4 MiB; executing (Rader's buffer, buffered
// loops of 8 transforms) 1024 N bytes a thread.
std::size_t fftw_planning_headroom(int N);
void require_fftw_headroom(std::size_t bytes, const std::string &what);
// Before a step's transforms: the execution's bound, where it reaches 64 KiB
// (below, the buffers come from freed heap blocks of their sizes).
void require_fftw_execution_headroom(int N, int threads);

// ---- matrix form (sine_euler_matrix.cpp) ----------------------------------
// W = sum_m w_m J_m, J_m = exp(2 pi i m1 m2 / N) g^m1 h^m2 (the transforms:
// sine_euler/matrix_form.hpp). O(N^3) products, used only on request.
// The vector field of eq. 5 through dW/dt = (i / (2 eps)) [P, W], P the
// stream function of H, exactly Hermitian: the half plane is computed, the
// other half is its conjugate and the inert mode w_0 does not move.
void sine_euler_matrix_vector_field(const sine_euler::Hamiltonian &H, const double *modes,
                                    double *rate);
// (1/N) tr W^k for k = 1 .. kmax, or fewer: the list ends at the first
// trace that is not finite (its callers refuse the whole call there, so the
// later powers, each N^3 operations, and a list of kmax values would be work
// and memory for nothing), and before the first power of W that is exactly
// zero (W = 0, or a small W whose powers underflow), whose trace and those
// of every later power are 0.
std::vector<double> sine_euler_traces(int N, const double *modes, int kmax);
// Sorted eigenvalues of the Hermitian W (LAPACK zheevd); LPI_ERR_OVERFLOW
// when W has overflowed, LPI_ERR_UNSUPPORTED naming LAPACK when built
// without it.
void sine_euler_spectrum(int N, const double *modes, double *out);

}  // namespace lpi
