// The one exception type of the core. The C API (src/capi) turns it into a
// status code and a per-handle message; nothing else crosses the ABI.
#pragma once

#include <stdexcept>
#include <string>
#if defined(__GLIBCXX__)
#include <cxxabi.h>
#endif

#include "liepoisson.h"

namespace lpi {

class Error : public std::runtime_error {
public:
    Error(lpi_status status, const std::string &message)
        : std::runtime_error(message), status_(status) {}
    lpi_status status() const noexcept { return status_; }

private:
    lpi_status status_;
};

[[noreturn]] inline void fail(lpi_status status, const std::string &message) {
    throw Error(status, message);
}

// LPI_ERR_UNSUPPORTED because a method can never apply to the system (not
// because this build or a spread system lacks what it needs): a checkpoint
// naming such a method is not one the library writes, so loading it is
// LPI_ERR_FORMAT.
class MethodNotApplicable : public Error {
public:
    explicit MethodNotApplicable(const std::string &message) : Error(LPI_ERR_UNSUPPORTED, message) {}
};

// Rethrows the exception being handled where it is the forced unwind of a
// thread that is ending inside a callback (pthread_exit, pthread_cancel, or
// Python ending a daemon thread at exit). No handler may stop it: caught and
// not rethrown, it aborted the process. Called first in a catch (...). The
// unwind is no C++ object, so its reference binds to null, which UBSan would
// report.
#if defined(__GLIBCXX__)
__attribute__((no_sanitize("null"))) inline void rethrow_if_thread_ending() {
    try {
        throw;
    } catch (abi::__forced_unwind &) {
        throw;
    } catch (...) {
    }
}
#else
inline void rethrow_if_thread_ending() {}
#endif

// Calls a user callback. A C++ exception thrown from it (a callback written
// in C++) is the user's failure: LPI_ERR_CALLBACK naming the callback
// (name() is formed only then), not an internal error of the library. A
// thread ending inside it goes on ending (rethrow_if_thread_ending).
template <class Call, class Name>
decltype(auto) call_user(Call &&call, Name &&name) {
    try {
        return call();
    } catch (const std::exception &e) {
        fail(LPI_ERR_CALLBACK, name() + " threw an exception: " + e.what());
    } catch (...) {
        rethrow_if_thread_ending();
        fail(LPI_ERR_CALLBACK, name() + " threw an exception");
    }
}

}  // namespace lpi
