// The implicit midpoint rule on the full vector field, x' = x + h f((x + x')/2),
// solved by fixed-point iteration on the midpoint: the implicit (symplectic on
// canonical systems, but not Lie-Poisson) baseline a user would otherwise pick.
#pragma once

#include "../core/methods.hpp"

namespace lpi {

// The implicit-midpoint row of the method table (listed in src/registry.cpp).
Method implicit_midpoint_method();

}  // namespace lpi
