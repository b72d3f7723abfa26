// Small helpers shared by the lpi subcommands. The command uses only the
// public C API, as any user program would.
#pragma once

#include <liepoisson.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace lpi_cli {

inline double cpu_seconds() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Exits with the library's message: the command (never the library) stops.
inline void check(int status, const lpi_system *sys, const char *what) {
    if (status == LPI_OK) return;
    std::fprintf(stderr, "lpi: %s failed: %s (%s)\n", what, lpi_last_error(sys),
                 lpi_status_name(status));
    std::exit(1);
}

// Owns one handle.
class Handle {
public:
    Handle() = default;
    explicit Handle(lpi_system *sys) : sys_(sys) {}
    Handle(const Handle &) = delete;
    Handle &operator=(const Handle &) = delete;
    Handle(Handle &&other) noexcept : sys_(other.sys_) { other.sys_ = nullptr; }
    Handle &operator=(Handle &&other) noexcept {
        std::swap(sys_, other.sys_);
        return *this;
    }
    ~Handle() { lpi_destroy(sys_); }
    lpi_system *get() const { return sys_; }
    lpi_system **out() { return &sys_; }

private:
    lpi_system *sys_ = nullptr;
};

// The registered methods a system accepts (the matrix-form baselines, for
// instance, apply to sine-Euler only), probed once on one system from `create`.
inline std::vector<bool> accepted_methods(const std::function<Handle()> &create) {
    Handle probe = create();
    std::vector<bool> accepted(static_cast<std::size_t>(lpi_method_count()));
    for (int i = 0; i < lpi_method_count(); ++i)
        accepted[static_cast<std::size_t>(i)] = lpi_set_method(probe.get(), lpi_method_name(i)) == LPI_OK;
    return accepted;
}

inline std::vector<double> state_of(const lpi_system *sys) {
    std::vector<double> x(lpi_dim(sys));
    check(lpi_get_state(sys, x.data(), x.size()), sys, "get state");
    return x;
}

inline std::vector<double> casimirs_of(const lpi_system *sys) {
    std::vector<double> c(lpi_casimir_count(sys));
    check(lpi_casimirs(sys, c.data(), c.size()), sys, "casimirs");
    return c;
}

inline double energy_of(const lpi_system *sys) {
    double h = 0.0;
    check(lpi_energy(sys, &h), sys, "energy");
    return h;
}

}  // namespace lpi_cli
