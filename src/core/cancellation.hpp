// Thread cancellation held off while the library waits or touches files.
//
// Those are cancellation points (pthread_join, a condition's wait, open,
// read, write, fsync, close; MPI's own), and a cancel acted on there unwinds
// through code that cannot be left half-way: a destructor that closes a file
// (noexcept: std::terminate), a probe whose threads still wait on a gate on
// the ending thread's stack, a collective the other processes are in. A
// cancel that comes meanwhile stays pending and acts at the thread's next
// cancellation point after the call. Callbacks keep the caller's state,
// where a cancel unwinds through the library as liepoisson(7) says. Not
// around every call: a pthread_setcancelstate pair costs about 85 ns, as much
// as a rigid-body step.
#pragma once

#include <pthread.h>

namespace lpi {

class CancellationHeldOff {
public:
    CancellationHeldOff() { pthread_setcancelstate(PTHREAD_CANCEL_DISABLE, &previous_); }
    ~CancellationHeldOff() {
        int ignored;
        pthread_setcancelstate(previous_, &ignored);
    }
    CancellationHeldOff(const CancellationHeldOff &) = delete;
    CancellationHeldOff &operator=(const CancellationHeldOff &) = delete;

private:
    int previous_ = PTHREAD_CANCEL_ENABLE;
};

// The first thing a C API call that touches files or starts threads does: a
// cancel already pending ends the thread here, before anything is done, as
// the open(2) the call would make does, so a thread looping over such calls
// can still be cancelled. Not later, inside the call: unwinding through the
// library's own frames from there is what AddressSanitizer cannot follow
// (a stale poisoned frame: "CHECK failed: asan_thread.cpp").
inline void act_on_a_pending_cancel() { pthread_testcancel(); }

}  // namespace lpi
