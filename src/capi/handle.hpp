// The opaque handle behind the C ABI and the one place where exceptions become
// status codes. Every exported function runs its body inside guarded().
#pragma once

#include <new>
#include <string>
#include <utility>

#include "../core/error.hpp"
#include "../core/system.hpp"
#include "liepoisson.h"

struct lpi_system {
    explicit lpi_system(std::unique_ptr<lpi::Model> model) : system(std::move(model)) {}
    lpi::System system;
    mutable std::string last_error;
};

namespace lpi::capi {

// Failures of calls with no handle to report on (a failed create, NULL handle).
std::string &thread_error();

inline void record(const lpi_system *sys, const std::string &message) {
    (sys ? sys->last_error : thread_error()) = message;
}

// Runs body(); maps lpi::Error to its status, std::bad_alloc to
// LPI_ERR_NO_MEMORY and anything else to LPI_ERR_INTERNAL, recording the
// message on sys (or the thread when sys is NULL).
template <class Body>
int guarded(const lpi_system *sys, const char *function, Body &&body) noexcept {
    try {
        body();
        return LPI_OK;
    } catch (const lpi::Error &e) {
        try { record(sys, std::string(function) + ": " + e.what()); } catch (...) {}
        return e.status();
    } catch (const std::bad_alloc &) {
        try { record(sys, std::string(function) + ": out of memory"); } catch (...) {}
        return LPI_ERR_NO_MEMORY;
    } catch (const std::exception &e) {
        try { record(sys, std::string(function) + ": internal error: " + e.what()); } catch (...) {}
        return LPI_ERR_INTERNAL;
    } catch (...) {
        try { record(sys, std::string(function) + ": internal error"); } catch (...) {}
        return LPI_ERR_INTERNAL;
    }
}

// Rejects a NULL handle or pointer argument with LPI_ERR_NULL.
inline void require(const void *pointer, const char *what) {
    if (!pointer) lpi::fail(LPI_ERR_NULL, std::string(what) + " is NULL");
}

// Creates a handle around a model built by make(); *out is NULL on failure.
template <class Make>
int create(lpi_system **out, const char *function, Make &&make) noexcept {
    if (out) *out = nullptr;
    return guarded(nullptr, function, [&] {
        require(out, "out");
        *out = new lpi_system(make());
    });
}

}  // namespace lpi::capi
