// Sine-Euler on MPI, an observer written in C++ that throws on one process
// only: every process fails the call with the same LPI_ERR_CALLBACK and
// message, the state rolled back; none is left waiting in the next
// collective (the others hung there). Run under mpirun with 2 processes.
#include <mpi.h>

#include <cstring>
#include <stdexcept>

#include "liepoisson_mpi.h"
#include "lpi_test.h"

namespace {

int rank_ = 0, size_ = 1;

int throwing_on_last(const lpi_system *, int64_t step, double, void *) {
    if (rank_ == size_ - 1 && step == 2) throw std::runtime_error("boom on the last process");
    return 0;
}

void test_observer_throwing_on_one_process(void **) {
    lpi_system *sys = nullptr;
    assert_int_equal(lpi_sine_euler_create_mpi(&sys, 7, MPI_COMM_WORLD), LPI_OK);
    double w[2 * 49] = {0};
    w[2 * 1] = 1.0, w[2 * 6] = 1.0, w[2 * 7] = 0.5, w[2 * 42] = 0.5;
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 98), LPI_OK);
    assert_int_equal(lpi_set_observer(sys, 1, throwing_on_last, nullptr), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.01, 5), LPI_ERR_CALLBACK, "lpi_step");
    const char *message = lpi_last_error(sys);
    assert_non_null(std::strstr(message, "the observer callback threw an exception: boom on the last process"));
    assert_non_null(std::strstr(message, "in step 2 of this call"));
    // The same on every process.
    char mine[512] = {0}, first[512] = {0};
    std::strncpy(mine, message, sizeof mine - 1);
    std::memcpy(first, mine, sizeof first);
    MPI_Bcast(first, sizeof first, MPI_CHAR, 0, MPI_COMM_WORLD);
    assert_string_equal(mine, first);
    // The handle steps on.
    assert_int_equal(lpi_set_observer(sys, 0, nullptr, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 5), LPI_OK);
    lpi_destroy(sys);
}

}  // namespace

int main(int argc, char **argv) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    const CMUnitTest tests[] = {cmocka_unit_test(test_observer_throwing_on_one_process)};
    const int status = lpi_run_tests(tests);
    MPI_Finalize();
    return status;
}
