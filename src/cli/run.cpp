#include "run.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "data_files.hpp"
#include "scenes.hpp"

namespace lpi_cli {

namespace {

struct RunOptions {
    std::string scene;
    std::string method;        // empty: the system's default (leapfrog)
    double dt = 0.0;           // 0: the scene's run_step
    int64_t steps = 0;         // the end step of the whole run, or (0)...
    double until = 0.0;        // ...its end time (0: the scene's final time)
    int64_t every = 0;         // output interval in steps (0: about 100 rows)
    int32_t threads = 1;
    int64_t snapshot_every = 10;  // keep the state every this many output rows (0: none)
    std::string out_dir = "lpi-run";
    std::string checkpoint;    // save here at the start, every checkpoint_every rows and at the end
    int64_t checkpoint_every = 10;
    std::string resume;        // continue from this checkpoint
    std::string init;          // sine-Euler: the initial vorticity grid from this file
    std::string format;        // of the data: "h5" or "npy" (default: h5 when built with HDF5)
    bool n_given = false;
    SceneOptions scene_options;
};

void run_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi run SCENE [options]\n"
                 "  integrate SCENE (lpi --help lists them) and write diagnostics and data\n"
                 "  --method NAME     integration method (default leapfrog; lpi methods lists them)\n"
                 "  --dt H            step size (default 0.01; figure2: 0.05)\n"
                 "  --steps N         number of steps, or\n"
                 "  --until T         end time (default: the scene's final time)\n"
                 "  --every K         write a row every K steps (default: about 100 rows)\n"
                 "  --threads N       threads inside a step (sine-Euler; default 1)\n"
                 "  --N N             sine-Euler size (odd >= 3, default 31, or the --init grid's)\n"
                 "  --init FILE       sine-Euler: the initial vorticity on the N x N grid, from a\n"
                 "                    .npy array (N, N) (float64 or float32) or an HDF5 file's\n"
                 "                    /init (N, N) or /vorticity (the last snapshot of an lpi run)\n"
                 "  --inertia A,B,C   rigid-body inertias (default 1,2,3)\n"
                 "  --snapshots K     keep the state (sine-Euler: the vorticity grid, also drawn as\n"
                 "                    PNG and SVG) every K rows (default 10; 0: none)\n"
                 "  --format h5|npy   the data: one HDF5 file DIR/SCENE.h5 (default when built with\n"
                 "                    HDF5) or NumPy files DIR/SCENE/NAME.npy\n"
                 "  --out DIR         output directory (default ./lpi-run)\n"
                 "  --checkpoint FILE save a checkpoint (atomically) at the start, every 10 rows\n"
                 "                    and at the end; a failed save stops the run (exit status 1)\n"
                 "  --checkpoint-every K   ... every K rows instead (0: at the start and end only)\n"
                 "  --resume FILE     continue an interrupted run from its checkpoint, with the\n"
                 "                    options of that run: it ends bit for bit where the run\n"
                 "                    would have ended (--steps and --until count from the start\n"
                 "                    of the whole run; the rows and snapshots after the\n"
                 "                    checkpoint's step are replaced)\n"
                 "  writes DIR/SCENE.csv: step, time, energy, relative energy error (to the energy\n"
                 "  at step 0), Casimirs; and the data (rows and snapshots) as --format says; a\n"
                 "  progress bar with the time left is shown on a terminal only. Ctrl-C (SIGINT) or\n"
                 "  SIGTERM stops within a few steps, writes a row at that step, the data and the\n"
                 "  checkpoint of the last row on the --every grid, and exits with status 130 (143).\n");
}

void parse(int argc, char **argv, RunOptions &o) {
    Arguments args("lpi run", argc, argv);
    const int32_t int32_max = 2147483647;
    while (!args.done()) {
        const std::string arg = args.next();
        if (arg == "--method") o.method = args.value(arg);
        else if (arg == "--dt") o.dt = args.positive(arg);
        else if (arg == "--steps") o.steps = args.integer(arg, 1, INT64_MAX);
        else if (arg == "--until") o.until = args.positive(arg);
        else if (arg == "--every") o.every = args.integer(arg, 1, INT64_MAX);
        else if (arg == "--threads") o.threads = static_cast<int32_t>(args.integer(arg, 1, int32_max));
        else if (arg == "--N") {
            o.scene_options.sine_euler_n = static_cast<int>(args.integer(arg, 3, int32_max));
            if (o.scene_options.sine_euler_n % 2 == 0) args.fail("--N must be odd");
            o.n_given = true;
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
        } else if (arg == "--help" || arg == "-h") {
            run_usage(stdout);
            std::exit(0);
        } else if (!arg.empty() && arg[0] == '-') {
            args.fail("unknown option '" + arg + "' (lpi run --help lists them)");
        } else if (o.scene.empty()) {
            o.scene = arg;
        } else {
            args.fail("one scene only ('" + o.scene + "' and '" + arg + "')");
        }
    }
    if (o.scene.empty()) args.fail("which scene? (lpi --help lists them)");
    if (o.steps > 0 && o.until > 0.0) args.fail("--steps and --until exclude each other");
    if (!o.init.empty() && !o.resume.empty())
        args.fail("--init and --resume exclude each other (the checkpoint holds the state)");
    if (o.format.empty()) o.format = have_hdf5() ? "h5" : "npy";
}

