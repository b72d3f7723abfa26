/* Sine-Euler on MPI: run under `mpirun -np 4`; the processes split into
 * communicators of P = 1, 2 and 4 and each times leapfrog steps at the same
 * N (default 255, 31 in the quick mode; argv[1] sets it), side by side: seconds per step, the
 * speed-up over P = 1, the bytes each process sends per step, and the share
 * of the step spent inside MPI collectives (counted by the PMPI wrappers
 * below, which the library's calls reach); and P = 1 against the
 * one-process library (lpi_sine_euler_create) on the same field: what the
 * spread layout and its exchanges cost where nothing travels. Prints
 * figures; asserts nothing. */
#include <liepoisson_mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include "bench_common.h"

static double sent_bytes, mpi_seconds;

/* The library's collectives, counted and timed (the PMPI profiling interface). */
int MPI_Alltoallv(const void *send, const int *send_counts, const int *send_offsets, MPI_Datatype send_type,
                  void *receive, const int *receive_counts, const int *receive_offsets,
                  MPI_Datatype receive_type, MPI_Comm comm) {
    int size, rank, type_size;
    MPI_Comm_size(comm, &size);
    MPI_Comm_rank(comm, &rank);
    MPI_Type_size(send_type, &type_size);
    for (int q = 0; q < size; ++q)
        if (q != rank) sent_bytes += (double)send_counts[q] * type_size;
    const double start = MPI_Wtime();
    const int status = PMPI_Alltoallv(send, send_counts, send_offsets, send_type, receive, receive_counts,
                                      receive_offsets, receive_type, comm);
    mpi_seconds += MPI_Wtime() - start;
    return status;
}

int MPI_Allreduce(const void *send, void *receive, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
    const double start = MPI_Wtime();
    const int status = PMPI_Allreduce(send, receive, count, type, op, comm);
    mpi_seconds += MPI_Wtime() - start;
    return status;
}

static void check(int status, lpi_system *sys, const char *what) {
    if (status != LPI_OK) {
        fprintf(stderr, "bench_sine_euler_mpi: %s: %s\n", what, lpi_last_error(sys));
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
}

int main(int argc, char **argv) {
    int provided;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    int rank, world;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world);
    const int N = argc > 1 ? atoi(argv[1]) : bench_quick() ? 31 : 255;
    const int steps = argc > 2 ? atoi(argv[2]) : bench_quick() ? 1 : 4;
    const size_t n = (size_t)N * N;
    double *x = malloc(n * sizeof *x);
    uint64_t s = 88172645463325252ull;
    for (size_t i = 0; i < n; ++i) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        x[i] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
    }
    if (rank == 0)
        printf("sine-Euler N = %d, leapfrog, %d steps, %d processes on this machine\n"
               "   P   s/step  speed-up  bytes sent/process/step  share in MPI\n",
               N, steps, world);
    /* The one-process library, timed as the rows below (rank 0; the others wait). */
    double serial = 0.0;
    if (rank == 0) {
        lpi_system *sys = NULL;
        check(lpi_sine_euler_create(&sys, N), NULL, "create");
        check(lpi_set_state(sys, x, n), sys, "set_state");
        check(lpi_step(sys, 1e-3, 1), sys, "warm-up step");
        const double start = MPI_Wtime();
        check(lpi_step(sys, 1e-3, steps), sys, "step");
        serial = (MPI_Wtime() - start) / steps;
        lpi_destroy(sys);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    double one = 0.0;
    for (int P = 1; P <= world; P *= 2) {
        MPI_Comm comm;
        MPI_Comm_split(MPI_COMM_WORLD, rank < P ? 0 : MPI_UNDEFINED, rank, &comm);
        if (comm != MPI_COMM_NULL) {
            lpi_system *sys = NULL;
            check(lpi_sine_euler_create_mpi(&sys, N, comm), NULL, "create");
            check(lpi_set_state(sys, x, n), sys, "set_state");
            check(lpi_step(sys, 1e-3, 1), sys, "warm-up step");  /* plans */
            sent_bytes = mpi_seconds = 0.0;
            MPI_Barrier(comm);
            const double start = MPI_Wtime();
            check(lpi_step(sys, 1e-3, steps), sys, "step");
            MPI_Barrier(comm);
            const double seconds = (MPI_Wtime() - start) / steps;
            double bytes = sent_bytes / steps, share = mpi_seconds / steps / seconds, most_bytes, most_share;
            MPI_Reduce(&bytes, &most_bytes, 1, MPI_DOUBLE, MPI_MAX, 0, comm);
            MPI_Reduce(&share, &most_share, 1, MPI_DOUBLE, MPI_MAX, 0, comm);
            if (P == 1) one = seconds;
            if (rank == 0)
                printf("%4d  %7.3f  %8.2f  %23.3g  %11.0f%%\n", P, seconds, one / seconds, most_bytes,
                       100.0 * most_share);
            lpi_destroy(sys);
            MPI_Comm_free(&comm);
        }
        MPI_Bcast(&one, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    }
    if (rank == 0)
        printf("P = 1 over the one-process library (%.3f s/step): %.2fx (the spread layout's exchanges "
               "reorder the field; no bytes travel)\n", serial, one / serial);
    free(x);
    MPI_Finalize();
    return 0;
}
