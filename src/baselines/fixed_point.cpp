#include "fixed_point.hpp"

#include <string>

#include "../core/error.hpp"

namespace lpi {

bool fixed_point_converged(double change, double largest, const ImplicitSettings &settings,
                           const char *method, std::int64_t step) {
    if (!std::isfinite(change))
        fail(LPI_ERR_NO_CONVERGENCE, std::string(method) +
                                         ": fixed-point iteration diverged at step " +
                                         std::to_string(step) +
                                         " (dt too large for the iteration); state rolled back");
    const double scale = std::fmax(1.0, largest);
    return change / scale <= settings.tolerance;
}

void fixed_point_failed(const ImplicitSettings &settings, const char *method, std::int64_t step) {
    fail(LPI_ERR_NO_CONVERGENCE,
         std::string(method) + ": fixed-point iteration did not converge in " +
             std::to_string(settings.max_iterations) + " iterations at step " +
             std::to_string(step) + " (dt too large for the iteration, or raise the limit with "
             "lpi_set_implicit_options); state rolled back");
}

}  // namespace lpi
