// Sine-Euler on MPI with each of the library's allocations failing in turn
// on the last process alone: for every call on a spread handle and every k,
// the k-th allocation (operator new, replaced here) of the call on the last
// process throws std::bad_alloc. Every process must return the same status
// (LPI_OK when the library absorbs it, else LPI_ERR_NO_MEMORY) with the
// state and time unchanged on failure, and none may be left waiting in a
// collective (ctest's timeout fails a hang). The sweep of a call ends at
// the first k its allocations on the last process do not reach. Run under
// mpirun with 2 and 3 processes.
#include <mpi.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "liepoisson_mpi.h"
#include "lpi_test.h"

namespace {

int rank_ = 0, size_ = 1;

// Counts down the allocations of the process it is armed on; the one that
// takes it to 0 fails, and `fired` says so.
std::atomic<long> countdown{0};
std::atomic<bool> fired{false};

bool this_allocation_fails() {
    if (countdown.load(std::memory_order_relaxed) <= 0) return false;
    if (countdown.fetch_sub(1) != 1) return false;
    fired = true;
    return true;
}

}  // namespace

void *operator new(std::size_t size) {
    if (this_allocation_fails()) throw std::bad_alloc();
    if (void *p = std::malloc(size ? size : 1)) return p;
    throw std::bad_alloc();
}
// Not inlined: GCC would see free() given a pointer from operator new.
__attribute__((noinline)) void operator delete(void *p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void *p, std::size_t) noexcept { std::free(p); }

namespace {

constexpr int N = 11;
constexpr std::size_t n = static_cast<std::size_t>(N) * N;

// Public coordinates of a field and a Hamiltonian other than Euler's (so
// that it is gathered whole where asked), the same on every process.
struct Fixture {
    lpi_system *sys = nullptr;
    std::vector<double> x = std::vector<double>(n), lambda = std::vector<double>(n),
                        f = std::vector<double>(2 * n);
    std::string path = "test_sine_euler_mpi_allocations_" + std::to_string(size_) + ".lpi";
};
Fixture *fixture = nullptr;

void make_fixture() {
    fixture = new Fixture;
    std::uint64_t seed = 12345;
    for (double &v : fixture->x) v = lpi_test_uniform(&seed);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
            const int ka = a <= N / 2 ? a : a - N, kb = b <= N / 2 ? b : b - N;
            const double k2 = static_cast<double>(ka * ka + kb * kb);
            fixture->lambda[static_cast<std::size_t>(a) * N + b] = k2 > 0 ? 1.0 / (k2 + 1.0) : 0.0;
        }
    assert_int_equal(lpi_sine_euler_create_mpi(&fixture->sys, N, MPI_COMM_WORLD), LPI_OK);
    assert_int_equal(lpi_set_state(fixture->sys, fixture->x.data(), n), LPI_OK);
    assert_int_equal(lpi_sine_euler_set_hamiltonian(fixture->sys, fixture->lambda.data(), n, nullptr, 0), LPI_OK);
    assert_int_equal(lpi_step(fixture->sys, 0.01, 1), LPI_OK);  // plans made
}

using Call = int (*)(lpi_system *sys);

// The k of this trial. A call prepares its buffers, then runs the library's
// calls through armed(): the test's own allocations never fail.
long trial_k = 0;
template <class F>
int armed(F &&library_calls) {
    if (rank_ == size_ - 1) countdown = trial_k;
    const int status = library_calls();
    countdown = 0;
    return status;
}

