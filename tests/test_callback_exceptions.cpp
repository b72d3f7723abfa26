// User callbacks written in C++ that throw: every kind of callback (gradient,
// energy, Casimir, the moments' H and H', the observer) fails its call with
// LPI_ERR_CALLBACK naming the callback and the exception's text, the state and
// time unchanged bit for bit, and the handle usable after. A throw was
// reported as an internal error of the library.
//
// And a thread that ends inside a callback (pthread_exit, or a cancellation
// acted on there; Python ends its daemon threads so at exit) unwinds through
// the library: the call rolls the system back and releases it, and the
// process goes on. Caught by the library's handlers and not rethrown, the
// unwind aborted the process ("FATAL: exception not rethrown").
#include <pthread.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>

#include "lpi_test.h"

namespace {

// Which callback fails, and how.
enum class Thrower { None, Gradient, Energy, Casimir, H, DH, Observer };
enum class Failure {
    Standard,      // throws a std::exception (its what() is named)
    Other,         // throws an int
    ThreadExit,    // ends its thread: pthread_exit
    ThreadCancel,  // ends its thread: a pending cancellation, acted on
};
struct Plan {
    Thrower who = Thrower::None;
    Failure how = Failure::Standard;
};
Plan plan;

void maybe_throw(Thrower here) {
    if (plan.who != here) return;
    switch (plan.how) {
        case Failure::Standard: throw std::runtime_error("boom from the user");
        case Failure::Other: throw 42;
        case Failure::ThreadExit: pthread_exit(nullptr);
        case Failure::ThreadCancel:
            pthread_cancel(pthread_self());
            pthread_testcancel();
            fail_msg("a pending cancellation did not end the thread");
    }
}

const double kInertia = 2.0;  // lpi_test_axis_gradient's user: I_k

int gradient(size_t n, const double *x, double *g, void *user) {
    maybe_throw(Thrower::Gradient);
    return lpi_test_axis_gradient(n, x, g, user);
}
int energy(size_t n, const double *x, double *h, void *user) {
    maybe_throw(Thrower::Energy);
    return lpi_test_axis_energy(n, x, h, user);
}
int casimir(size_t, const double *x, double *c, void *) {
    maybe_throw(Thrower::Casimir);
    *c = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    return 0;
}
int product_h(double u, double *out, void *) {
    maybe_throw(Thrower::H);
    *out = 0.5 * u * u;
    return 0;
}
int product_dh(double u, double *out, void *) {
    maybe_throw(Thrower::DH);
    *out = u;
    return 0;
}
int observer(const lpi_system *, int64_t, double, void *) {
    maybe_throw(Thrower::Observer);
    return 0;
}

// so(3) by structure constants, three axis pieces and |m|^2 as a Casimir.
lpi_system *generic_body() {
    static const int32_t i[] = {0, 1, 2}, j[] = {1, 2, 0}, k[] = {2, 0, 1};
    static const double c[] = {1, 1, 1};
    lpi_system *sys = nullptr;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    for (int32_t axis = 0; axis < 3; ++axis)
        assert_int_equal(lpi_add_piece(sys, 1, &axis, gradient, energy,
                                       const_cast<double *>(&kInertia)),
                         LPI_OK);
    assert_int_equal(lpi_add_casimir(sys, casimir, nullptr), LPI_OK);
    const double m[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(sys, m, 3), LPI_OK);
    assert_int_equal(lpi_set_observer(sys, 2, observer, nullptr), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK);  // a time to keep
    return sys;
}

lpi_system *moments() {
    lpi_system *sys = nullptr;
    assert_int_equal(lpi_moments_create(&sys), LPI_OK);
    assert_int_equal(lpi_moments_add_product_piece(sys, product_h, product_dh, nullptr), LPI_OK);
    const double x[8] = {1.0, 0.2, 0.5, 2.5, 0.6, 0.6, 0.3, 0.8};
    assert_int_equal(lpi_set_state(sys, x, 8), LPI_OK);
    return sys;
}

// `call` on `sys` fails with LPI_ERR_CALLBACK naming `callback` and, for a
// std::exception, its text; nothing changes; the same call then succeeds.
template <class Call>
void expect_callback_failure(lpi_system *sys, Thrower who, const char *callback, const char *function,
                             Call call) {
    for (bool standard : {true, false}) {
        plan = {who, standard ? Failure::Standard : Failure::Other};
        LPI_ASSERT_FAILS(sys, call(), LPI_ERR_CALLBACK, function);
        const char *message = lpi_last_error(sys);
        if (!std::strstr(message, callback) || !std::strstr(message, "threw an exception"))
            fail_msg("message '%s' does not name %s and its exception", message, callback);
        if (standard && !std::strstr(message, "boom from the user"))
            fail_msg("message '%s' does not give the exception's text", message);
        if (std::strstr(message, "internal error")) fail_msg("message '%s' blames the library", message);
        plan = {};
        assert_int_equal(call(), LPI_OK);
    }
}

// `call` on `sys`, made on a thread of its own whose `who` callback ends it
// both ways: the thread ends there (the process goes on), `sys` is as it was,
// bit for bit, and free (not LPI_ERR_BUSY: the claim went with the unwind),
// and the same call then succeeds.
void expect_thread_ended(lpi_system *sys, Thrower who, const std::function<int()> &call) {
    for (Failure how : {Failure::ThreadExit, Failure::ThreadCancel}) {
        lpi_snapshot before;
        lpi_take_snapshot(sys, &before);
        plan = {who, how};
        static bool returned;
        returned = false;
        pthread_t thread;
        auto run = [](void *argument) -> void * {
            (void)(*static_cast<const std::function<int()> *>(argument))();
            returned = true;
            return nullptr;
        };
        assert_int_equal(pthread_create(&thread, nullptr, run, const_cast<std::function<int()> *>(&call)), 0);
        void *result = nullptr;
        assert_int_equal(pthread_join(thread, &result), 0);
        plan = {};
        assert_false(returned);
        assert_true(result == (how == Failure::ThreadCancel ? PTHREAD_CANCELED : nullptr));
        lpi_assert_unchanged(sys, &before);
        assert_int_equal(call(), LPI_OK);
    }
}

void test_generic_callbacks_that_throw(void **) {
    lpi_system *sys = generic_body();
    double h = 0.0, c = 0.0;
    for (const char *method : {"leapfrog", "rk4", "implicit-midpoint"}) {
        assert_int_equal(lpi_set_method(sys, method), LPI_OK);
        expect_callback_failure(sys, Thrower::Gradient, "gradient callback of piece", "lpi_step",
                                [&] { return lpi_step(sys, 0.1, 5); });
        expect_callback_failure(sys, Thrower::Observer, "observer callback", "lpi_step",
                                [&] { return lpi_step(sys, 0.1, 5); });
    }
    expect_callback_failure(sys, Thrower::Energy, "energy callback of piece", "lpi_energy",
                            [&] { return lpi_energy(sys, &h); });
    expect_callback_failure(sys, Thrower::Casimir, "callback of Casimir 0", "lpi_casimirs",
                            [&] { return lpi_casimirs(sys, &c, 1); });
    lpi_destroy(sys);
}

void test_threads_that_end_in_a_callback(void **) {
    lpi_system *sys = generic_body();
    double h = 0.0, c = 0.0;
    for (const char *method : {"leapfrog", "rk4", "implicit-midpoint"}) {
        assert_int_equal(lpi_set_method(sys, method), LPI_OK);
        for (Thrower who : {Thrower::Gradient, Thrower::Observer})
            expect_thread_ended(sys, who, [&] { return lpi_step(sys, 0.1, 5); });
    }
    expect_thread_ended(sys, Thrower::Energy, [&] { return lpi_energy(sys, &h); });
    expect_thread_ended(sys, Thrower::Casimir, [&] { return lpi_casimirs(sys, &c, 1); });
    lpi_destroy(sys);
    sys = moments();
    expect_thread_ended(sys, Thrower::DH, [&] { return lpi_step(sys, 0.1, 5); });
    expect_thread_ended(sys, Thrower::H, [&] { return lpi_energy(sys, &h); });
    lpi_destroy(sys);
}

void test_moments_callbacks_that_throw(void **) {
    lpi_system *sys = moments();
    double h = 0.0;
    expect_callback_failure(sys, Thrower::DH, "H' callback of piece 0", "lpi_step",
                            [&] { return lpi_step(sys, 0.1, 5); });
    expect_callback_failure(sys, Thrower::H, "H callback of piece 0", "lpi_energy",
                            [&] { return lpi_energy(sys, &h); });
    lpi_destroy(sys);
}

}  // namespace

int main() {
    const CMUnitTest tests[] = {
        cmocka_unit_test(test_generic_callbacks_that_throw),
        cmocka_unit_test(test_moments_callbacks_that_throw),
        cmocka_unit_test(test_threads_that_end_in_a_callback),
    };
    return lpi_run_tests(tests);
}
