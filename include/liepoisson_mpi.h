/* liepoisson on MPI: sine-Euler spread over the processes of a communicator.
 *
 * An optional part (built when CMake finds MPI and FFTW3): programs include
 * this header and link libliepoisson_mpi, which carries the whole C API of
 * liepoisson.h as well, so they link it instead of libliepoisson. The
 * handles it makes are ordinary lpi_system handles: every function of
 * liepoisson.h works on them, collectively, when every process of the
 * communicator makes the same calls in the same order with the same
 * arguments (compared first: arguments that differ give LPI_ERR_INVALID on
 * every process; thread counts may differ, and reads that stay on one
 * process, such as lpi_time, may be made by one alone): setters take the
 * whole field on every process, getters return it on every process, and a
 * failure on any process returns the same status and message on all of
 * them. While stepping, each process holds only its share of the field and
 * of the Hamiltonian (O(N^2 / P + N) bytes, see docs/scaling.md).
 * Threads per process (lpi_set_threads) need MPI initialised with
 * MPI_Init_thread at MPI_THREAD_FUNNELED or higher. Splitting methods only: the baselines (rk4, implicit-midpoint and the
 * matrix methods) need the whole state on one process and are refused with
 * LPI_ERR_UNSUPPORTED. lpi_save writes one file, from rank 0, which
 * lpi_load (one process) or lpi_load_mpi (spread) reads back. */
#ifndef LIEPOISSON_MPI_H
#define LIEPOISSON_MPI_H

#include <mpi.h>

#include "liepoisson.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Collective over comm (duplicated: the library's messages never meet the
 * program's; MPI errors on it are returned as LPI_ERR_INTERNAL, never
 * aborting). Sine-Euler of order N (odd, >= 3) as lpi_sine_euler_create
 * makes it, its lines spread over the processes of comm (any count; more
 * than (N-1)/2 leaves some idle). LPI_ERR_INVALID when MPI is not running,
 * comm is MPI_COMM_NULL or an intercommunicator, or the processes pass
 * different N. The handle must be
 * destroyed (lpi_destroy, collective) before MPI_Finalize; a call on it
 * after MPI_Finalize returns LPI_ERR_INVALID. Observers may read the system,
 * making the same calls on every process (see lpi_sine_euler_create_mpi(3));
 * a callback of another system may not call it, nor create or load one
 * (LPI_ERR_INVALID: a process whose callback failed would leave the others
 * waiting). */
LPI_API int lpi_sine_euler_create_mpi(lpi_system **out, int32_t N, MPI_Comm comm);

/* Collective: the checkpoint file at path (read by rank 0) as a sine-Euler
 * system spread over comm, with its method, time and state; the statuses of
 * lpi_load, and LPI_ERR_UNSUPPORTED for a checkpoint of another kind. */
LPI_API int lpi_load_mpi(lpi_system **out, const char *path, MPI_Comm comm);

#ifdef __cplusplus
}
#endif

#endif /* LIEPOISSON_MPI_H */
