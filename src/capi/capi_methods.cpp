// The C ABI of the method registry and of a system's composition: names,
// orders, stages and sources of the methods; user-supplied compositions; the
// cost of a step in piece flows.
#include <cmath>

#include "../core/methods.hpp"
#include "handle.hpp"

using lpi::capi::Arguments;
using lpi::capi::guarded;
using lpi::capi::guarded_local_read;
using lpi::capi::require;

namespace {

const lpi::Method *row(int i) {
    const auto &table = lpi::method_table();
    return i >= 0 && static_cast<std::size_t>(i) < table.size() ? &table[i] : nullptr;
}

}  // namespace

extern "C" {

LPI_API int lpi_method_count(void) { return static_cast<int>(lpi::method_table().size()); }

LPI_API const char *lpi_method_name(int i) {
    const lpi::Method *m = row(i);
    return m ? m->name.c_str() : nullptr;
}

LPI_API int lpi_method_order(int i) {
    const lpi::Method *m = row(i);
    return m ? m->order : -1;
}

LPI_API int lpi_method_stages(int i) {
    const lpi::Method *m = row(i);
    return m ? m->stages : -1;
}

LPI_API const char *lpi_method_reference(int i) {
    const lpi::Method *m = row(i);
    return m ? m->source.c_str() : nullptr;
}

LPI_API int lpi_method_is_poisson(int i) {
    const lpi::Method *m = row(i);
    return m ? (m->poisson ? 1 : 0) : -1;
}

LPI_API int lpi_set_implicit_options(lpi_system *sys, double tolerance, int32_t max_iterations) {
    return guarded(sys, "lpi_set_implicit_options", Arguments(tolerance, max_iterations), [&] {
        require(sys, "system");
        if (std::isnan(tolerance)) lpi::fail(LPI_ERR_NONFINITE, "tolerance is NaN");
        sys->system.set_implicit_settings({tolerance, max_iterations});
    });
}

LPI_API int lpi_set_composition(lpi_system *sys, size_t n, const double *gammas) {
    return guarded(sys, "lpi_set_composition", Arguments(n, gammas), [&] {
        require(sys, "system");
        require(gammas, "gammas");
        sys->system.set_composition(gammas, n);
    });
}

LPI_API int lpi_flows_per_step(const lpi_system *sys, size_t *out) {
    return guarded_local_read(sys, "lpi_flows_per_step", [&] {
        require(sys, "system");
        require(out, "out");
        *out = sys->system.flows_per_step();
    });
}

}  // extern "C"
