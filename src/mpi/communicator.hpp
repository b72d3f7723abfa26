// The library's own MPI communicator: a duplicate of the user's, with
// MPI_ERRORS_RETURN, so that a failed MPI call becomes an lpi::Error
// (LPI_ERR_INTERNAL naming the call) instead of aborting the program, and the
// library's messages never meet the user's. Every function here is
// collective unless it says otherwise.
//
// What keeps the processes in step: a call on a spread system opens with
// require_same, and from there every process makes the same collectives
// unless one fails, which only an agreement's action may do (agree,
// on_root: the failure is shared at its end). So nothing that may throw on
// one process alone (an allocation) stands between two collectives outside
// an action, no action makes a collective of its own (an observer's calls on
// the system, each opening with require_same, aside), and these functions
// allocate nothing before their MPI calls. require_same and the end of an
// agreement exchange one kind of header, so a process that left its
// observer (it failed there) while another calls the system from its own is
// seen by both, instead of pairing two different collectives: the call is
// refused, and the ending agreement waits for it.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "../core/action_ref.hpp"

namespace lpi {
namespace mpi {

class Communicator {
public:
    // A duplicate of comm (collective on it). LPI_ERR_INVALID when MPI is
    // not initialised (or already finalised), or comm is MPI_COMM_NULL or an
    // intercommunicator; LPI_ERR_NO_MEMORY on every process when one cannot
    // allocate it. Every collective after MPI_Finalize is refused alike
    // (LPI_ERR_INVALID): MPI would abort the program.
    static std::shared_ptr<const Communicator> duplicate(MPI_Comm comm);
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
    // One value from each process, in rank order, on every process (held
    // until the next collective).
    const std::vector<double> &allgather(double value) const;
    const std::vector<long long> &allgather(long long value) const;
    double max(double value) const;
    // LPI_ERR_INVALID on every process, naming `what`, when the processes'
    // values differ (fingerprints of what each process was given). A call
    // on the system opens with it.
    void require_same(long long value, const char *what) const;
    bool all(bool value) const;
    void broadcast(double *values, std::size_t n) const;  // from rank 0
    void broadcast(unsigned char *bytes, std::size_t n) const;  // from rank 0

    // Runs action on every process; when it throws on any of them, every
    // process throws the status and message of the lowest such rank, so
    // that no process goes on alone.
    void agree(ActionRef action) const;
    // Runs action on rank 0 only and gives its outcome to every process.
    void on_root(ActionRef action) const;

private:
    explicit Communicator(int size);  // buffers for size processes; no MPI call
    // What a process is doing when it sends a header.
    enum Stage : long long { kCalling = 1, kEndingAgreement = 2 };
    void check(int code, const char *call) const;  // throws LPI_ERR_INTERNAL
    void require_running() const;                 // LPI_ERR_INVALID after MPI_Finalize
    // Every process's (stage, value), into headers_.
    void exchange_headers(Stage stage, long long value) const;
    // Every process learns the outcome (status, message) of the lowest rank
    // that failed; throws it when there is one.
    void share_outcome(int status, const std::string &message) const;
    MPI_Comm comm_ = MPI_COMM_NULL;
    int rank_ = 0, size_ = 1;
    // Allocated once: the collectives allocate nothing.
    mutable std::vector<long long> headers_, gathered_integers_;
    mutable std::vector<double> gathered_;
    mutable std::vector<char> message_;
};

}  // namespace mpi
}  // namespace lpi
