#include "fixed_point.hpp"

#include <string>

#include "../core/error.hpp"

namespace lpi {

void FixedPointTest::diverged() const {
    fail(LPI_ERR_NO_CONVERGENCE, std::string(method_) + ": fixed-point iteration diverged at step " +
                                     std::to_string(step_) +
                                     " (dt too large for the iteration); state rolled back");
}

void FixedPointTest::failed() const {
    fail(LPI_ERR_NO_CONVERGENCE,
         std::string(method_) + ": fixed-point iteration did not converge in " +
             std::to_string(settings_.max_iterations) + " iterations at step " +
             std::to_string(step_) + " (dt too large for the iteration, or raise the limit with "
             "lpi_set_implicit_options); state rolled back");
}

}  // namespace lpi
