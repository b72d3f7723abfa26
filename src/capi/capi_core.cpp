// The C ABI of the core: handles, methods, state, stepping, diagnostics.
// Functions here validate and forward; the System does the work.
#include <cmath>
#include <limits>

#include "../core/cancellation.hpp"
#include "../core/methods.hpp"
#include "../models/models.hpp"
#include "handle.hpp"

using lpi::capi::create;
using lpi::capi::Arguments;
using lpi::capi::guarded;
using lpi::capi::require;
using lpi::capi::Text;

namespace lpi::capi {
std::string &thread_error() {
    static thread_local std::string message;
    return message;
}
}  // namespace lpi::capi

#define LPI_STRINGIFY2(x) #x
#define LPI_STRINGIFY(x) LPI_STRINGIFY2(x)

extern "C" {

LPI_API const char *lpi_version_string(void) {
    return LPI_STRINGIFY(LPI_VERSION_MAJOR) "." LPI_STRINGIFY(LPI_VERSION_MINOR) "." LPI_STRINGIFY(
        LPI_VERSION_PATCH);
}

LPI_API int lpi_version_number(void) { return LPI_VERSION_NUMBER; }

LPI_API const char *lpi_status_name(int status) {
    switch (status) {
#define LPI_STATUS_NAME_CASE(name, value, message) \
    case value:                                    \
        return #name;
        LPI_STATUS_LIST(LPI_STATUS_NAME_CASE)
#undef LPI_STATUS_NAME_CASE
    }
    return "LPI_UNKNOWN_STATUS";
}

LPI_API const char *lpi_status_message(int status) {
    switch (status) {
#define LPI_STATUS_MESSAGE_CASE(name, value, message) \
    case value:                                       \
        return message;
        LPI_STATUS_LIST(LPI_STATUS_MESSAGE_CASE)
#undef LPI_STATUS_MESSAGE_CASE
    }
    return "unknown status code";
}

LPI_API int lpi_rigid_body_create(lpi_system **out, double I1, double I2, double I3) {
    return create(out, "lpi_rigid_body_create", [&] { return lpi::make_rigid_body(I1, I2, I3); });
}

LPI_API int lpi_pendulum_create(lpi_system **out) {
    return create(out, "lpi_pendulum_create", [] { return lpi::make_pendulum(); });
}

LPI_API int lpi_destroy(lpi_system *sys) {
    // Freeing the handle under a call in progress on it would leave that
    // call working on freed memory.
    lpi::capi::Claim claim(sys, true);
    if (const char *why = claim.refused()) {
        lpi::capi::record(claim.by_another_thread() ? nullptr : sys, "lpi_destroy", why);
        return LPI_ERR_BUSY;
    }
    claim.release_with_handle();
    delete sys;
    return LPI_OK;
}

LPI_API int lpi_set_method(lpi_system *sys, const char *name) {
    return guarded(sys, "lpi_set_method", Arguments(Text{name}), [&] {
        require(sys, "system");
        require(name, "method name");
        sys->system.set_method(name);
    });
}

LPI_API int lpi_set_split(lpi_system *sys, const char *name) {
    return guarded(sys, "lpi_set_split", Arguments(Text{name}), [&] {
        require(sys, "system");
        require(name, "split name");
        sys->system.set_split(name);
    });
}

LPI_API int lpi_set_threads(lpi_system *sys, int32_t n) {
    lpi::act_on_a_pending_cancel();
    return guarded(sys, "lpi_set_threads", Arguments(), [&] {
        require(sys, "system");
        sys->system.set_threads(n);  // bounded in the System, before the model sees n
    });
}

LPI_API const char *lpi_kind(const lpi_system *sys) {
    return sys ? sys->system.model().kind() : nullptr;
}

LPI_API const char *lpi_get_method(const lpi_system *sys) {
    return sys ? sys->system.method().name.c_str() : nullptr;
}

LPI_API const char *lpi_get_split(const lpi_system *sys) {
    return sys ? sys->system.split().c_str() : nullptr;
}

LPI_API size_t lpi_dim(const lpi_system *sys) { return sys ? sys->system.dim() : 0; }

LPI_API int lpi_set_state(lpi_system *sys, const double *x, size_t n) {
    return guarded(sys, "lpi_set_state", Arguments(x, n), [&] {
        require(sys, "system");
        require(x, "state");
        sys->system.set_state(x, n);
    });
}

LPI_API int lpi_get_state(const lpi_system *sys, double *x, size_t n) {
    return guarded(sys, "lpi_get_state", Arguments(x, n), [&] {
        require(sys, "system");
        require(x, "state buffer");
        sys->system.get_state(x, n);
    });
}

LPI_API int lpi_step(lpi_system *sys, double dt, int64_t nsteps) {
    return guarded(sys, "lpi_step", Arguments(dt, nsteps), [&] {
        require(sys, "system");
        return sys->system.step(dt, nsteps) ? LPI_OK : LPI_STOPPED;
    });
}

LPI_API int lpi_set_observer(lpi_system *sys, int64_t every, lpi_observer_fn fn, void *user) {
    return guarded(sys, "lpi_set_observer", Arguments(every, fn), [&] {
        require(sys, "system");
        if (!fn) return sys->system.set_observer(0, nullptr);
        // While fn runs the handle is Observing: fn may read it, not change it.
        // Made (it allocates) where a failure on one process of a spread
        // system fails the call on all: a process without the observer would
        // skip the agreements the others make at each observation.
        lpi::System::Observer observer;
        sys->system.model().agree_on_every_process([&] {
            observer = [sys, fn, user](std::int64_t step, double t) {
                lpi::capi::ActivityScope observing(sys, lpi::capi::Activity::Observing);
                return lpi::call_user([&] { return fn(sys, step, t, user); },
                                      [] { return std::string("the observer callback"); }) != 0;
            };
        });
        sys->system.set_observer(every, std::move(observer));
    });
}

LPI_API double lpi_time(const lpi_system *sys) {
    return sys ? sys->system.time() : std::numeric_limits<double>::quiet_NaN();
}

LPI_API int lpi_energy(const lpi_system *sys, double *out) {
    return guarded(sys, "lpi_energy", Arguments(out), [&] {
        require(sys, "system");
        require(out, "out");
        *out = sys->system.energy();
    });
}

LPI_API size_t lpi_casimir_count(const lpi_system *sys) {
    return sys ? sys->system.casimir_count() : 0;
}

LPI_API int lpi_casimirs(const lpi_system *sys, double *out, size_t n) {
    return guarded(sys, "lpi_casimirs", Arguments(out, n), [&] {
        require(sys, "system");
        require(out, "out");
        sys->system.casimirs(out, n);
    });
}

LPI_API const char *lpi_last_error(const lpi_system *sys) {
    return sys ? sys->last_error.c_str() : lpi::capi::thread_error().c_str();
}

}  // extern "C"
