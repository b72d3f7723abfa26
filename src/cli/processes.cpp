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

// Whether every process was given rank 0's command line. The processes make
// the same calls in the same order only if they parse the same options: an
// option refused, or a call made, on some processes alone (an MPMD launch,
// `mpirun -np 1 lpi ... : -np 1 lpi ...`) left the others waiting forever.
bool same_command_line(int argc, char **argv) {
    std::string line;
    for (int i = 0; i < argc; ++i) line.append(argv[i]).push_back('\0');
    long long size = static_cast<long long>(line.size());
    MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    std::string first(static_cast<std::size_t>(size), '\0');
    if (world_rank == 0) first = line;
    MPI_Bcast(&first[0], static_cast<int>(size), MPI_CHAR, 0, MPI_COMM_WORLD);
    int same = first == line;
    MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return same != 0;
}

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
    if (world_size > 1 && !same_command_line(*argc, *argv)) {
        std::fprintf(stderr, "lpi: the processes were given different command lines; every process "
                             "of an MPI run must run the same lpi command with the same options\n");
        std::exit(2);
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

int agreed_failure(int status, const std::string &why) {
    int first = status != 0 ? world_rank : world_size;
    if (world_size > 1) MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == world_size) return 0;
    std::string message = why;
    if (world_size > 1) {
        // Only rank 0 prints (the others' stderr is /dev/null): it takes the
        // first failing process's status and message.
        int sizes[2] = {status, static_cast<int>(message.size())};
        MPI_Bcast(sizes, 2, MPI_INT, first, MPI_COMM_WORLD);
        status = sizes[0];
        message.resize(static_cast<std::size_t>(sizes[1]));
        MPI_Bcast(&message[0], sizes[1], MPI_CHAR, first, MPI_COMM_WORLD);
    }
    if (!message.empty()) std::fprintf(stderr, "%s\n", message.c_str());
    return status;
}

bool same_everywhere(int64_t value) {
    if (world_size == 1) return true;
    long long least = static_cast<long long>(value), most = least;
    MPI_Allreduce(MPI_IN_PLACE, &least, 1, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &most, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    return least == most;
}

#else

void start_processes(int *, char ***) {}
int process_count() { return 1; }
bool writes_output() { return true; }
int create_sine_euler(lpi_system **out, int32_t N) { return lpi_sine_euler_create(out, N); }
int load_checkpoint(lpi_system **out, const char *path) { return lpi_load(out, path); }
int agreed_signal(int caught) { return caught; }
void synchronize() {}

int agreed_failure(int status, const std::string &why) {
    if (status != 0 && !why.empty()) std::fprintf(stderr, "%s\n", why.c_str());
    return status;
}

bool same_everywhere(int64_t) { return true; }

#endif

}  // namespace lpi_cli
