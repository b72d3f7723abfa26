// `lpi run`'s options: the command line read into RunOptions.
#pragma once

#include <cstdint>
#include <set>
#include <string>

#include "scenes.hpp"

namespace lpi_cli {

struct RunOptions {
    std::string scene;
    std::string method;        // empty: the system's default (leapfrog)
    double dt = 0.0;           // 0: the scene's run_step
    int64_t steps = 0;         // the end step of the whole run, or (0)...
    double until = 0.0;        // ...its end time (0: the scene's final time)
    int64_t every = 0;         // output interval in steps (0: about 100 rows)
    int32_t threads = 1;
    std::string planning;      // sine-Euler FFTW planning (empty: the library's default)
    std::string wisdom;        // FFTW wisdom file: imported when it exists, written after measuring
    int64_t snapshot_every = 10;  // keep the state every this many output rows (0: none)
    std::string out_dir = "lpi-run";
    std::string checkpoint;    // save here at the start, every checkpoint_every rows and at the end
    int64_t checkpoint_every = 10;
    std::string resume;        // continue from this checkpoint
    std::string init;          // sine-Euler: the initial vorticity grid from this file
    std::string format;        // of the data: "h5" or "npy" (default: h5 when built with HDF5)
    std::set<std::string> given;  // the options given ("--N", ...)
    SceneOptions scene_options;
};

// Reads lpi run's arguments; false when --help printed the usage instead (the
// command then succeeds), and a bad option exits 2 with a message.
bool parse_run_options(int argc, char **argv, RunOptions &o);

// Exits 2 with a message naming the first option given that `scene` does not
// take: one that configures other scenes (Scene::options), or, for a scene
// run its own way, any but its own and --steps, --dt and --out.
void refuse_options_not_taken(const RunOptions &o, const Scene &scene);

}  // namespace lpi_cli
