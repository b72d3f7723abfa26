// The opaque handle behind the C ABI and the one place where exceptions become
// status codes and re-entrant calls are refused. Every exported function runs
// its body inside guarded().
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>

#include "../core/error.hpp"
#include "../core/system.hpp"
#include "liepoisson.h"

namespace lpi::capi {

// What a handle is doing. A call that finds a handle not Idle comes from a
// user callback that the library runs inside a call on that handle (the
// owner's thread), or from another thread, which is refused whatever the
// handle is doing (one handle is used by one thread at a time).
enum class Activity : unsigned char {
    Idle,       // no call in progress
    Busy,       // inside a call: every further call on the handle is refused
    Observing,  // inside the observer of lpi_step: read-only calls are allowed
};

}  // namespace lpi::capi

struct lpi_system {
    explicit lpi_system(std::unique_ptr<lpi::Model> model) : system(std::move(model)) {}
    lpi::System system;
    mutable std::string last_error;
    // A call claims an Idle handle by one compare-and-swap, so that of two
    // threads calling at once one is refused, reliably (a plain test and set
    // let both in). Only the owner's thread changes it from then until the
    // call releases it (its callbacks' nested calls, the observer).
    mutable std::atomic<lpi::capi::Activity> activity{lpi::capi::Activity::Idle};
    mutable std::atomic<std::thread::id> owner{};
};

namespace lpi::capi {

// Failures of calls with no handle to report on (a failed create, NULL handle).
std::string &thread_error();

// Records "function: what" as the message of this call on sys (or the
// thread). Where memory is exhausted and even that string cannot be built,
// an older message must not stand for this call's: the slot then says "out
// of memory", which fits the string's own buffer (no allocation).
inline void record(const lpi_system *sys, const char *function, const char *what,
                   const char *more = "") noexcept {
    std::string &slot = sys ? sys->last_error : thread_error();
    try {
        slot.assign(function).append(": ").append(what).append(more);
    } catch (...) {
        slot.clear();
        slot.append("out of memory");
    }
}

// Sets the activity of a handle its thread holds for the lifetime of the
// scope, then restores it (the observer, a callback's nested call).
class ActivityScope {
public:
    ActivityScope(const lpi_system *sys, Activity activity)
        : sys_(sys), previous_(sys ? sys->activity.load(std::memory_order_relaxed) : Activity::Idle) {
        if (sys_) sys_->activity.store(activity, std::memory_order_relaxed);
    }
    ~ActivityScope() {
        if (sys_) sys_->activity.store(previous_, std::memory_order_relaxed);
    }
    ActivityScope(const ActivityScope &) = delete;
    ActivityScope &operator=(const ActivityScope &) = delete;

private:
    const lpi_system *sys_;
    Activity previous_;
};

// A call's hold on its handle: claims an Idle handle for this thread, or
// enters a held one from a callback of the owner's thread where that
// activity allows it; otherwise refused() says why (nothing is changed).
class Claim {
public:
    Claim(const lpi_system *sys, bool mutates) : sys_(sys) {
        if (!sys) return;
        Activity found = Activity::Idle;
        if (sys->activity.compare_exchange_strong(found, Activity::Busy, std::memory_order_acquire,
                                                  std::memory_order_relaxed)) {
            sys->owner.store(std::this_thread::get_id(), std::memory_order_relaxed);
            claimed_ = true;
            return;
        }
        // Another thread may be anywhere in its call, writing the handle's
        // message too: only the owner's thread is told through the handle.
        if (sys->owner.load(std::memory_order_relaxed) != std::this_thread::get_id()) {
            refused_ = "another thread is inside a call on this handle (a handle is used by one "
                       "thread at a time: share it under a lock of your own); nothing was changed";
            other_thread_ = true;
            return;
        }
        if (found == Activity::Observing && !mutates) {
            nested_ = found;
            sys->activity.store(Activity::Busy, std::memory_order_relaxed);
            return;
        }
        refused_ = found == Activity::Observing
                       ? "called from this handle's observer, which may only read the handle "
                         "(functions taking a const lpi_system *); nothing was changed"
                       : "the handle is inside a call already: called from a callback that the "
                         "library is running in it (a piece, Casimir or product-piece callback), "
                         "where no call on the handle is allowed; nothing was changed";
    }
    ~Claim() {
        if (claimed_) {
            sys_->owner.store(std::thread::id(), std::memory_order_relaxed);
            sys_->activity.store(Activity::Idle, std::memory_order_release);
        } else if (nested_ != Activity::Idle) {
            sys_->activity.store(nested_, std::memory_order_relaxed);
        }
    }
    Claim(const Claim &) = delete;
    Claim &operator=(const Claim &) = delete;

