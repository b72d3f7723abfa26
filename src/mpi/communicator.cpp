// MPI behind the library's Communicator (see the header). Every MPI call is
// made with thread cancellation held off (core/cancellation.hpp).
#include "communicator.hpp"

#include <algorithm>
#include <climits>
#include <new>
#include <stdexcept>
#include <string>

#include "../core/cancellation.hpp"
#include "../core/error.hpp"

namespace lpi {
namespace mpi {

namespace {

bool mpi_running() {
    int initialised = 0, finalised = 0;
    MPI_Initialized(&initialised);
    MPI_Finalized(&finalised);
    return initialised && !finalised;
}

// message = text, or empty when there is no memory for it: the outcome
// must reach the agreement's collective.
void set_message(std::string &message, const char *prefix, const char *text) noexcept {
    try {
        message = std::string(prefix) + text;
    } catch (...) {
        message.clear();
    }
}

// The status and message of whatever action() throws; LPI_OK when nothing.
int outcome_of(ActionRef action, std::string &message) {
    try {
        action();
        return LPI_OK;
    } catch (const Error &e) {
        set_message(message, "", e.what());
        return e.status();
    } catch (const std::bad_alloc &) {
        set_message(message, "", "out of memory");
        return LPI_ERR_NO_MEMORY;
    } catch (const std::length_error &) {
        set_message(message, "", "a buffer of the size this needs cannot be allocated");
        return LPI_ERR_NO_MEMORY;
    } catch (const std::exception &e) {
        set_message(message, "internal error: ", e.what());
        return LPI_ERR_INTERNAL;
    } catch (...) {
        rethrow_if_thread_ending();
        set_message(message, "internal error: ", "an exception of unknown type");
        return LPI_ERR_INTERNAL;
    }
}

// Fails with status, as every process that comes here does; the message
// (it allocates) is left empty where there is no memory for it, so that the
// status stays the others'.
template <class Message>
[[noreturn]] void fail_alike(lpi_status status, Message &&message) {
    std::string text;
    try {
        text = message();
    } catch (...) {
        text.clear();
    }
    fail(status, text);
}

// The longest message an agreement shares (its buffer is allocated once).
constexpr std::size_t kMessageCapacity = 2048;

}  // namespace

Communicator::Communicator(int size)
    : size_(size),
      headers_(2 * static_cast<std::size_t>(size)),
      gathered_integers_(static_cast<std::size_t>(size)),
      gathered_(static_cast<std::size_t>(size)),
      message_(kMessageCapacity) {}

std::shared_ptr<const Communicator> Communicator::duplicate(MPI_Comm comm) {
    const CancellationHeldOff held_off;
    if (!mpi_running())
        fail(LPI_ERR_INVALID, "MPI is not initialised (call MPI_Init first) or already finalised");
    if (comm == MPI_COMM_NULL) fail(LPI_ERR_INVALID, "the communicator is MPI_COMM_NULL");
    // Collectives on an intercommunicator pair the two groups instead of
    // joining them (one process of a group of one waited for ever). Every
    // process of one holds one: refused alike on each, without a collective.
    int inter = 0;
    if (MPI_Comm_test_inter(comm, &inter) == MPI_SUCCESS && inter)
        fail(LPI_ERR_INVALID, "the communicator is an intercommunicator (a system is spread over the "
                              "processes of one group: MPI_Intercomm_merge makes one)");
    int size = 0;
    if (MPI_Comm_size(comm, &size) != MPI_SUCCESS || size < 1)
        fail(LPI_ERR_INVALID, "the communicator's size cannot be read");
    // Made before the first collective, and agreed on in it: a process that
    // cannot allocate it does not leave the others waiting in MPI_Comm_dup.
    std::shared_ptr<Communicator> made;
    int ready = 0;
    try {
        made.reset(new Communicator(size));
        ready = 1;
    } catch (const std::bad_alloc &) {
    } catch (const std::length_error &) {
    }
    // The user's communicator returns its errors while it is used here, and
    // keeps its own handler otherwise.
    MPI_Errhandler users = MPI_ERRHANDLER_NULL;
    MPI_Comm_get_errhandler(comm, &users);
    MPI_Comm_set_errhandler(comm, MPI_ERRORS_RETURN);
    int all_ready = 0;
    int code = MPI_Allreduce(&ready, &all_ready, 1, MPI_INT, MPI_MIN, comm);
    MPI_Comm new_comm = MPI_COMM_NULL;
    if (code == MPI_SUCCESS && all_ready) code = MPI_Comm_dup(comm, &new_comm);
    MPI_Comm_set_errhandler(comm, users);
    MPI_Errhandler_free(&users);
    if (code != MPI_SUCCESS) {
        char text[MPI_MAX_ERROR_STRING];
        int length = 0;
        MPI_Error_string(code, text, &length);
        fail(LPI_ERR_INTERNAL, "duplicating the communicator failed: " + std::string(text, length));
    }
    if (!all_ready) fail(LPI_ERR_NO_MEMORY, "out of memory for the communicator on some process");
    made->comm_ = new_comm;
    made->check(MPI_Comm_set_errhandler(new_comm, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
    made->check(MPI_Comm_rank(new_comm, &made->rank_), "MPI_Comm_rank");
    return made;
}

Communicator::~Communicator() {
    const CancellationHeldOff held_off;
    if (comm_ != MPI_COMM_NULL && mpi_running()) MPI_Comm_free(&comm_);
}

bool Communicator::allows_threads() const {
    int level = MPI_THREAD_SINGLE;
    return MPI_Query_thread(&level) == MPI_SUCCESS && level >= MPI_THREAD_FUNNELED;
}

void Communicator::check(int code, const char *call) const {
    if (code == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    fail(LPI_ERR_INTERNAL, std::string(call) + " failed: " + std::string(text, length));
}

void Communicator::require_running() const {
    if (!mpi_running())
        fail(LPI_ERR_INVALID, "MPI is finalised: destroy a system spread over processes (lpi_destroy) "
                              "before MPI_Finalize");
}

void Communicator::alltoallv(const double *send, const std::vector<int> &send_counts,
                             const std::vector<int> &send_offsets, double *receive,
                             const std::vector<int> &receive_counts,
                             const std::vector<int> &receive_offsets) const {
    const CancellationHeldOff held_off;
    require_running();
    check(MPI_Alltoallv(send, send_counts.data(), send_offsets.data(), MPI_C_DOUBLE_COMPLEX, receive,
                        receive_counts.data(), receive_offsets.data(), MPI_C_DOUBLE_COMPLEX, comm_),
          "MPI_Alltoallv");
}

void Communicator::allgatherv(const double *send, int count, double *receive,
                              const std::vector<int> &counts, const std::vector<int> &offsets) const {
    const CancellationHeldOff held_off;
    require_running();
    check(MPI_Allgatherv(send, count, MPI_C_DOUBLE_COMPLEX, receive, counts.data(), offsets.data(),
                         MPI_C_DOUBLE_COMPLEX, comm_),
          "MPI_Allgatherv");
}

const std::vector<double> &Communicator::allgather(double value) const {
    const CancellationHeldOff held_off;
    require_running();
    check(MPI_Allgather(&value, 1, MPI_DOUBLE, gathered_.data(), 1, MPI_DOUBLE, comm_), "MPI_Allgather");
    return gathered_;
}

const std::vector<long long> &Communicator::allgather(long long value) const {
    const CancellationHeldOff held_off;
    require_running();
    check(MPI_Allgather(&value, 1, MPI_LONG_LONG, gathered_integers_.data(), 1, MPI_LONG_LONG, comm_),
          "MPI_Allgather");
    return gathered_integers_;
}

void Communicator::exchange_headers(Stage stage, long long value) const {
    const CancellationHeldOff held_off;
    require_running();
    const long long mine[2] = {stage, value};
    check(MPI_Allgather(mine, 2, MPI_LONG_LONG, headers_.data(), 2, MPI_LONG_LONG, comm_), "MPI_Allgather");
}

void Communicator::require_same(long long value, const char *what) const {
    exchange_headers(kCalling, value);
    // A process ending an agreement has left the observer this process calls
    // from: the call is refused alike on every process that makes it.
    int ended = -1, failed = -1;
    for (int r = 0; r < size_; ++r) {
        if (headers_[2 * r] != kEndingAgreement) continue;
        if (ended < 0) ended = r;
        if (failed < 0 && headers_[2 * r + 1] != LPI_OK) failed = r;
    }
    if (failed >= 0)
        fail_alike(LPI_ERR_CALLBACK, [&] {
            return "rank " + std::to_string(failed) + " failed in its observer and left it while this "
                   "process called the system from its own";
        });
    if (ended >= 0)
        fail_alike(LPI_ERR_INVALID, [&] {
            return "rank " + std::to_string(ended) + " had returned from its observer while this process "
                   "called the system from its own (the observers of a system spread over processes make "
                   "the same calls; one that retries a refused call for ever keeps the others waiting)";
        });
    for (int r = 1; r < size_; ++r)
        if (headers_[2 * r + 1] != headers_[1])
            fail_alike(LPI_ERR_INVALID, [&] {
                return std::string("the processes passed different ") + what +
                       " (every process must make the same calls with the same arguments)";
            });
}

double Communicator::max(double value) const {
    const CancellationHeldOff held_off;
    require_running();
    double result = 0.0;
    check(MPI_Allreduce(&value, &result, 1, MPI_DOUBLE, MPI_MAX, comm_), "MPI_Allreduce");
    return result;
}

bool Communicator::all(bool value) const {
    const CancellationHeldOff held_off;
    require_running();
    int local = value ? 1 : 0, result = 0;
    check(MPI_Allreduce(&local, &result, 1, MPI_INT, MPI_LAND, comm_), "MPI_Allreduce");
    return result != 0;
}

void Communicator::broadcast(double *values, std::size_t n) const {
    const CancellationHeldOff held_off;
    require_running();
    while (n > 0) {  // in pieces that an int counts
        const int count = n > INT_MAX ? INT_MAX : static_cast<int>(n);
        check(MPI_Bcast(values, count, MPI_DOUBLE, 0, comm_), "MPI_Bcast");
        values += count;
        n -= static_cast<std::size_t>(count);
    }
}

void Communicator::broadcast(unsigned char *bytes, std::size_t n) const {
    const CancellationHeldOff held_off;
    require_running();
    while (n > 0) {
        const int count = n > INT_MAX ? INT_MAX : static_cast<int>(n);
        check(MPI_Bcast(bytes, count, MPI_UNSIGNED_CHAR, 0, comm_), "MPI_Bcast");
        bytes += count;
        n -= static_cast<std::size_t>(count);
    }
}

void Communicator::share_outcome(int status, const std::string &message) const {
    // Until no process calls the system from an observer this one has left
    // (each such call is refused, and its process comes here in the end).
    const CancellationHeldOff held_off;
    bool calling = true;
    while (calling) {
        exchange_headers(kEndingAgreement, status);
        calling = false;
        for (int r = 0; r < size_; ++r) calling = calling || headers_[2 * r] == kCalling;
    }
    int failed = -1;
    for (int r = 0; r < size_ && failed < 0; ++r)
        if (headers_[2 * r + 1] != LPI_OK) failed = r;
    if (failed < 0) return;
    int length = rank_ == failed ? static_cast<int>(std::min(message.size(), message_.size())) : 0;
    check(MPI_Bcast(&length, 1, MPI_INT, failed, comm_), "MPI_Bcast");
    if (rank_ == failed) std::copy(message.begin(), message.begin() + length, message_.begin());
    check(MPI_Bcast(message_.data(), length, MPI_CHAR, failed, comm_), "MPI_Bcast");
    fail_alike(static_cast<lpi_status>(headers_[2 * failed + 1]), [&] {
        const std::string text(message_.data(), static_cast<std::size_t>(length));
        return size_ > 1 && failed != 0 ? "on rank " + std::to_string(failed) + ": " + text : text;
    });
}

void Communicator::agree(ActionRef action) const {
    std::string message;
    const int status = outcome_of(action, message);
    share_outcome(status, message);
}

void Communicator::on_root(ActionRef action) const {
    std::string message;
    const int status = rank_ == 0 ? outcome_of(action, message) : LPI_OK;
    share_outcome(status, message);
}

}  // namespace mpi
}  // namespace lpi