// Set by SIGINT or SIGTERM; the observer then stops the steps (watch_steps).
volatile std::sig_atomic_t interrupted_by = 0;

extern "C" void on_interrupt(int signal_number) { interrupted_by = signal_number; }

// One shot: a second Ctrl-C ends the command at once (SA_RESETHAND).
void catch_interrupts() {
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

// Usage error (exit status 2) when an option the library refuses was given.
void check_option(int status, const lpi_system *sys, const char *option) {
    if (status == LPI_OK) return;
    std::fprintf(stderr, "lpi run: %s: %s (%s)\n", option, lpi_last_error(sys), lpi_status_name(status));
    std::exit(2);
}

// Whether `loaded` is a state of the system `fresh` (the scene with these
// options): same kind, size and Hamiltonian (its energy at the same state).
std::string mismatch(lpi_system *fresh, const lpi_system *loaded) {
    int32_t n_fresh = 0, n_loaded = 0;
    const bool sine_fresh = lpi_sine_euler_size(fresh, &n_fresh) == LPI_OK;
    const bool sine_loaded = lpi_sine_euler_size(loaded, &n_loaded) == LPI_OK;
    if (sine_fresh != sine_loaded) return "it holds another kind of system";
    if (n_fresh != n_loaded) return "it has N = " + std::to_string(n_loaded) + ", not " + std::to_string(n_fresh);
    if (lpi_dim(fresh) != lpi_dim(loaded) || lpi_casimir_count(fresh) != lpi_casimir_count(loaded))
        return "its system has another dimension";
    double m[3];
    if ((lpi_rigid_body_exact(fresh, 0.0, m) == LPI_OK) != (lpi_rigid_body_exact(loaded, 0.0, m) == LPI_OK))
        return "it holds another kind of system";
    const std::vector<double> x = state_of(loaded);
    check(lpi_set_state(fresh, x.data(), x.size()), fresh, "set state");
    const double h_fresh = energy_of(fresh), h_loaded = energy_of(loaded);
    if (std::fabs(h_fresh - h_loaded) > 1e-12 * std::max(std::fabs(h_fresh), std::fabs(h_loaded)))
        return "its Hamiltonian differs (other parameters, such as --inertia)";
    return "";
}

// The step index a time is, to round-off: a resumed run's start.
bool whole_steps(double time, double dt, int64_t &steps) {
    const double s = time / dt;
    if (!(s >= 0.0 && s < 0x1p62)) return false;
    steps = std::llround(s);
    return std::fabs(s - static_cast<double>(steps)) <= 1e-9 * std::max(1.0, s);
}

// The CSV of an interrupted run, up to and including the row of `step`:
// its lines, and the energy of its step-0 row (the error's reference).
// Empty when the file is absent or has no row at `step`.
std::vector<std::string> csv_up_to(const std::string &path, int64_t step, double &energy0) {
    std::vector<std::string> lines;
    FILE *f = std::fopen(path.c_str(), "r");
    if (!f) return lines;
    std::string line;
    bool found = false;
    for (int c; (c = std::fgetc(f)) != EOF;) {
        if (c != '\n') {
            line += static_cast<char>(c);
            continue;
        }
        const bool header = lines.empty();
        if (!header) {
            const long long row_step = std::strtoll(line.c_str(), nullptr, 10);
            if (row_step == 0) {
                const std::size_t a = line.find(','), b = line.find(',', a + 1);
                energy0 = std::strtod(line.c_str() + b + 1, nullptr);
            }
            if (row_step > step) break;
            found = row_step == step;
        }
        lines.push_back(line);
        line.clear();
    }
    std::fclose(f);
    if (!found) lines.clear();
    return lines;
}

// A progress bar with the time left, on stderr, only when it is a terminal;
// redrawn at most ten times a second (wall clock).
class Progress {
public:
    Progress(int64_t first, int64_t last)
        : first_(first), total_(last - first), enabled_(isatty(STDERR_FILENO) == 1 && last > first),
          started_(Clock::now()) {}
    void update(int64_t done) {
        if (!enabled_) return;
        const double elapsed = std::chrono::duration<double>(Clock::now() - started_).count();
        if (elapsed - last_ < 0.1) return;
        last_ = elapsed;
        const double f = static_cast<double>(done - first_) / static_cast<double>(total_);
        const int width = 40, filled = static_cast<int>(f * width);
        // The time left, once 1% is done: before that the rate is noise.
        char left[32] = "";
        if (f >= 0.01) std::snprintf(left, sizeof left, "%.0f s left", elapsed * (1.0 - f) / f);
        std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %-14s", filled, "########################################",
                     width - filled, "", 100.0 * f, left);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_) std::fprintf(stderr, "\r%*s\r", 70, "");
    }

