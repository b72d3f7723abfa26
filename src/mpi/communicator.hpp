// The library's own MPI communicator: a duplicate of the user's, with
// MPI_ERRORS_RETURN, so that a failed MPI call becomes an lpi::Error
// (LPI_ERR_INTERNAL naming the call) instead of aborting the program, and the
// library's messages never meet the user's. Every function here is
// collective unless it says otherwise.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace lpi {
namespace mpi {

class Communicator {
public:
    // LPI_ERR_INVALID when MPI is not initialised (or already finalised) or
    // comm is MPI_COMM_NULL.
    explicit Communicator(MPI_Comm comm);
    ~Communicator();
    Communicator(const Communicator &) = delete;
    Communicator &operator=(const Communicator &) = delete;

    int rank() const { return rank_; }  // local
    int size() const { return size_; }  // local
    // Whether threads other than the caller may exist while it makes MPI
    // calls (MPI initialised at MPI_THREAD_FUNNELED or higher). Local.
    bool allows_threads() const;

    // Complex values (2 doubles each): counts and offsets in complex units.
    void alltoallv(const double *send, const std::vector<int> &send_counts,
                   const std::vector<int> &send_offsets, double *receive,
                   const std::vector<int> &receive_counts,
                   const std::vector<int> &receive_offsets) const;
    void allgatherv(const double *send, int count, double *receive, const std::vector<int> &counts,
                    const std::vector<int> &offsets) const;
    // One value from each process, in rank order, on every process.
    std::vector<double> allgather(double value) const;
    std::vector<long long> allgather(long long value) const;
    double max(double value) const;
    // LPI_ERR_INVALID on every process, naming `what`, when the processes'
    // values differ (fingerprints of what each process was given).
    void require_same(long long value, const std::string &what) const;
    bool all(bool value) const;
    void broadcast(double *values, std::size_t n) const;  // from rank 0
    void broadcast(unsigned char *bytes, std::size_t n) const;  // from rank 0

    // Runs action on every process; when it throws on any of them, every
    // process throws the status and message of the lowest such rank, so
    // that no process goes on alone.
    void agree(const std::function<void()> &action) const;
    // Runs action on rank 0 only and gives its outcome to every process.
    void on_root(const std::function<void()> &action) const;

private:
    void check(int code, const char *call) const;  // throws LPI_ERR_INTERNAL
    // Every process learns the outcome (status, message) of the lowest rank
    // that failed; throws it when there is one.
    void share_outcome(int status, const std::string &message) const;
    MPI_Comm comm_ = MPI_COMM_NULL;
    int rank_ = 0, size_ = 1;
};

}  // namespace mpi
}  // namespace lpi
