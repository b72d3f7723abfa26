#include "fixed_point.hpp"

#include <string>

#include "../core/error.hpp"

namespace lpi {

void FixedPointTest::diverged() const {
    fail(LPI_ERR_NO_CONVERGENCE, std::string(method_) +
                                     ": fixed-point iteration diverged to a change that is not finite "
                                     "(dt too large for the iteration, or a state so far from magnitude 1 "
                                     "that its products overflow or underflow)");
}

void FixedPointTest::failed() const {
    fail(LPI_ERR_NO_CONVERGENCE,
         std::string(method_) + ": fixed-point iteration did not converge in " +
             std::to_string(settings_.max_iterations) + " iterations (dt too large for the "
             "iteration, a state whose products underflow, or raise the limit with "
             "lpi_set_implicit_options)");
}

}  // namespace lpi