private:
    using Clock = std::chrono::steady_clock;
    int64_t first_, total_;
    bool enabled_;
    Clock::time_point started_;
    double last_ = -1.0;
};


// Stops lpi_step (through its observer) within a few steps of a signal, and
// moves the progress bar on inside long calls. Observing changes no bit of
// the trajectory, so neither the terminal nor the timing changes the run.
struct Watch {
    int64_t call_start = 0;   // the run's step where the current lpi_step call began
    int64_t stopped_at = -1;  // the run's step where the observer stopped it
    Progress *progress = nullptr;
};

extern "C" int watch_steps(const lpi_system *, int64_t step, double, void *user) {
    Watch *watch = static_cast<Watch *>(user);
    if (interrupted_by) {
        watch->stopped_at = watch->call_start + step;
        return 1;
    }
    watch->progress->update(watch->call_start + step);
    return 0;
}

// Observed every this many steps: about 64 piece flows apart, so the extra
// flow an observation costs (the seam it unmerges) stays near 1.5%.
int64_t observation_interval(const lpi_system *sys) {
    std::size_t flows = 0;
    if (lpi_flows_per_step(sys, &flows) != LPI_OK || flows == 0) return 1;
    return static_cast<int64_t>((64 + flows - 1) / flows);
}

// What lpi run keeps as data: every row of the CSV (full precision, the
// Casimir drift added) and a snapshot of the state every --snapshots rows.
struct RunData {
    std::vector<double> step, time, energy, energy_error, casimir_drift;
    std::vector<double> casimirs;  // rows x casimir_count
    std::size_t casimir_count = 0;
    std::vector<double> snapshot_step, snapshot_time;
    std::vector<double> snapshots;            // snapshots x snapshot_shape
    std::vector<std::size_t> snapshot_shape;  // (N, N) vorticity, else (dim) state
    bool vorticity = false;

    std::size_t snapshot_size() const {
        std::size_t n = 1;
        for (std::size_t d : snapshot_shape) n *= d;
        return n;
    }
    // Drops the rows and snapshots after `step` (a resumed run's start).
    void keep_up_to(int64_t last) {
        std::size_t rows = 0, shots = 0;
        while (rows < step.size() && step[rows] <= static_cast<double>(last)) ++rows;
        while (shots < snapshot_step.size() && snapshot_step[shots] <= static_cast<double>(last)) ++shots;
        for (auto *v : {&step, &time, &energy, &energy_error, &casimir_drift}) v->resize(rows);
        casimirs.resize(rows * casimir_count);
        snapshot_step.resize(shots);
        snapshot_time.resize(shots);
        snapshots.resize(shots * snapshot_size());
    }
};

Array array_of(std::vector<std::size_t> shape, const std::vector<double> &values, bool integer = false) {
    Array a;
    a.shape = std::move(shape);
    a.values = values;
    a.integer = integer;
    return a;
}

std::vector<double> indices(std::size_t n, double scale) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = scale * static_cast<double>(i);
    return v;
}

// The datasets of a run's data, with their dimensions named for xarray:
// rows along "time", snapshots along "snapshot_time", the grid along x and y
// (2 pi a / N), the Casimirs and state components by index.
std::vector<Dataset> datasets_of(const RunData &d) {
    const std::size_t rows = d.step.size(), shots = d.snapshot_step.size();
    std::vector<Dataset> sets = {
        {"time", array_of({rows}, d.time), {}, true},
        {"step", array_of({rows}, d.step, true), {"time"}, false},
        {"energy", array_of({rows}, d.energy), {"time"}, false},
        {"energy_error", array_of({rows}, d.energy_error), {"time"}, false},
        {"casimir", array_of({d.casimir_count}, indices(d.casimir_count, 1.0), true), {}, true},
        {"casimirs", array_of({rows, d.casimir_count}, d.casimirs), {"time", "casimir"}, false},
        {"casimir_drift", array_of({rows}, d.casimir_drift), {"time"}, false},
        {"snapshot_time", array_of({shots}, d.snapshot_time), {}, true},
        {"snapshot_step", array_of({shots}, d.snapshot_step, true), {"snapshot_time"}, false},
    };
    std::vector<std::size_t> shape = {shots};
    shape.insert(shape.end(), d.snapshot_shape.begin(), d.snapshot_shape.end());
    if (d.vorticity) {
        const std::size_t N = d.snapshot_shape[0];
        const std::vector<double> x = indices(N, 2.0 * 3.14159265358979323846 / static_cast<double>(N));
        sets.push_back({"x", array_of({N}, x), {}, true});
        sets.push_back({"y", array_of({N}, x), {}, true});
        sets.push_back({"vorticity", array_of(shape, d.snapshots), {"snapshot_time", "x", "y"}, false});
    } else {
        sets.push_back({"component", array_of({d.snapshot_shape[0]}, indices(d.snapshot_shape[0], 1.0), true),
                        {}, true});
        sets.push_back({"state", array_of(shape, d.snapshots), {"snapshot_time", "component"}, false});
    }
    return sets;
}