    const char *refused() const { return refused_; }
    // Entered from the handle's own observer.
    bool nested() const { return nested_ != Activity::Idle; }
    // The handle is about to be freed with its claim (lpi_destroy).
    void release_with_handle() { claimed_ = false, nested_ = Activity::Idle; }
    // The refusal's message goes to the calling thread's slot, not the handle's.
    bool by_another_thread() const { return other_thread_; }

private:
    const lpi_system *sys_;
    bool claimed_ = false, other_thread_ = false;
    Activity nested_ = Activity::Idle;  // the activity a nested call restores
    const char *refused_ = nullptr;
};

// A string argument compared by its contents (other pointers are compared
// by whether they are NULL).
struct Text {
    const char *text;
};

// The arguments of a call, as words that every process of a handle spread
// over processes must agree on before the call does anything (a value that
// one process alone refuses would leave the others waiting in a collective):
// numbers by their bits, pointers by whether they are NULL, Text by its
// contents. What arrays hold is compared where it is first read, after its
// length is checked (Model::require_same_on_every_process).
class Arguments {
public:
    template <class... A>
    explicit Arguments(const A &...arguments) noexcept {
        (add(arguments), ...);
    }
    // FNV-1a of the function's name and the words (nothing is allocated: a
    // call may be refused for want of memory only inside its guard). The
    // name is in it: lpi_energy and lpi_sine_euler_enstrophy take the same
    // words, and on two processes paired different collectives.
    std::uint64_t fingerprint(const char *function) const {
        std::uint64_t hash = hash_;
        for (const char *c = function; *c; ++c) hash = (hash ^ static_cast<unsigned char>(*c)) * 1099511628211ull;
        return hash;
    }

private:
    void mix(std::uint64_t word) noexcept {
        for (int byte = 0; byte < 8; ++byte) hash_ = (hash_ ^ ((word >> (8 * byte)) & 0xff)) * 1099511628211ull;
    }
    template <class T>
    void add(const T &x) noexcept {
        if constexpr (std::is_pointer_v<T>) {
            mix(x != nullptr);
        } else if constexpr (std::is_floating_point_v<T>) {
            const double d = x;
            std::uint64_t bits;
            std::memcpy(&bits, &d, sizeof bits);
            mix(bits);
        } else {
            static_assert(std::is_integral_v<T>, "an argument is a number, a pointer or Text");
            mix(static_cast<std::uint64_t>(x));
        }
    }
    void add(const Text &t) noexcept {
        mix(t.text != nullptr);
        if (!t.text) return;
        const std::size_t length = std::strlen(t.text);
        mix(length);
        for (std::size_t i = 0; i < length; ++i) mix(static_cast<unsigned char>(t.text[i]));
    }
    std::uint64_t hash_ = 1469598103934665603ull;
};

// Guarded calls in progress on this thread: more than one inside a call is a
// call from a callback the library runs (an observer, a piece).
inline int &calls_in_progress() noexcept {
    thread_local int calls = 0;
    return calls;
}
class CallInProgress {
public:
    CallInProgress() noexcept : from_callback_(calls_in_progress()++ > 0) {}
    ~CallInProgress() { --calls_in_progress(); }
    CallInProgress(const CallInProgress &) = delete;
    CallInProgress &operator=(const CallInProgress &) = delete;
    bool from_callback() const { return from_callback_; }

private:
    bool from_callback_;
};
// A system spread over processes is called from a callback only where the
// callback is its own observer's: the others run on each process alone, and
// a process whose callback failed would leave the rest waiting in the
// collectives of such a call. Refused alike on every process that makes it.
constexpr const char *kSpreadFromCallback =
    "a system spread over processes is not called from a callback of another system (its observer "
    "may read it): a process whose callback failed would leave the others waiting; nothing was changed";

// Runs body() with sys claimed (Claim); maps lpi::Error to its status,
// std::bad_alloc and std::length_error to LPI_ERR_NO_MEMORY and anything else
// to LPI_ERR_INTERNAL, recording the message on sys (or the thread when sys
// is NULL). A body may return a status of its own (LPI_STOPPED). Nothing
// leaves but the forced unwind of a thread ending inside a callback
// (rethrow_if_thread_ending): the system rolled back on its way and the claim
// released, it goes on to end the thread. So these are not noexcept, which
// would abort the process there.
template <class Body>
int run_guarded(const lpi_system *sys, bool mutates, const char *function, const Arguments *arguments,
                Body &&body) {
    const CallInProgress call;
    Claim claim(sys, mutates);
    if (const char *why = claim.refused()) {
        record(claim.by_another_thread() ? nullptr : sys, function, why);
        return LPI_ERR_BUSY;
    }
    if (sys && call.from_callback() && !claim.nested() && sys->system.model().distributed()) {
        record(sys, function, kSpreadFromCallback);
        return LPI_ERR_INVALID;
    }
    try {
        if (sys && arguments) {
            const std::uint64_t fingerprint = arguments->fingerprint(function);
            sys->system.model().require_same_on_every_process(&fingerprint, sizeof fingerprint,
                                                              "arguments to this call (or made different calls)");
        }
        if constexpr (std::is_void_v<decltype(body())>) {
            body();
            return LPI_OK;
        } else {
            return body();
        }
    } catch (const lpi::Error &e) {
        record(sys, function, e.what());
        return e.status();
    } catch (const std::bad_alloc &) {
        record(sys, function, "out of memory");
        return LPI_ERR_NO_MEMORY;
    } catch (const std::length_error &) {
        record(sys, function, "a buffer of the size this needs cannot be allocated");
        return LPI_ERR_NO_MEMORY;
    } catch (const std::exception &e) {
        record(sys, function, "internal error: ", e.what());
        return LPI_ERR_INTERNAL;
    } catch (...) {
        lpi::rethrow_if_thread_ending();
        record(sys, function, "internal error");
        return LPI_ERR_INTERNAL;
    }
}

// A function taking a mutable handle may change it; one taking a const handle
// only reads it. The signature decides which calls an observer may make.
// Every call that changes a handle, and every read that a spread handle
// answers collectively (a getter of the field, energies, Casimirs, a save),
// names its arguments; reads that stay on one process (sizes, names, the
// time) do not, so a program may make them on one process alone.
template <class Body>
int guarded(lpi_system *sys, const char *function, const Arguments &arguments, Body &&body) {
    return run_guarded(sys, true, function, &arguments, std::forward<Body>(body));
}
template <class Body>
int guarded(const lpi_system *sys, const char *function, const Arguments &arguments, Body &&body) {
    return run_guarded(sys, false, function, &arguments, std::forward<Body>(body));
}
template <class Body>
int guarded_local_read(const lpi_system *sys, const char *function, Body &&body) {
    return run_guarded(sys, false, function, nullptr, std::forward<Body>(body));
}
template <class Body>
int guarded(std::nullptr_t, const char *function, Body &&body) {
    return run_guarded(nullptr, false, function, nullptr, std::forward<Body>(body));
}

// Rejects a NULL handle or pointer argument with LPI_ERR_NULL.
inline void require(const void *pointer, const char *what) {
    if (!pointer) lpi::fail(LPI_ERR_NULL, std::string(what) + " is NULL");
}

// A file name: not NULL, not empty (which no system call takes as a name).
inline void require_path(const char *path) {
    require(path, "path");
    if (!*path) lpi::fail(LPI_ERR_INVALID, "path is empty");
}

// Creates a handle around a model built by make(); *out is NULL on failure.
template <class Make>
int create(lpi_system **out, const char *function, Make &&make) {
    if (out) *out = nullptr;
    return guarded(nullptr, function, [&] {
        require(out, "out");
        *out = new lpi_system(make());
    });
}

}  // namespace lpi::capi
