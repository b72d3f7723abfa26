// MPI behind the library's Communicator (see the header).
#include "communicator.hpp"

#include <climits>
#include <new>
#include <stdexcept>
#include <string>

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

// The status and message of whatever action() throws; LPI_OK when nothing.
int outcome_of(const std::function<void()> &action, std::string &message) {
    try {
        action();
        return LPI_OK;
    } catch (const Error &e) {
        message = e.what();
        return e.status();
    } catch (const std::bad_alloc &) {
        message = "out of memory";
        return LPI_ERR_NO_MEMORY;
    } catch (const std::length_error &) {
        message = "a buffer of the size this needs cannot be allocated";
        return LPI_ERR_NO_MEMORY;
    } catch (const std::exception &e) {
        message = std::string("internal error: ") + e.what();
        return LPI_ERR_INTERNAL;
    }
}

}  // namespace

Communicator::Communicator(MPI_Comm comm) {
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
    // The duplicate returns its errors. The user's communicator keeps its own
    // handler, except while it is duplicated (a failure there is returned).
    MPI_Errhandler users = MPI_ERRHANDLER_NULL;
    MPI_Comm_get_errhandler(comm, &users);
    MPI_Comm_set_errhandler(comm, MPI_ERRORS_RETURN);
    const int duplicated = MPI_Comm_dup(comm, &comm_);
    MPI_Comm_set_errhandler(comm, users);
    MPI_Errhandler_free(&users);
    check(duplicated, "MPI_Comm_dup");
    check(MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
    check(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    check(MPI_Comm_size(comm_, &size_), "MPI_Comm_size");
}

Communicator::~Communicator() {
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

void Communicator::alltoallv(const double *send, const std::vector<int> &send_counts,
                             const std::vector<int> &send_offsets, double *receive,
                             const std::vector<int> &receive_counts,
                             const std::vector<int> &receive_offsets) const {
    check(MPI_Alltoallv(send, send_counts.data(), send_offsets.data(), MPI_C_DOUBLE_COMPLEX, receive,
                        receive_counts.data(), receive_offsets.data(), MPI_C_DOUBLE_COMPLEX, comm_),
          "MPI_Alltoallv");
}

void Communicator::allgatherv(const double *send, int count, double *receive,
                              const std::vector<int> &counts, const std::vector<int> &offsets) const {
    check(MPI_Allgatherv(send, count, MPI_C_DOUBLE_COMPLEX, receive, counts.data(), offsets.data(),
                         MPI_C_DOUBLE_COMPLEX, comm_),
          "MPI_Allgatherv");
}

std::vector<double> Communicator::allgather(double value) const {
    std::vector<double> values(static_cast<std::size_t>(size_));
    check(MPI_Allgather(&value, 1, MPI_DOUBLE, values.data(), 1, MPI_DOUBLE, comm_), "MPI_Allgather");
    return values;
}

std::vector<long long> Communicator::allgather(long long value) const {
    std::vector<long long> values(static_cast<std::size_t>(size_));
    check(MPI_Allgather(&value, 1, MPI_LONG_LONG, values.data(), 1, MPI_LONG_LONG, comm_),
          "MPI_Allgather");
    return values;
}

void Communicator::require_same(long long value, const std::string &what) const {
    const std::vector<long long> values = allgather(value);
    for (long long v : values)
        if (v != values[0])
            fail(LPI_ERR_INVALID, "the processes passed different " + what +
                                      " (every process must make the same calls with the same arguments)");
}

double Communicator::max(double value) const {
    double result = 0.0;
    check(MPI_Allreduce(&value, &result, 1, MPI_DOUBLE, MPI_MAX, comm_), "MPI_Allreduce");
    return result;
}

bool Communicator::all(bool value) const {
    int local = value ? 1 : 0, result = 0;
    check(MPI_Allreduce(&local, &result, 1, MPI_INT, MPI_LAND, comm_), "MPI_Allreduce");
    return result != 0;
}

void Communicator::broadcast(double *values, std::size_t n) const {
    while (n > 0) {  // in pieces that an int counts
        const int count = n > INT_MAX ? INT_MAX : static_cast<int>(n);
        check(MPI_Bcast(values, count, MPI_DOUBLE, 0, comm_), "MPI_Bcast");
        values += count;
        n -= static_cast<std::size_t>(count);
    }
}

void Communicator::broadcast(unsigned char *bytes, std::size_t n) const {
    while (n > 0) {
        const int count = n > INT_MAX ? INT_MAX : static_cast<int>(n);
        check(MPI_Bcast(bytes, count, MPI_UNSIGNED_CHAR, 0, comm_), "MPI_Bcast");
        bytes += count;
        n -= static_cast<std::size_t>(count);
    }
}

void Communicator::share_outcome(int status, const std::string &message) const {
    std::vector<int> statuses(static_cast<std::size_t>(size_));
    check(MPI_Allgather(&status, 1, MPI_INT, statuses.data(), 1, MPI_INT, comm_), "MPI_Allgather");
    int failed = -1;
    for (int r = 0; r < size_ && failed < 0; ++r)
        if (statuses[static_cast<std::size_t>(r)] != LPI_OK) failed = r;
    if (failed < 0) return;
    int length = rank_ == failed ? static_cast<int>(message.size()) : 0;
    check(MPI_Bcast(&length, 1, MPI_INT, failed, comm_), "MPI_Bcast");
    std::string text(static_cast<std::size_t>(length), '\0');
    if (rank_ == failed) text = message;
    check(MPI_Bcast(&text[0], length, MPI_CHAR, failed, comm_), "MPI_Bcast");
    if (size_ > 1 && failed != 0) text = "on rank " + std::to_string(failed) + ": " + text;
    fail(static_cast<lpi_status>(statuses[static_cast<std::size_t>(failed)]), text);
}

void Communicator::agree(const std::function<void()> &action) const {
    std::string message;
    const int status = outcome_of(action, message);
    share_outcome(status, message);
}

void Communicator::on_root(const std::function<void()> &action) const {
    std::string message;
    const int status = rank_ == 0 ? outcome_of(action, message) : LPI_OK;
    share_outcome(status, message);
}

}  // namespace mpi
}  // namespace lpi
