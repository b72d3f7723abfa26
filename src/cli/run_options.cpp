#include "run_options.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <vector>

#include "data_files.hpp"

namespace lpi_cli {

namespace {

void run_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi run SCENE [options]\n"
                 "  integrate SCENE (lpi --help lists them) and write diagnostics and data\n"
                 "  --method NAME     integration method (default leapfrog; lpi methods lists them)\n"
                 "  --dt H            step size (default 0.01; figure2: 0.05)\n"
                 "  --steps N         number of steps, or\n"
                 "  --until T         end time (default: the scene's final time)\n"
                 "  --every K         write a row every K steps (default: about 100 rows;\n"
                 "                    resumed: the interrupted run's)\n"
                 "  --threads N       threads inside a step (sine-Euler; default 1)\n"
                 "  --planning R      sine-Euler FFTW planning: estimate (default: the same bits in\n"
                 "                    every process), measure or patient (faster transforms; other\n"
                 "                    processes may round differently unless they share --wisdom)\n"
                 "  --wisdom FILE     FFTW wisdom: imported first when FILE exists, and written\n"
                 "                    after measured planning, so later runs reuse those plans\n"
                 "                    (sine-Euler; a file that cannot be read or written: exit 1)\n"
                 "  --N N             sine-Euler size (odd >= 3, default 31, or the --init grid's)\n"
                 "  --init FILE       sine-Euler: the initial vorticity on the N x N grid, from a\n"
                 "                    .npy array (N, N) (float64, float32, int64 or int32) or an\n"
                 "                    HDF5 file's /init (N, N) or /vorticity (the last snapshot\n"
                 "                    of an lpi run)\n"
                 "  --inertia A,B,C   rigid-body inertias (default 1,2,3)\n"
                 "  --kd K            qg: the deformation wavenumber k_d > 0 (default 1)\n"
                 "  --snapshots K     keep the state (sine-Euler: the vorticity grid, also drawn\n"
                 "                    by DIR/SCENE_vorticity.gp as DIR/SCENE_vorticity_STEP.png\n"
                 "                    and .svg) every K rows (default 10; 0: none)\n"
                 "  --format h5|npy   the data: one HDF5 file DIR/SCENE.h5 (default when built with\n"
                 "                    HDF5) or NumPy files DIR/SCENE/NAME.npy\n"
                 "  --out DIR         output directory (default ./lpi-run)\n"
                 "  --checkpoint FILE save a checkpoint (atomically) at the start, every 10 rows\n"
                 "                    and at the end, the CSV and the data with it (so a run\n"
                 "                    killed outright resumes with its snapshots; they grow in\n"
                 "                    place, HDF5 through DIR/SCENE.h5-pending); a failed save\n"
                 "                    stops the run (exit status 1); not for moments, nor a FILE\n"
                 "                    the run writes\n"
                 "  --checkpoint-every K   ... every K rows instead (0: at the start and end only)\n"
                 "  --resume FILE     continue an interrupted run from its checkpoint, with the\n"
                 "                    options of that run: it ends bit for bit where the run\n"
                 "                    would have ended (--steps and --until count from the start\n"
                 "                    of the whole run; the rows and snapshots after the\n"
                 "                    checkpoint's step are replaced); --dt, --every and\n"
                 "                    --snapshots not given are that run's (so a larger --steps\n"
                 "                    extends it); into an --out without the run's files, new\n"
                 "                    files start at the checkpoint's step, given --dt and\n"
                 "                    --every (the checkpoint does not record them)\n"
                 "  The options that configure a scene (lpi --help lists each scene's in brackets)\n"
                 "  are refused for a scene that does not take them.\n"
                 "  writes DIR/SCENE.csv: step, time, energy, relative energy error (to the energy\n"
                 "  at step 0; absolute where that is 0), Casimirs; and the data (rows and\n"
                 "  snapshots) as --format says; a failed write keeps the old files (lpi(1)); a\n"
                 "  progress bar with the time left is shown on a terminal only. Ctrl-C (SIGINT) or\n"
                 "  SIGTERM stops within a few steps, writes a row at that step, the data and the\n"
                 "  checkpoint of the last row on the --every grid, and exits with status 130 (143).\n");
}

}  // namespace

