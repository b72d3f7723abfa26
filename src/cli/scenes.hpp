// The built-in scenes: a configured system, an initial state, a final time,
// the step sizes to sweep, and how the reference solution is obtained.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common.hpp"

namespace lpi_cli {

struct Scene {
    std::string name;
    std::string description;
    std::function<Handle()> create;  // configured system with its initial state
    double final_time = 1.0;
    std::vector<double> steps;       // the sweep, largest first
    // Reference: the exact solution when the system has one, otherwise a much
    // finer run of `reference_method` with `reference_step`.
    bool exact_reference = false;
    std::string reference_method;
    double reference_step = 0.0;
    bool in_default_report = true;
};

std::vector<Scene> builtin_scenes();

}  // namespace lpi_cli
