// The stopping test of the implicit baselines' fixed-point iterations
// (implicit-midpoint, isomp), written once.
#pragma once

#include <cmath>
#include <cstdint>

#include "../core/integrator.hpp"

namespace lpi {

// The largest change of an iteration so far, updated by one more
// component's change d: a NaN, once seen, stays.
inline double max_change(double change, double d) {
    return d > change || std::isnan(d) ? d : change;
}

// Whether an iteration whose largest change is `change` has converged for a
// state whose largest |component| is `largest`: change <= tolerance *
// max(1, largest) (lpi_set_implicit_options). Compared as a quotient: the
// product of a large tolerance and a large state would overflow to +inf and
// pass any change at once. Throws LPI_ERR_NO_CONVERGENCE naming `method` and
// `step` when the iteration diverged (a change that is not finite).
bool fixed_point_converged(double change, double largest, const ImplicitSettings &settings,
                           const char *method, std::int64_t step);

// Throws LPI_ERR_NO_CONVERGENCE: no convergence in settings.max_iterations.
[[noreturn]] void fixed_point_failed(const ImplicitSettings &settings, const char *method,
                                     std::int64_t step);

}  // namespace lpi