bool parse_run_options(int argc, char **argv, RunOptions &o) {
    Arguments args("lpi run", argc, argv);
    const int32_t int32_max = 2147483647;
    while (!args.done()) {
        const std::string arg = args.next();
        if (arg == "--method") o.method = args.value(arg);
        else if (arg == "--dt") o.dt = args.positive(arg);
        else if (arg == "--steps") o.steps = args.integer(arg, 1, kMaxSteps);
        else if (arg == "--until") o.until = args.positive(arg);
        else if (arg == "--every") o.every = args.integer(arg, 1, INT64_MAX);
        else if (arg == "--threads") o.threads = static_cast<int32_t>(args.integer(arg, 1, int32_max));
        else if (arg == "--planning") {
            o.planning = args.value(arg);
            if (o.planning != "estimate" && o.planning != "measure" && o.planning != "patient")
                args.fail("--planning: '" + o.planning + "' is not estimate, measure or patient");
        } else if (arg == "--wisdom") o.wisdom = args.value(arg);
        else if (arg == "--kd") o.scene_options.qg_kd = args.positive(arg);
        else if (arg == "--N") {
            o.scene_options.sine_euler_n = static_cast<int>(args.integer(arg, 3, int32_max));
            if (o.scene_options.sine_euler_n % 2 == 0) args.fail("--N must be odd");
        } else if (arg == "--init") o.init = args.value(arg);
        else if (arg == "--format") {
            o.format = args.value(arg);
            if (o.format != "h5" && o.format != "npy") args.fail("--format: '" + o.format + "' is not h5 or npy");
            if (o.format == "h5" && !have_hdf5())
                args.fail("--format h5: this lpi is built without HDF5 (use --format npy)");
        } else if (arg == "--snapshots") o.snapshot_every = args.integer(arg, 0, INT64_MAX);
        else if (arg == "--out") o.out_dir = args.value(arg);
        else if (arg == "--checkpoint") o.checkpoint = args.value(arg);
        else if (arg == "--checkpoint-every") o.checkpoint_every = args.integer(arg, 0, INT64_MAX);
        else if (arg == "--resume") o.resume = args.value(arg);
        else if (arg == "--inertia") {
            const std::vector<double> I = args.positives(arg, 3);
            std::copy(I.begin(), I.end(), o.scene_options.inertia);
        } else if (args.help(arg)) {
            run_usage(stdout);
            return false;
        } else {
            args.operand(arg, "SCENE");
            if (!o.scene.empty()) args.fail("one scene only ('" + o.scene + "' and '" + arg + "')");
            o.scene = arg;
        }
    }
    if (o.scene.empty()) args.fail("which scene? (lpi --help lists them)");
    if (o.steps > 0 && o.until > 0.0) args.fail("--steps and --until exclude each other");
    if (o.checkpoint.empty() && args.given().count("--checkpoint-every"))
        args.fail("--checkpoint-every: there is no --checkpoint to save (it would be ignored)");
    if (!o.init.empty() && !o.resume.empty())
        args.fail("--init and --resume exclude each other (the checkpoint holds the state)");
    if (o.format.empty()) o.format = have_hdf5() ? "h5" : "npy";
    o.given = args.given();
    return true;
}

void refuse_options_not_taken(const RunOptions &o, const Scene &scene) {
    std::set<std::string> allowed(scene.options.begin(), scene.options.end());
    // A scene run its own way takes its options and these only.
    if (scene.run_own) allowed.insert({"--steps", "--dt", "--out"});
    for (const std::string &option : o.given) {
        if (allowed.count(option)) continue;
        if (!scene.run_own && !configures_scenes(option)) continue;  // an option of every run
        std::string takes;
        for (const std::string &name : scene.options) takes += ", " + name;
        if (scene.run_own) takes += ", --steps, --dt and --out only";
        std::fprintf(stderr, "lpi run: %s: %s does not take it (%s)\n", option.c_str(), scene.name.c_str(),
                     takes.empty() ? "it takes no scene option" : ("it takes " + takes.substr(2)).c_str());
        std::exit(2);
    }
}

}  // namespace lpi_cli