// Where a run's data lives: DIR/SCENE.h5, or the folder DIR/SCENE of .npy files.
std::string data_path(const RunOptions &o) {
    return o.out_dir + "/" + o.scene + (o.format == "h5" ? ".h5" : "");
}

// Where the snapshots' raw doubles start in the written data (for gnuplot).
struct SnapshotBytes {
    std::string file;
    std::uint64_t offset = UINT64_MAX;
};

// Writes the data atomically (each .npy file on its own); "" or the reason.
std::string write_data(const RunOptions &o, const RunData &d, const std::vector<Attribute> &attributes,
                       SnapshotBytes &bytes) {
    const std::vector<Dataset> sets = datasets_of(d);
    const std::string path = data_path(o);
    if (o.format == "h5") {
        std::vector<std::uint64_t> offsets;
        const std::string why = write_hdf5(path, sets, attributes, &offsets);
        if (!why.empty()) return why;
        bytes = {path, offsets.back()};
        return "";
    }
    if (mkdir(path.c_str(), 0777) != 0 && errno != EEXIST) return std::strerror(errno);
    for (const Dataset &set : sets) {
        const std::string why = write_npy(path + "/" + set.name + ".npy", set.array);
        if (!why.empty()) return set.name + ".npy: " + why;
    }
    // The attributes as JSON (json.load reads them).
    auto quoted = [](const std::string &text) {
        std::string q = "\"";
        for (char c : text) q += c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c);
        return q + "\"";
    };
    std::string json = "{";
    for (const Attribute &a : attributes) {
        char number[40];
        std::snprintf(number, sizeof number, "%.17g", a.number);
        if (a.integer) std::snprintf(number, sizeof number, "%lld", static_cast<long long>(a.number));
        json += (json.size() > 1 ? ", \"" : "\"") + a.name + "\": " + (a.is_text ? quoted(a.text) : number);
    }
    FILE *f = std::fopen((path + "/attributes.json").c_str(), "w");
    if (!f || std::fprintf(f, "%s}\n", json.c_str()) < 0 || std::fclose(f) != 0) return "attributes.json";
    bytes = {path + "/" + sets.back().name + ".npy", npy_header(sets.back().array).size()};
    return "";
}

// One array of a run's earlier data, in this run's format.
std::string read_data_array(const RunOptions &o, const std::string &name, Array &a) {
    const std::string path = data_path(o);
    if (o.format == "npy") return read_npy(path + "/" + name + ".npy", a);
    bool found = false;
    return read_hdf5(path, name, a, &found);
}

// The method of a resumed run given no --method: the checkpoint's, which the
// library does not name; the interrupted run's data does.
std::string earlier_method(const RunOptions &o) {
    std::string method;
    if (o.format == "h5") {
        if (read_hdf5_text(data_path(o), "method", method).empty()) return method;
    } else if (FILE *f = std::fopen((data_path(o) + "/attributes.json").c_str(), "r")) {
        char text[4096] = "";
        const std::size_t n = std::fread(text, 1, sizeof text - 1, f);
        std::fclose(f);
        text[n] = '\0';
        const char *at = std::strstr(text, "\"method\": \"");
        const char *end = at ? std::strchr(at + 11, '"') : nullptr;
        if (end) return std::string(at + 11, end);
    }
    return "the checkpoint's method";
}

// The snapshots of the interrupted run up to `start`, from its data; a note
// on stdout (not an error) when they cannot be read.
void keep_snapshots(const RunOptions &o, int64_t start, RunData &d) {
    Array steps, times, shots;
    std::string why = read_data_array(o, "snapshot_step", steps);
    if (why.empty()) why = read_data_array(o, "snapshot_time", times);
    if (why.empty()) why = read_data_array(o, d.vorticity ? "vorticity" : "state", shots);
    const std::size_t n = steps.values.size();
    if (why.empty() && (times.values.size() != n || shots.values.size() != n * d.snapshot_size()))
        why = "its snapshot arrays do not match this run";
    if (!why.empty()) {
        std::printf("%s: %s; the data keeps the snapshots from step %lld on\n", data_path(o).c_str(),
                    why.c_str(), static_cast<long long>(start));
        return;
    }
    d.snapshot_step = steps.values;
    d.snapshot_time = times.values;
    d.snapshots = shots.values;
    d.keep_up_to(start);
}

