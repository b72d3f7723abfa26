// Sine-Euler on MPI, an observer written in C++ that throws on one process
// only: every process fails the call with the same LPI_ERR_CALLBACK and
// message, the state rolled back; none is left waiting in the next
// collective (the others hung there), also when the others' observers read
// the system meanwhile (their calls met the failing process's end of the
// agreement: a truncated message, then a hang in the next call). And a
// handle used after MPI_Finalize is refused, not aborted. Different calls
// with the same arguments are refused, and so are calls on another spread
// system from an observer. Run under mpirun with 2 processes.
#include <mpi.h>

#include <cstdio>
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

int observer_status = LPI_OK;  // what the observer's own call returned

// Reads the system at every step; the last process throws at step 2.
int reading_but_throwing_on_last(const lpi_system *sys, int64_t step, double, void *) {
    if (rank_ == size_ - 1 && step == 2) throw std::runtime_error("boom on the last process");
    double h = 0.0;
    const int status = lpi_energy(sys, &h);
    if (status != LPI_OK) observer_status = status;
    return 0;
}

// Reads the system on every process but the last.
int reading_on_all_but_last(const lpi_system *sys, int64_t, double, void *) {
    if (rank_ == size_ - 1) return 0;
    double h = 0.0;
    const int status = lpi_energy(sys, &h);
    if (status != LPI_OK) observer_status = status;
    return 0;
}

lpi_system *observed_system() {
    lpi_system *sys = nullptr;
    assert_int_equal(lpi_sine_euler_create_mpi(&sys, 7, MPI_COMM_WORLD), LPI_OK);
    double w[2 * 49] = {0};
    w[2 * 1] = 1.0, w[2 * 6] = 1.0, w[2 * 7] = 0.5, w[2 * 42] = 0.5;
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, 98), LPI_OK);
    return sys;
}

void test_observers_reading_while_one_throws(void **) {
    lpi_system *sys = observed_system();
    double before[49], after[49];
    assert_int_equal(lpi_get_state(sys, before, 49), LPI_OK);
    observer_status = LPI_OK;
    assert_int_equal(lpi_set_observer(sys, 1, reading_but_throwing_on_last, nullptr), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.01, 5), LPI_ERR_CALLBACK, "lpi_step");
    assert_non_null(std::strstr(lpi_last_error(sys), "boom on the last process"));
    // The others' reads at step 2 were refused: the last process had left.
    if (rank_ != size_ - 1) assert_int_equal(observer_status, LPI_ERR_CALLBACK);
    assert_true(lpi_time(sys) == 0.0);
    assert_int_equal(lpi_get_state(sys, after, 49), LPI_OK);
    assert_memory_equal(before, after, sizeof before);
    // The processes are still in step.
    assert_int_equal(lpi_set_observer(sys, 0, nullptr, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 5), LPI_OK);
    lpi_destroy(sys);
}

void test_observers_making_different_calls(void **) {
    lpi_system *sys = observed_system();
    observer_status = LPI_OK;
    assert_int_equal(lpi_set_observer(sys, 1, reading_on_all_but_last, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 3), LPI_OK);
    if (rank_ != size_ - 1) assert_int_equal(observer_status, LPI_ERR_INVALID);
    assert_int_equal(lpi_set_observer(sys, 0, nullptr, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 3), LPI_OK);
    lpi_destroy(sys);
}

// Two calls that take the same arguments, one on each process: refused on
// both (they paired different collectives: a truncated message, a hang).
void test_different_calls_with_the_same_arguments(void **) {
    lpi_system *sys = observed_system();
    double v = 0.0;
    const int status = rank_ == 0 ? lpi_energy(sys, &v) : lpi_sine_euler_enstrophy(sys, &v);
    assert_int_equal(status, LPI_ERR_INVALID);
    assert_non_null(std::strstr(lpi_last_error(sys), "different calls"));
    assert_int_equal(lpi_step(sys, 0.01, 2), LPI_OK);
    lpi_destroy(sys);
}

int different_reads(const lpi_system *sys, int64_t, double, void *) {
    double x[49];
    const int status = rank_ == 0 ? lpi_get_state(sys, x, 49) : lpi_sine_euler_get_grid(sys, x, 49);
    if (status != LPI_OK) observer_status = status;
    return 0;
}

void test_observers_making_different_reads(void **) {
    lpi_system *sys = observed_system();
    observer_status = LPI_OK;
    assert_int_equal(lpi_set_observer(sys, 1, different_reads, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 3), LPI_OK);
    assert_int_equal(observer_status, LPI_ERR_INVALID);
    assert_int_equal(lpi_set_observer(sys, 0, nullptr, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 3), LPI_OK);
    lpi_destroy(sys);
}

// An observer of one spread system reading another, or making a new one,
// while the last process's observer throws: those calls are refused on
// every process (the others waited for ever in the other system's
// collectives for the process that had left).
lpi_system *other = nullptr;
int create_status = LPI_OK;
int reading_another_system(const lpi_system *, int64_t step, double, void *) {
    if (rank_ == size_ - 1 && step == 2) throw std::runtime_error("boom on the last process");
    double h = 0.0;
    const int status = lpi_energy(other, &h);
    if (status != LPI_OK) observer_status = status;
    lpi_system *made = nullptr;
    create_status = lpi_sine_euler_create_mpi(&made, 7, MPI_COMM_WORLD);
    lpi_destroy(made);
    return 0;
}

void test_observer_calling_another_spread_system(void **) {
    lpi_system *sys = observed_system();
    other = observed_system();
    observer_status = LPI_OK;
    assert_int_equal(lpi_set_observer(sys, 1, reading_another_system, nullptr), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.01, 5), LPI_ERR_CALLBACK, "lpi_step");
    assert_int_equal(observer_status, LPI_ERR_INVALID);
    assert_non_null(std::strstr(lpi_last_error(other), "not called from a callback of another system"));
    assert_int_equal(create_status, LPI_ERR_INVALID);
    // Both systems are still in step.
    assert_int_equal(lpi_set_observer(sys, 0, nullptr, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 2), LPI_OK);
    assert_int_equal(lpi_step(other, 0.01, 2), LPI_OK);
    lpi_destroy(other);
    lpi_destroy(sys);
}

}  // namespace

int main(int argc, char **argv) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    const CMUnitTest tests[] = {cmocka_unit_test(test_observer_throwing_on_one_process),
                                cmocka_unit_test(test_observers_reading_while_one_throws),
                                cmocka_unit_test(test_observers_making_different_calls),
                                cmocka_unit_test(test_different_calls_with_the_same_arguments),
                                cmocka_unit_test(test_observers_making_different_reads),
                                cmocka_unit_test(test_observer_calling_another_spread_system)};
    const int status = lpi_run_tests(tests);
    // A handle still held at MPI_Finalize: its calls are refused (MPI would
    // abort the program), and it is destroyed without MPI.
    lpi_system *kept = nullptr;
    if (lpi_sine_euler_create_mpi(&kept, 7, MPI_COMM_WORLD) != LPI_OK) return 1;
    MPI_Finalize();
    double h = 0.0;
    const int after = lpi_energy(kept, &h);
    const bool refused = after == LPI_ERR_INVALID && std::strstr(lpi_last_error(kept), "MPI_Finalize");
    if (!refused) std::printf("lpi_energy after MPI_Finalize: %s, %s\n", lpi_status_name(after), lpi_last_error(kept));
    lpi_destroy(kept);
    return refused ? status : 1;
}
