// Calls that run out of memory: LPI_ERR_NO_MEMORY, the handle unchanged, and
// a message that is this call's, never an older one left standing; and what
// a call asks of memory. The test replaces operator new (the library's
// allocations go through it) with one that fails while this thread asks it
// to, or any single allocation above a size it sets.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <thread>

#include "lpi_test.h"

namespace {
thread_local bool allocations_fail = false;
thread_local std::size_t largest_allocation = SIZE_MAX;
}  // namespace

void *operator new(std::size_t size) {
    if (allocations_fail || size > largest_allocation) throw std::bad_alloc();
    if (void *p = std::malloc(size ? size : 1)) return p;
    throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }

namespace {

// Whether the library's allocations come here (a tool such as valgrind may
// put its own operator new in their way): a create must then fail.
bool replacement_in_use() {
    lpi_system *sys = NULL;
    allocations_fail = true;
    const int status = lpi_pendulum_create(&sys);
    allocations_fail = false;
    lpi_destroy(sys);
    return status == LPI_ERR_NO_MEMORY;
}

// A message the string holding it has room for: "lpi_set_method: out of
// memory", not the unknown-method message before it (the new one used to be
// built in temporaries, which could not be allocated, and the old stood).
void test_message_is_this_calls(void **state) {
    (void)state;
    if (!replacement_in_use()) LPI_SKIP("operator new is not this test's (a tool replaced it)");
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "no-such-method"), LPI_ERR_INVALID);
    allocations_fail = true;
    const int status = lpi_set_method(sys, "yoshida-6");
    allocations_fail = false;
    assert_int_equal(status, LPI_ERR_NO_MEMORY);
    printf("after a failed allocation: %s\n", lpi_last_error(sys));
    assert_string_equal(lpi_last_error(sys), "lpi_set_method: out of memory");
    assert_string_equal(lpi_get_method(sys), "leapfrog");
    lpi_destroy(sys);
}

// A thread's first message, where its string has no room yet: "out of
// memory" (it fits the string's own buffer), not an empty string.
void test_message_without_room(void **state) {
    (void)state;
    if (!replacement_in_use()) LPI_SKIP("operator new is not this test's (a tool replaced it)");
    int status = LPI_OK;
    std::string message;
    std::thread thread([&] {
        lpi_system *sys = NULL;
        allocations_fail = true;
        status = lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0);
        const char *text = lpi_last_error(NULL);
        allocations_fail = false;
        message = text;
    });
    thread.join();
    assert_int_equal(status, LPI_ERR_NO_MEMORY);
    printf("a thread's first message, out of memory: %s\n", message.c_str());
    assert_string_equal(message.c_str(), "out of memory");
}

// A method's flows are held as its stages and the pieces, not written out:
// suzuki-16 (78125 stages) on the rigid body's two pieces is 156250 flows a
// step, which written out took 6 MB at the peak (sine-Euler at N = 101:
// 500 MB); now every allocation stays under 1 MiB.
void test_flows_not_written_out(void **state) {
    (void)state;
    if (!replacement_in_use()) LPI_SKIP("operator new is not this test's (a tool replaced it)");
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, 1.0, 2.0, 3.0), LPI_OK);
    largest_allocation = std::size_t(1) << 20;
    const int status = lpi_set_method(sys, "suzuki-16");
    largest_allocation = SIZE_MAX;
    if (status != LPI_OK) printf("%s\n", lpi_last_error(sys));
    assert_int_equal(status, LPI_OK);
    size_t flows = 0;
    assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
    assert_int_equal(flows, 78125u * 2u);
    lpi_destroy(sys);
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_message_is_this_calls),
        cmocka_unit_test(test_message_without_room),
        cmocka_unit_test(test_flows_not_written_out),
    };
    return lpi_run_tests(tests);
}