// The initial grid of --init, checked against the system's N. Exits 1 when
// the file cannot be read, 2 when it holds no N x N grid for this run.
std::vector<double> initial_grid(const std::string &path, int *N) {
    Array a;
    std::string why;
    if (is_hdf5_file(path)) {
        bool found = false;
        why = read_hdf5(path, "init", a, &found);
        if (!found && why.rfind("no dataset", 0) == 0) why = read_hdf5(path, "vorticity", a, &found);
        if (!why.empty() && found) {
            std::fprintf(stderr, "lpi run: --init %s: %s\n", path.c_str(), why.c_str());
            std::exit(2);
        }
        if (!why.empty() && why.rfind("no dataset", 0) == 0) {
            std::fprintf(stderr, "lpi run: --init %s: no dataset /init or /vorticity\n", path.c_str());
            std::exit(2);
        }
        // A run's /vorticity holds snapshots (S, N, N): start from the last.
        if (why.empty() && a.shape.size() == 3 && a.shape[0] > 0) {
            const std::size_t size = a.shape[1] * a.shape[2];
            a.values.erase(a.values.begin(), a.values.end() - static_cast<std::ptrdiff_t>(size));
            a.shape.erase(a.shape.begin());
        }
    } else {
        why = read_npy(path, a);
    }
    if (!why.empty()) {
        std::fprintf(stderr, "lpi run: --init %s: %s\n", path.c_str(), why.c_str());
        std::exit(1);
    }
    std::string shape;
    for (std::size_t d : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    if (a.shape.size() != 2 || a.shape[0] != a.shape[1] || a.shape[0] < 3 || a.shape[0] % 2 == 0 ||
        a.shape[0] > 2147483647u) {
        std::fprintf(stderr, "lpi run: --init %s: the array has shape (%s), not (N, N) with N odd >= 3\n",
                     path.c_str(), shape.c_str());
        std::exit(2);
    }
    if (*N > 0 && static_cast<std::size_t>(*N) != a.shape[0]) {
        std::fprintf(stderr, "lpi run: --init %s: the grid is %s x %s, but --N is %d\n", path.c_str(),
                     std::to_string(a.shape[0]).c_str(), std::to_string(a.shape[0]).c_str(), *N);
        std::exit(2);
    }
    *N = static_cast<int>(a.shape[0]);
    return a.values;
}

// Draws every vorticity snapshot of the data as PNG and SVG with gnuplot,
// which reads the doubles straight from the data file (nothing is copied
// and nothing deleted). Returns how many were drawn.
std::size_t plot_vorticity(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                           const std::string &method) {
    const std::size_t N = d.snapshot_shape[0], shots = d.snapshot_step.size();
    if (shots == 0 || bytes.offset == UINT64_MAX) return 0;
    double scale = 0.0;  // one symmetric colour range for every snapshot
    for (double v : d.snapshots) scale = std::max(scale, std::fabs(v));
    if (!(scale > 0.0)) scale = 1.0;
    const std::string script = o.out_dir + "/vorticity.gp";
    FILE *g = std::fopen(script.c_str(), "w");
    if (!g) return 0;
    // Grid point (a, b) is x = 2 pi a / N, y = 2 pi b / N: the axes count
    // x / 2 pi, each pixel centred on its point. The array is [a][b], b
    // fastest: gnuplot reads it with x and y swapped back (transpose).
    std::fprintf(g,
                 "set size ratio -1\nset palette defined (0 '#2166ac', 0.5 'white', 1 '#b2182b')\n"
                 "unset key\nset xrange [%.17g:%.17g]\nset yrange [%.17g:%.17g]\n"
                 "set xtics 0.25 out nomirror\nset ytics 0.25 out nomirror\nset format x '%%g'\n"
                 "set format y '%%g'\nset cbrange [%.6g:%.6g]\nset cbtics out\n"
                 "set xlabel 'x / 2{/Symbol p}'\nset ylabel 'y / 2{/Symbol p}'\n"
                 "set cblabel 'vorticity {/Symbol w}(x, y)'\n",
                 -0.5 / N, 1.0 - 0.5 / N, -0.5 / N, 1.0 - 0.5 / N, -scale, scale);
    const char *terminals[][2] = {{"pngcairo size 720,640 enhanced font ',12'", "png"},
                                  {"svg size 720,640 enhanced font 'Helvetica,12' background '#ffffff'", "svg"}};
    for (std::size_t k = 0; k < shots; ++k) {
        char name[64];
        const int64_t row = static_cast<int64_t>(d.snapshot_step[k]);
        std::snprintf(name, sizeof name, "vorticity_%06lld", static_cast<long long>(row));
        std::fprintf(g, "set title '%s, N = %zu, %s, dt = %g: t = %.6g (step %lld)' noenhanced\n",
                     o.scene.c_str(), N, method.c_str(), dt, d.snapshot_time[k], static_cast<long long>(row));
        for (const auto &terminal : terminals)
            std::fprintf(g,
                         "set terminal %s\nset output '%s/%s.%s'\n"
                         "plot '%s' binary array=(%zu,%zu) format='%%float64' endian=little skip=%llu "
                         "transpose dx=%.17g dy=%.17g origin=(0,0) with image\n",
                         terminal[0], o.out_dir.c_str(), name, terminal[1], bytes.file.c_str(), N, N,
                         static_cast<unsigned long long>(bytes.offset + 8 * k * N * N), 1.0 / N, 1.0 / N);
    }
    std::fprintf(g, "set output\n");
    std::fclose(g);
    if (std::system(("gnuplot '" + script + "' 2>/dev/null").c_str()) != 0) return 0;
    return shots;
}

}  // namespace