// The k-th allocation of call fails on the last process. Returns whether
// any process reached it.
bool one_failure(const char *name, Call call, long k) {
    lpi_system *sys = fixture->sys;
    std::vector<double> before(n), after(n);
    assert_int_equal(lpi_get_state(sys, before.data(), n), LPI_OK);
    const double time_before = lpi_time(sys);
    fired = false;
    trial_k = k;
    const int status = call(sys);
    int mine[2] = {status, fired ? 1 : 0}, low[2], high[2];
    MPI_Allreduce(mine, low, 2, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(mine, high, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (low[0] != high[0] || (status != LPI_OK && status != LPI_ERR_NO_MEMORY))
        fail_msg("%s, allocation %ld failing on rank %d: status %s on rank %d (from %d to %d over the processes): %s",
                 name, k, size_ - 1, lpi_status_name(status), rank_, low[0], high[0],
                 lpi_last_error(status == LPI_OK ? nullptr : sys));
    if (status == LPI_ERR_NO_MEMORY) {
        assert_int_equal(lpi_get_state(sys, after.data(), n), LPI_OK);
        assert_memory_equal(before.data(), after.data(), n * sizeof(double));
        assert_true(lpi_time(sys) == time_before);
    }
    return high[1] != 0;
}

void sweep(const char *name, Call call) {
    long k = 1;
    while (one_failure(name, call, k)) {
        ++k;
        if (k > 100000) fail_msg("%s: more than 100000 allocations", name);
    }
    if (rank_ == 0) std::printf("%-34s %ld allocations on the last process, each failed once\n", name, k - 1);
}

int energy_in_observer(const lpi_system *sys, int64_t, double, void *) {
    double h = 0.0;
    lpi_energy(sys, &h);
    return 0;
}

int step(lpi_system *sys) {
    return armed([&] { return lpi_step(sys, 0.01, 2); });
}
int observed_step(lpi_system *sys) {
    // The observer reads the system (collective calls of its own); it is
    // removed before the result is compared.
    return armed([&] {
        int status = lpi_set_observer(sys, 1, energy_in_observer, nullptr);
        if (status == LPI_OK) status = lpi_step(sys, 0.01, 2);
        const int removed = lpi_set_observer(sys, 0, nullptr, nullptr);
        return status != LPI_OK ? status : removed;
    });
}
int energy(lpi_system *sys) {
    double h;
    return armed([&] { return lpi_energy(sys, &h); });
}
int enstrophy(lpi_system *sys) {
    double z;
    return armed([&] { return lpi_sine_euler_enstrophy(sys, &z); });
}
int get_state(lpi_system *sys) {
    std::vector<double> x(n);
    return armed([&] { return lpi_get_state(sys, x.data(), n); });
}
int set_state(lpi_system *sys) {
    std::vector<double> x(n);
    const int status = lpi_get_state(sys, x.data(), n);
    return status != LPI_OK ? status : armed([&] { return lpi_set_state(sys, x.data(), n); });
}
int casimirs(lpi_system *sys) {
    std::vector<double> c(N);
    return armed([&] { return lpi_casimirs(sys, c.data(), c.size()); });
}
int traces(lpi_system *sys) {
    std::vector<double> t(4);
    return armed([&] { return lpi_sine_euler_casimir_traces(sys, 4, t.data()); });
}
int modes(lpi_system *sys) {
    std::vector<double> w(2 * n);
    return armed([&] {
        const int status = lpi_sine_euler_get_modes(sys, w.data(), w.size());
        return status != LPI_OK ? status : lpi_sine_euler_set_modes(sys, w.data(), w.size());
    });
}
int grid(lpi_system *sys) {
    std::vector<double> g(n);
    return armed([&] {
        const int status = lpi_sine_euler_get_grid(sys, g.data(), n);
        return status != LPI_OK ? status : lpi_sine_euler_set_grid(sys, g.data(), n);
    });
}
int stream(lpi_system *sys) {
    std::vector<double> psi(n);
    return armed([&] { return lpi_sine_euler_get_stream(sys, psi.data(), n); });
}
int spectrum(lpi_system *sys) {
    std::vector<double> e(N), z(N);
    size_t shells = 0;
    return armed([&] { return lpi_sine_euler_spectrum(sys, e.data(), z.data(), e.size(), &shells); });
}
int save_buffer(lpi_system *sys) {
    size_t size = 0;
    return armed([&] { return lpi_save_buffer(sys, nullptr, 0, &size); });
}
int save(lpi_system *sys) {
    return armed([&] { return lpi_save(sys, fixture->path.c_str()); });
}
int load(lpi_system *) {
    lpi_system *loaded = nullptr;
    const int status = armed([&] { return lpi_load_mpi(&loaded, fixture->path.c_str(), MPI_COMM_WORLD); });
    lpi_destroy(loaded);
    return status;
}
int create(lpi_system *) {
    lpi_system *made = nullptr;
    const int status = armed([&] { return lpi_sine_euler_create_mpi(&made, N, MPI_COMM_WORLD); });
    lpi_destroy(made);
    return status;
}
int hamiltonian(lpi_system *sys) {
    return armed([&] { return lpi_sine_euler_set_hamiltonian(sys, fixture->lambda.data(), n, nullptr, 0); });
}
int method(lpi_system *sys) {
    return armed([&] {
        const int status = lpi_set_method(sys, "suzuki-4");
        return status != LPI_OK ? status : lpi_set_method(sys, "leapfrog");
    });
}
int composition(lpi_system *sys) {
    const double gammas[3] = {1.3512071919596578, -1.7024143839193153, 1.3512071919596578};
    return armed([&] {
        const int status = lpi_set_composition(sys, 3, gammas);
        return status != LPI_OK ? status : lpi_set_method(sys, "leapfrog");
    });
}
int split(lpi_system *sys) {
    return armed([&] { return lpi_set_split(sys, "directions"); });
}
int threads(lpi_system *sys) {
    return armed([&] { return lpi_set_threads(sys, 1); });
}
int implicit_options(lpi_system *sys) {
    return armed([&] { return lpi_set_implicit_options(sys, 1e-13, 100); });
}
int planning(lpi_system *sys) {
    return armed([&] { return lpi_sine_euler_set_planning(sys, "estimate"); });
}
int fft_floor(lpi_system *sys) {
    double seconds = 0.0, flops = 0.0;
    return armed([&] { return lpi_sine_euler_fft_floor(sys, 1, &seconds, &flops); });
}

void test_each_allocation_failing_on_one_process(void **) {
    make_fixture();
    assert_int_equal(lpi_save(fixture->sys, fixture->path.c_str()), LPI_OK);
    const struct {
        const char *name;
        Call call;
    } calls[] = {{"lpi_step", step},
                 {"lpi_step observed (lpi_energy)", observed_step},
                 {"lpi_energy", energy},
                 {"lpi_sine_euler_enstrophy", enstrophy},
                 {"lpi_get_state", get_state},
                 {"lpi_set_state", set_state},
                 {"lpi_casimirs", casimirs},
                 {"lpi_sine_euler_casimir_traces", traces},
                 {"lpi_sine_euler_get/set_modes", modes},
                 {"lpi_sine_euler_get/set_grid", grid},
                 {"lpi_sine_euler_get_stream", stream},
                 {"lpi_sine_euler_spectrum", spectrum},
                 {"lpi_save_buffer", save_buffer},
                 {"lpi_save", save},
                 {"lpi_load_mpi", load},
                 {"lpi_sine_euler_create_mpi", create},
                 {"lpi_sine_euler_set_hamiltonian", hamiltonian},
                 {"lpi_set_method", method},
                 {"lpi_set_composition", composition},
                 {"lpi_set_split", split},
                 {"lpi_set_threads", threads},
                 {"lpi_set_implicit_options", implicit_options},
                 {"lpi_sine_euler_set_planning", planning},
                 {"lpi_sine_euler_fft_floor", fft_floor}};
    for (const auto &c : calls) sweep(c.name, c.call);
    lpi_destroy(fixture->sys);
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank_ == 0) std::remove(fixture->path.c_str());
    delete fixture;
}

}  // namespace

int main(int argc, char **argv) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    const CMUnitTest tests[] = {cmocka_unit_test(test_each_allocation_failing_on_one_process)};
    const int status = lpi_run_tests(tests);
    MPI_Finalize();
    return status;
}
