// The built-in scenes: a configured system, an initial state, a final time,
// the step sizes to sweep, and how the reference solution is obtained.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common.hpp"

namespace lpi_cli {

// What `lpi run` gives a scene with run_own: --N, --steps and --dt (0 when not
// given) and --out.
struct OwnRun {
    int N = 0;
    int64_t steps = 0;
    double dt = 0.0;
    std::string out_dir;
};

struct Scene {
    std::string name;
    std::string description;
    // The options that configure this scene (lpi --help lists them beside
    // it): any other option that configures scenes is refused for this one.
    std::vector<std::string> options;
    std::function<Handle()> create;  // configured system with its initial state (empty: report only)
    double final_time = 1.0;
    double run_step = 0.01;          // lpi run's default --dt
    std::vector<double> steps;       // the sweep, largest first (a custom_run's steps, for the check of
                                     // final_time / step below 2^62 before any scene runs)
    // Reference: the exact solution when the system has one (accurate to
    // `exact_accuracy` at T, as its documentation bounds it), otherwise a
    // much finer run of `reference_method` with `reference_step`.
    bool exact_reference = false;
    double exact_accuracy = 0.0;
    std::string reference_method;
    double reference_step = 0.0;
    bool in_default_report = true;
    // Methods left out of the sweep, with the reason printed.
    std::vector<std::string> excluded_methods;
    std::string exclusion_reason;
    // Why the scene cannot run in this build ("" when it can).
    std::function<std::string()> unavailable = [] { return std::string(); };
    // A scene that is not a step-size sweep runs this instead (figure2);
    // false when an output file was not written (it said why).
    std::function<bool(const std::string &out_dir)> custom_run;
    // The fixed topography h of a scene over one (its state is q = w + h) on
    // the grid, which lpi run writes with the data; empty for the others.
    std::function<std::vector<double>()> topography;
    // A scene `lpi run` integrates its own way (rollup); returns the exit status.
    std::function<int(const OwnRun &)> run_own;
};


struct SceneOptions {
    int sine_euler_n = 31;  // lpi report sine-euler --N (both sine-Euler scenes)
    double qg_kd = 1.0;     // lpi run qg --kd: the deformation wavenumber
    double long_run_time = 2000.0;  // lpi report sine-euler-long --T
    double inertia[3] = {1.0, 2.0, 3.0};  // lpi run rigid-body --inertia
};

std::vector<Scene> builtin_scenes(const SceneOptions &options = {});

// Whether `option` configures some scene (is in some Scene::options).
bool configures_scenes(const std::string &option);

// A long-run scene: each method at its own step sizes, run to final_time
// once per step size, with the maximum energy error and Casimir drift over the
// whole run set against the CPU time the steps took (sine-euler-long).
struct LongRunSweep {
    std::string method;
    std::vector<double> steps;  // largest first
};
struct LongRunScene {
    std::string name;
    std::string description;
    std::string setting;  // the size and final time, for titles: "N = 31, T = 2000"
    std::function<Handle()> create;
    double final_time = 1.0;
    // Diagnostics at the same equally spaced times for every run: at most this
    // many, and never closer than the largest step of the sweep.
    int max_samples = 500;
    std::vector<LongRunSweep> sweeps;
    std::string exclusion_reason;  // registered methods left out, and why
};

// False when an output file was not written (it said why).
bool run_long_scene(const LongRunScene &scene, const std::string &out_dir);

// The Figure 2 scene: a long leapfrog run, energy error and Casimir drift
// against time, written as CSV and PNG under out_dir. False when an output
// file was not written (it said why).
bool run_figure2(const std::string &out_dir);

// The roll-up scene: a smooth sine-Euler field run long (default N = 63,
// 10^5 leapfrog steps of 0.05), the enstrophy fraction in the highest third of
// the shells against time and the enstrophy spectrum at a few times, as CSV
// and PNG under out_dir.
int run_rollup(const OwnRun &run);

}  // namespace lpi_cli