int run_command(int argc, char **argv) {
    RunOptions o;
    parse(argc, argv, o);
    std::vector<double> init_grid;
    if (!o.init.empty()) {
        int N = o.n_given ? o.scene_options.sine_euler_n : 0;
        init_grid = initial_grid(o.init, &N);
        o.scene_options.sine_euler_n = N;
    }
    const std::vector<Scene> all = builtin_scenes(o.scene_options);
    auto it = std::find_if(all.begin(), all.end(), [&](const Scene &s) { return s.name == o.scene; });
    if (it == all.end()) {
        std::fprintf(stderr, "lpi run: unknown scene '%s' (lpi --help lists them)\n", o.scene.c_str());
        return 2;
    }
    if (!it->create) {
        std::fprintf(stderr, "lpi run: %s is a report (lpi report %s)\n", o.scene.c_str(), o.scene.c_str());
        return 2;
    }
    const std::string why_not = it->unavailable();
    if (!why_not.empty()) {
        std::fprintf(stderr, "lpi run: %s is not available in this build: %s\n", o.scene.c_str(),
                     why_not.c_str());
        return 1;
    }
    const double dt = o.dt > 0.0 ? o.dt : it->run_step;
    Handle h = it->create();
    if (!init_grid.empty()) {
        int32_t N = 0;
        if (lpi_sine_euler_size(h.get(), &N) != LPI_OK) {
            std::fprintf(stderr, "lpi run: --init: %s is not a sine-Euler scene\n", o.scene.c_str());
            return 2;
        }
        if (static_cast<std::size_t>(N) * N != init_grid.size()) {
            std::fprintf(stderr, "lpi run: --init: %s has N = %d, the grid is not %d x %d\n", o.scene.c_str(), N,
                         N, N);
            return 2;
        }
        check_option(lpi_sine_euler_set_grid(h.get(), init_grid.data(), init_grid.size()), h.get(), "--init");
    }
    if (!o.resume.empty()) {
        Handle loaded;
        if (lpi_load(loaded.out(), o.resume.c_str()) != LPI_OK) {
            std::fprintf(stderr, "lpi run: --resume: %s\n", lpi_last_error(nullptr));
            return 1;
        }
        const std::string why = mismatch(h.get(), loaded.get());
        if (!why.empty()) {
            std::fprintf(stderr, "lpi run: --resume: %s is not a checkpoint of this scene: %s\n",
                         o.resume.c_str(), why.c_str());
            return 2;
        }
        h = std::move(loaded);
    }
    lpi_system *sys = h.get();
    if (!o.method.empty()) check_option(lpi_set_method(sys, o.method.c_str()), sys, "--method");
    if (o.threads != 1) check_option(lpi_set_threads(sys, o.threads), sys, "--threads");
    const std::string method = !o.method.empty()     ? o.method
                               : o.resume.empty()    ? "leapfrog"
                                                     : earlier_method(o);

    // Steps are counted from the start of the whole run, and the lpi_step
    // calls (one per row) end at the multiples of `every` and at the end: an
    // interrupted run resumed with the same options makes the very same
    // calls, so it ends bit for bit where the uninterrupted run ends.
    int64_t start = 0;
    if (!whole_steps(lpi_time(sys), dt, start)) {
        std::fprintf(stderr, "lpi run: --resume: the checkpoint's time %.17g is not a whole number of "
                             "steps of %g (resume with the run's --dt)\n", lpi_time(sys), dt);
        return 2;
    }
    int64_t end = o.steps;
    if (end == 0) {
        const double steps = (o.until > 0.0 ? o.until : it->final_time) / dt;
        if (!(steps < 0x1p62)) {
            std::fprintf(stderr, "lpi run: --until / --dt is too many steps (%g)\n", steps);
            return 2;
        }
        end = std::llround(steps);
        if (end < 1) {
            std::fprintf(stderr, "lpi run: --until %g with --dt %g is less than one step\n",
                         o.until > 0.0 ? o.until : it->final_time, dt);
            return 2;
        }
    }
    if (end < start) {
        std::fprintf(stderr, "lpi run: the checkpoint is at step %lld, past the run's end at step %lld\n",
                     static_cast<long long>(start), static_cast<long long>(end));
        return 2;
    }
    const int64_t every = o.every > 0 ? o.every : std::max<int64_t>(1, end / 100);
    // Row r is written after step min(r * every, end).
    auto row_index = [&](int64_t step) { return step / every + (step % every != 0); };
    RunData data;
    int32_t N = 0;
    data.vorticity = lpi_sine_euler_size(sys, &N) == LPI_OK;
    data.snapshot_shape = data.vorticity ? std::vector<std::size_t>{static_cast<std::size_t>(N),
                                                                    static_cast<std::size_t>(N)}
                                         : std::vector<std::size_t>{lpi_dim(sys)};
    data.casimir_count = lpi_casimir_count(sys);

    mkdir(o.out_dir.c_str(), 0777);
    const std::string csv = o.out_dir + "/" + o.scene + ".csv";
    std::vector<std::string> kept;
    if (!o.resume.empty()) {
        double csv_h0 = std::nan("");
        kept = csv_up_to(csv, start, csv_h0);
        if (kept.empty())
            std::printf("%s has no row at step %lld: a new file, energy error relative to step %lld\n",
                        csv.c_str(), static_cast<long long>(start), static_cast<long long>(start));
    }
    // The references of the errors and drifts: the step-0 row of the CSV
    // when resuming (to the bit: written with 17 digits), else this state.
    double H0 = energy_of(sys);
    std::vector<double> C0 = casimirs_of(sys);
    const bool spectrum = data.vorticity;
    auto add_row = [&](int64_t step, double time, double H, const std::vector<double> &c) {
        data.step.push_back(static_cast<double>(step));
        data.time.push_back(time);
        data.energy.push_back(H);
        data.energy_error.push_back((H - H0) / std::fabs(H0));
        data.casimirs.insert(data.casimirs.end(), c.begin(), c.end());
        data.casimir_drift.push_back(casimir_drift(spectrum, c, C0));
    };
    for (std::size_t i = 1; i < kept.size(); ++i) {
        std::vector<double> fields;
        for (const char *p = kept[i].c_str();; ++p) {
            char *next = nullptr;
            fields.push_back(std::strtod(p, &next));
            p = std::strchr(next, ',');
            if (!p) break;
        }
        if (fields.size() != 4 + data.casimir_count) continue;
        const std::vector<double> c(fields.begin() + 4, fields.end());
        if (fields[0] == 0.0) H0 = fields[2], C0 = c;
        add_row(static_cast<int64_t>(fields[0]), fields[1], fields[2], c);
    }
    if (!o.resume.empty()) keep_snapshots(o, start, data);

    FILE *f = std::fopen(csv.c_str(), "w");
    if (!f) {
        std::fprintf(stderr, "lpi run: cannot write %s: %s\n", csv.c_str(), std::strerror(errno));
        return 1;
    }
    if (kept.empty()) {
        std::fprintf(f, "step,time,energy,energy_error");
        for (std::size_t i = 0; i < data.casimir_count; ++i) std::fprintf(f, ",casimir_%zu", i);
        std::fprintf(f, "\n");
    }
    for (const std::string &line : kept) std::fprintf(f, "%s\n", line.c_str());
    // Flushed row by row: a killed run leaves complete rows.
    auto row = [&](int64_t step) {
        const double H = energy_of(sys);
        const std::vector<double> c = casimirs_of(sys);
        add_row(step, lpi_time(sys), H, c);
        std::fprintf(f, "%lld,%.17g,%.17g,%.6e", static_cast<long long>(step), lpi_time(sys), H,
                     data.energy_error.back());
        for (double v : c) std::fprintf(f, ",%.17g", v);
        std::fprintf(f, "\n");
        std::fflush(f);
    };
    auto snapshot = [&](int64_t step) {
        if (o.snapshot_every <= 0 || row_index(step) % o.snapshot_every != 0) return;
        const std::size_t size = data.snapshot_size(), at = data.snapshots.size();
        data.snapshots.resize(at + size);
        if (data.vorticity)
            check(lpi_sine_euler_get_grid(sys, &data.snapshots[at], size), sys, "get grid");
        else
            check(lpi_get_state(sys, &data.snapshots[at], size), sys, "get state");
        data.snapshot_step.push_back(static_cast<double>(step));
        data.snapshot_time.push_back(lpi_time(sys));
    };
    // A checkpoint that cannot be written stops the run: going on would lose it.
    auto save_checkpoint = [&](const lpi_system *state, int64_t step) {
        if (lpi_save(state, o.checkpoint.c_str()) == LPI_OK) return;
        std::fprintf(stderr, "lpi run: checkpoint not written at step %lld: %s\n",
                     static_cast<long long>(step), lpi_last_error(state));
        std::exit(1);
    };
    auto save = [&](int64_t step, bool always) {
        if (o.checkpoint.empty()) return;
        if (!always && (o.checkpoint_every <= 0 || row_index(step) % o.checkpoint_every != 0)) return;
        save_checkpoint(sys, step);
    };
    const std::vector<Attribute> attributes = {
        {"scene", o.scene, 0.0, true},
        {"method", method, 0.0, true},
        {"dt", "", dt, false},
        {"every", "", static_cast<double>(every), false, true},
        {"snapshot_every", "", static_cast<double>(o.snapshot_every), false, true},
        {"N", "", static_cast<double>(N), false, true},
        {"lpi_version", lpi_version_string(), 0.0, true},
        {"description", it->description, 0.0, true},
    };
    SnapshotBytes bytes;
    auto keep_data = [&] {
        const std::string why = write_data(o, data, attributes, bytes);
        if (why.empty()) return true;
        std::fprintf(stderr, "lpi run: the data %s was not written: %s\n", data_path(o).c_str(), why.c_str());
        return false;
    };

    std::printf("lpi run %s: steps %lld to %lld of %g with %s, output every %lld steps\n", o.scene.c_str(),
                static_cast<long long>(start), static_cast<long long>(end), dt, method.c_str(),
                static_cast<long long>(every));
    std::fflush(stdout);
    // Caught before the first row: once it is written, a signal stops the run
    // cleanly (before the first step, if it comes that early).
    catch_interrupts();
    save(start, true);
    if (kept.empty()) row(start);
    if (o.resume.empty()) snapshot(0);
    Progress progress(start, end);
    Watch watch;
    watch.progress = &progress;
    check(lpi_set_observer(sys, observation_interval(sys), watch_steps, &watch), sys, "set observer");
    // An interrupted call leaves the state at its stop, between two rows: a
    // run resumed from there would split that call in two, and no longer
    // merge the flows at the seam as the uninterrupted run does. So the
    // checkpoint written then is that of the call's start, held in memory.
    std::vector<unsigned char> call_start_checkpoint;
    const double t0 = cpu_seconds();
    int64_t done = start;
    bool stopped_between_rows = false;
    while (done < end && !interrupted_by) {
        const int64_t next = std::min(end, (done / every + 1) * every);
        if (!o.checkpoint.empty()) {
            std::size_t size = 0;
            check(lpi_save_buffer(sys, nullptr, 0, &size), sys, "checkpoint size");
            call_start_checkpoint.resize(size);
            check(lpi_save_buffer(sys, call_start_checkpoint.data(), size, &size), sys, "checkpoint");
        }
        watch.call_start = done;
        int status = lpi_step(sys, dt, next - done);
        if (status == LPI_STOPPED && watch.stopped_at < next) {
            stopped_between_rows = true;
            row(watch.stopped_at);
            break;
        }
        if (status == LPI_STOPPED) status = LPI_OK;  // stopped after the call's last step: it is whole
        if (status != LPI_OK) {
            progress.finish();
            std::fclose(f);
            std::fprintf(stderr, "lpi run: steps %lld to %lld failed: %s (%s); the state at step %lld is "
                                 "the last row of %s\n",
                         static_cast<long long>(done), static_cast<long long>(next), lpi_last_error(sys),
                         lpi_status_name(status), static_cast<long long>(done), csv.c_str());
            keep_data();
            return 1;
        }
        done = next;
        row(done);
        snapshot(done);
        save(done, false);
        progress.update(done);
    }
    progress.finish();
    if (stopped_between_rows && !o.checkpoint.empty()) {
        Handle at_call_start;
        check(lpi_load_buffer(at_call_start.out(), call_start_checkpoint.data(), call_start_checkpoint.size()),
              nullptr, "checkpoint");
        save_checkpoint(at_call_start.get(), done);
    } else {
        save(done, true);
    }
    if (std::ferror(f) != 0 || std::fclose(f) != 0) {
        std::fprintf(stderr, "lpi run: writing %s failed\n", csv.c_str());
        return 1;
    }
    if (!keep_data()) return 1;
    const double H = energy_of(sys);
    if (interrupted_by) {
        const int64_t stop = stopped_between_rows ? watch.stopped_at : done;
        std::printf("interrupted at step %lld (t = %.17g)", static_cast<long long>(stop), lpi_time(sys));
        if (!o.checkpoint.empty())
            std::printf("; %s holds step %lld (the last row on the --every grid): the same command with "
                        "--resume %s continues it",
                        o.checkpoint.c_str(), static_cast<long long>(done), o.checkpoint.c_str());
        std::printf("\n");
        return 128 + interrupted_by;
    }
    if (!o.checkpoint.empty()) std::printf("checkpoint: %s\n", o.checkpoint.c_str());
    std::printf("done: t = %g, %.3f CPU seconds, relative energy error %.3e; wrote %s and %s\n", lpi_time(sys),
                cpu_seconds() - t0, (H - H0) / std::fabs(H0), csv.c_str(), data_path(o).c_str());

    if (data.vorticity && !data.snapshot_step.empty()) {
        if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
            std::printf("gnuplot not found: no vorticity images (the snapshots are in %s)\n",
                        data_path(o).c_str());
            return 0;
        }
        const std::size_t drawn = plot_vorticity(o, data, bytes, dt, method);
        if (drawn > 0)
            std::printf("wrote %zu vorticity snapshots: %s/vorticity_*.png and .svg\n", drawn, o.out_dir.c_str());
        else
            std::printf("gnuplot failed: see %s/vorticity.gp\n", o.out_dir.c_str());
    }
    return 0;
}

}  // namespace lpi_cli
