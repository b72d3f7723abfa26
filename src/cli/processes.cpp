#include "processes.hpp"

#include <cstdio>
#include <cstdlib>

#if LPI_CLI_MPI
#include <liepoisson_mpi.h>
#endif

namespace lpi_cli {

#if LPI_CLI_MPI

namespace {

int world_size = 1, world_rank = 0;

// Launchers announce themselves in the environment: Open MPI, PMIx, and the
// PMI of MPICH and Slurm. A plain start stays a one-process program, without
// MPI's start-up cost.
bool launched_by_mpi() {
    for (const char *name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
        if (std::getenv(name)) return true;
    return false;
}

void finalize() { MPI_Finalize(); }

}  // namespace

void start_processes(int *argc, char ***argv) {
    if (!launched_by_mpi()) return;
    int provided = MPI_THREAD_SINGLE;  // --threads: the library's threads make no MPI call
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    std::atexit(finalize);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    if (world_rank != 0) {
        if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr)) std::exit(1);
    }
}

int process_count() { return world_size; }
bool writes_output() { return world_rank == 0; }

int create_sine_euler(lpi_system **out, int32_t N) {
    return world_size > 1 ? lpi_sine_euler_create_mpi(out, N, MPI_COMM_WORLD) : lpi_sine_euler_create(out, N);
}

int load_checkpoint(lpi_system **out, const char *path) {
    if (world_size == 1) return lpi_load(out, path);
    // A checkpoint of another kind stays on every process whole.
    const int status = lpi_load_mpi(out, path, MPI_COMM_WORLD);
    return status == LPI_ERR_UNSUPPORTED ? lpi_load(out, path) : status;
}

int agreed_signal(int caught) {
    if (world_size == 1) return caught;
    int agreed = caught;
    MPI_Allreduce(&caught, &agreed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return agreed;
}

void synchronize() {
    if (world_size > 1) MPI_Barrier(MPI_COMM_WORLD);
}

#else

void start_processes(int *, char ***) {}
int process_count() { return 1; }
bool writes_output() { return true; }
int create_sine_euler(lpi_system **out, int32_t N) { return lpi_sine_euler_create(out, N); }
int load_checkpoint(lpi_system **out, const char *path) { return lpi_load(out, path); }
int agreed_signal(int caught) { return caught; }
void synchronize() {}

#endif

}  // namespace lpi_cli
