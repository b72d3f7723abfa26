// `lpi report`: a work-precision table (error against CPU time) for every
// applicable method over a sweep of step sizes, written as text, CSV and PNG.
#pragma once

#include <string>

#include "scenes.hpp"

namespace lpi_cli {

struct ReportOptions {
    std::string out_dir = "lpi-report";
    double min_timing_seconds = 0.05;  // repeat a timed run until it lasts this long
    int samples = 200;                 // energy/Casimir samples per diagnostic run
};

// False when an output file was not written (it said why).
bool run_report(const Scene &scene, const ReportOptions &options);

// One diagnostic sample of a run: the relative energy error and Casimir drift
// at a time.
struct Sample {
    double time, energy_error, casimir_drift;
};

// Keeps the BLAS on the calling thread, so CPU times are those of one core.
void measure_on_one_core();

}  // namespace lpi_cli
