// The stress cases of lpi stress: stiff and extreme systems, the step sizes
// each is run at, and what a Poisson method is allowed there.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common.hpp"

namespace lpi_cli {

// Extra measured quantities a case may compute itself (moments).
using CasimirMeasure = std::function<void(const std::vector<double> &x, std::vector<long double> &c,
                                          std::vector<long double> &scale)>;

struct Case {
    std::string name;
    std::function<Handle()> create;  // configured system with its initial state
    double period = 0.0;             // fastest period; steps are multiples of it
    std::vector<double> factors;     // dt = factor * period (period 0: dt = factor)
    std::int64_t steps = 1000;
    std::vector<std::string> methods;  // empty: every method
    CasimirMeasure measure;            // empty: lpi_casimirs, scale from kind below
    bool spectrum_scale = false;       // scale = max |C_k(0)| (eigenvalues)
    int samples = 20;                  // times the state is measured (equal chunks of steps)
    // Casimir round-off allowed to a Poisson method: floor (the measurement's
    // own round-off) + per_flow * flows.
    double drift_floor = 1e-15;
    // A status a Poisson method may return here (rolled back) instead of
    // stepping: LPI_ERR_NONFINITE where the exact flow of a piece overflows,
    // LPI_ERR_INVALID where a generic flow needs too many squarings.
    int allowed_failure = LPI_OK;
};

// The matrix of cases (quick: shorter runs, and no N = 1021 sine-Euler).
std::vector<Case> build_cases(bool quick);

}  // namespace lpi_cli
