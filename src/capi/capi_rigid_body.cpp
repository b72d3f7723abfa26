// The C ABI of the rigid body's exact solution (a baseline, beside the
// integrators, never inside them).
#include <cmath>

#include "../models/models.hpp"
#include "../baselines/rigid_body_exact.hpp"
#include "../core/text.hpp"
#include "handle.hpp"

using lpi::capi::guarded;
using lpi::capi::guarded_local_read;
using lpi::capi::require;

extern "C" {

LPI_API int lpi_rigid_body_exact(const lpi_system *sys, double t, double *out) {
    return guarded_local_read(sys, "lpi_rigid_body_exact", [&] {
        require(sys, "system");
        require(out, "out");
        if (!std::isfinite(t)) lpi::fail(LPI_ERR_NONFINITE, "t = " + lpi::number_text(t) + " is not finite");
        double inertia[3], m0[3], m[3];
        if (!lpi::rigid_body_inertia(sys->system.model(), inertia))
            lpi::fail(LPI_ERR_UNSUPPORTED, std::string("the exact solution is defined for the "
                                                       "rigid body, not for ") +
                                               sys->system.model().kind());
        sys->system.get_state(m0, 3);
        lpi::rigid_body_exact(inertia, m0, t, m);
        // The state and t are finite: a value that is not has overflowed.
        lpi::require_no_overflow(m, 3, [](std::size_t i) {
            return "component " + std::to_string(i) + " of the exact solution at this t";
        });
        out[0] = m[0], out[1] = m[1], out[2] = m[2];
    });
}

}  // extern "C"
