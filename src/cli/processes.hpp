// lpi under an MPI launcher (mpirun -np P lpi run sine-euler ...): when lpi
// is built with libliepoisson_mpi and started by a launcher, it joins
// MPI_COMM_WORLD, and sine-Euler systems are spread over its processes. The
// processes make the same calls in the same order; rank 0 alone writes files
// and prints. Without MPI (or started plainly) there is one process and every
// function here is the obvious one.
#pragma once

#include <cstdint>
#include <string>

#include <liepoisson.h>

namespace lpi_cli {

// Joins MPI when a launcher started this process (MPI_Finalize at exit);
// the other processes than rank 0 then print nothing (their stdout and
// stderr go to /dev/null: every status is the same on all processes).
void start_processes(int *argc, char ***argv);
int process_count();
// Whether this process writes the output (rank 0).
bool writes_output();
// Sine-Euler of size N: spread over the processes when there are several.
int create_sine_euler(lpi_system **out, int32_t N);
// lpi_load, spread over the processes when there are several.
int load_checkpoint(lpi_system **out, const char *path);
// The signal that stops the run, agreed by all processes (collective: every
// process calls it at the same step): the largest any of them caught, or 0.
int agreed_signal(int caught);
// Returns once every process has called it (files read before rank 0
// rewrites them).
void synchronize();
// Whether a step that may fail on some processes only failed on any
// (collective: every process calls it at the same point). Such steps are
// rank 0's alone (the files it writes) or each process's own (the files it
// reads, a limit of its own such as --threads): a process that stopped there
// alone would leave the others waiting forever in the next collective call.
// `status` is this process's exit status (0 or false: it succeeded), `why`
// its message (empty: none, or printed already by rank 0). Returns 0 where
// every process succeeded, else on every process the status of the lowest
// failing rank, whose message rank 0 prints on standard error.
int agreed_failure(int status, const std::string &why = "");
// Whether every process has the same `value` (collective).
bool same_everywhere(int64_t value);

}  // namespace lpi_cli
