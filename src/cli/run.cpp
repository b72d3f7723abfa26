#include "run.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

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
    int64_t snapshot_every = 10;  // sine-Euler: a PNG every this many output rows (0: none)
    std::string out_dir = "lpi-run";
    std::string checkpoint;    // save here at the start, every checkpoint_every rows and at the end
    int64_t checkpoint_every = 10;
    std::string resume;        // continue from this checkpoint
    SceneOptions scene_options;
};

void run_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi run SCENE [options]\n"
                 "  integrate SCENE (lpi --help lists them) and write diagnostics\n"
                 "  --method NAME     integration method (default leapfrog; lpi methods lists them)\n"
                 "  --dt H            step size (default 0.01; figure2: 0.05)\n"
                 "  --steps N         number of steps, or\n"
                 "  --until T         end time (default: the scene's final time)\n"
                 "  --every K         write a row every K steps (default: about 100 rows)\n"
                 "  --threads N       threads inside a step (sine-Euler; default 1)\n"
                 "  --N N             sine-Euler size (odd >= 3, default 31)\n"
                 "  --inertia A,B,C   rigid-body inertias (default 1,2,3)\n"
                 "  --snapshots K     sine-Euler: a vorticity PNG every K rows (default 10; 0: none)\n"
                 "  --out DIR         output directory (default ./lpi-run)\n"
                 "  --checkpoint FILE save a checkpoint (atomically) at the start, every 10 rows\n"
                 "                    and at the end; a failed save stops the run (exit status 1)\n"
                 "  --checkpoint-every K   ... every K rows instead (0: at the start and end only)\n"
                 "  --resume FILE     continue an interrupted run from its checkpoint, with the\n"
                 "                    options of that run: it ends bit for bit where the run\n"
                 "                    would have ended (--steps and --until count from the start\n"
                 "                    of the whole run; the rows after the checkpoint's step in\n"
                 "                    DIR/SCENE.csv are replaced)\n"
                 "  writes DIR/SCENE.csv: step, time, energy, relative energy error (to the energy\n"
                 "  at step 0), Casimirs; a progress bar with the time left is shown on a terminal\n"
                 "  only. Ctrl-C (SIGINT) or SIGTERM finishes the current row's steps, writes the\n"
                 "  row and the checkpoint, and exits with status 130 (143).\n");
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
}

// Set by SIGINT or SIGTERM; the stepping loop stops at the end of its chunk.
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

// A progress bar with the time left, on stderr, only when it is a terminal.
class Progress {
public:
    explicit Progress(int64_t total) : total_(total), enabled_(isatty(STDERR_FILENO) == 1) {}
    void update(int64_t done, double elapsed) {
        if (!enabled_ || elapsed - last_ < 0.1) return;
        last_ = elapsed;
        const double f = static_cast<double>(done) / static_cast<double>(total_);
        const int width = 40, filled = static_cast<int>(f * width);
        const double left = f > 0 ? elapsed * (1.0 - f) / f : 0.0;
        std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %.0f s left   ", filled,
                     "########################################", width - filled, "", 100.0 * f, left);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_) std::fprintf(stderr, "\r%*s\r", 70, "");
    }

private:
    int64_t total_;
    bool enabled_;
    double last_ = -1.0;
};

// Writes the grid as a whitespace matrix for gnuplot (rows: x index a).
bool write_grid(const std::string &path, const std::vector<double> &grid, int N) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    for (int b = 0; b < N; ++b) {
        for (int a = 0; a < N; ++a) std::fprintf(f, "%.6e ", grid[static_cast<std::size_t>(a) * N + b]);
        std::fprintf(f, "\n");
    }
    std::fclose(f);
    return true;
}

}  // namespace

int run_command(int argc, char **argv) {
    RunOptions o;
    parse(argc, argv, o);
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

    // Steps are counted from the start of the whole run, and the chunks
    // (lpi_step calls, one per row) end at the multiples of `every` and at the
    // end: an interrupted run resumed with the same options makes the very
    // same calls, so it ends bit for bit where the uninterrupted run ends.
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
    int32_t N = 0;
    const bool vorticity = lpi_sine_euler_size(sys, &N) == LPI_OK;

    mkdir(o.out_dir.c_str(), 0777);
    const std::string csv = o.out_dir + "/" + o.scene + ".csv";
    double H0 = energy_of(sys);
    std::vector<std::string> kept;
    if (!o.resume.empty()) {
        double csv_h0 = std::nan("");
        kept = csv_up_to(csv, start, csv_h0);
        if (kept.empty())
            std::printf("%s has no row at step %lld: a new file, energy error relative to step %lld\n",
                        csv.c_str(), static_cast<long long>(start), static_cast<long long>(start));
        else if (!std::isnan(csv_h0))
            H0 = csv_h0;
    }
    FILE *f = std::fopen(csv.c_str(), "w");
    if (!f) {
        std::fprintf(stderr, "lpi run: cannot write %s: %s\n", csv.c_str(), std::strerror(errno));
        return 1;
    }
    std::vector<double> c = casimirs_of(sys);
    if (kept.empty()) {
        std::fprintf(f, "step,time,energy,energy_error");
        for (std::size_t i = 0; i < c.size(); ++i) std::fprintf(f, ",casimir_%zu", i);
        std::fprintf(f, "\n");
    }
    for (const std::string &line : kept) std::fprintf(f, "%s\n", line.c_str());
    // Flushed row by row: a killed run leaves complete rows.
    auto row = [&](int64_t step) {
        const double H = energy_of(sys);
        c = casimirs_of(sys);
        std::fprintf(f, "%lld,%.17g,%.17g,%.6e", static_cast<long long>(step), lpi_time(sys), H,
                     (H - H0) / std::fabs(H0));
        for (double v : c) std::fprintf(f, ",%.17g", v);
        std::fprintf(f, "\n");
        std::fflush(f);
    };
    std::vector<std::string> snapshots;
    double vorticity_scale = 0.0;  // one symmetric colour range for every snapshot
    auto snapshot = [&](int64_t rows) {
        if (!vorticity || o.snapshot_every <= 0 || rows % o.snapshot_every != 0) return;
        std::vector<double> grid(static_cast<std::size_t>(N) * N);
        check(lpi_sine_euler_get_grid(sys, grid.data(), grid.size()), sys, "get grid");
        for (double v : grid) vorticity_scale = std::max(vorticity_scale, std::fabs(v));
        char name[64];
        std::snprintf(name, sizeof name, "vorticity_%06lld", static_cast<long long>(rows));
        if (write_grid(o.out_dir + "/" + name + ".dat", grid, N)) snapshots.push_back(name);
    };
    // A checkpoint that cannot be written stops the run: going on would lose it.
    auto save = [&](int64_t step, bool always) {
        if (o.checkpoint.empty()) return;
        if (!always && (o.checkpoint_every <= 0 || row_index(step) % o.checkpoint_every != 0)) return;
        if (lpi_save(sys, o.checkpoint.c_str()) == LPI_OK) return;
        std::fprintf(stderr, "lpi run: checkpoint not written at step %lld: %s\n",
                     static_cast<long long>(step), lpi_last_error(sys));
        std::exit(1);
    };

    std::printf("lpi run %s: steps %lld to %lld of %g with %s, output every %lld steps\n", o.scene.c_str(),
                static_cast<long long>(start), static_cast<long long>(end), dt,
                o.method.empty() ? (o.resume.empty() ? "leapfrog" : "the checkpoint's method") : o.method.c_str(),
                static_cast<long long>(every));
    std::fflush(stdout);
    save(start, true);
    if (kept.empty()) row(start);
    if (o.resume.empty()) snapshot(0);
    catch_interrupts();
    Progress progress(end - start);
    const double t0 = cpu_seconds();
    int64_t done = start;
    while (done < end && !interrupted_by) {
        const int64_t next = std::min(end, (done / every + 1) * every);
        const int status = lpi_step(sys, dt, next - done);
        if (status != LPI_OK) {
            progress.finish();
            std::fclose(f);
            std::fprintf(stderr, "lpi run: steps %lld to %lld failed: %s (%s); the state at step %lld is "
                                 "the last row of %s\n",
                         static_cast<long long>(done), static_cast<long long>(next), lpi_last_error(sys),
                         lpi_status_name(status), static_cast<long long>(done), csv.c_str());
            return 1;
        }
        done = next;
        row(done);
        snapshot(row_index(done));
        save(done, false);
        progress.update(done - start, cpu_seconds() - t0);
    }
    progress.finish();
    save(done, true);
    if (std::ferror(f) != 0 || std::fclose(f) != 0) {
        std::fprintf(stderr, "lpi run: writing %s failed\n", csv.c_str());
        return 1;
    }
    const double H = energy_of(sys);
    if (interrupted_by) {
        std::printf("interrupted at step %lld (t = %.17g)", static_cast<long long>(done), lpi_time(sys));
        if (!o.checkpoint.empty())
            std::printf("; the same command with --resume %s continues it", o.checkpoint.c_str());
        std::printf("\n");
        return 128 + interrupted_by;
    }
    if (!o.checkpoint.empty()) std::printf("checkpoint: %s\n", o.checkpoint.c_str());
    std::printf("done: t = %g, %.3f CPU seconds, relative energy error %.3e; wrote %s\n", lpi_time(sys),
                cpu_seconds() - t0, (H - H0) / std::fabs(H0), csv.c_str());

    if (!snapshots.empty()) {
        if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
            std::printf("gnuplot not found: vorticity snapshots left as %s/vorticity_*.dat\n",
                        o.out_dir.c_str());
            return 0;
        }
        const std::string script = o.out_dir + "/vorticity.gp";
        FILE *g = std::fopen(script.c_str(), "w");
        if (!g) return 0;
        std::fprintf(g, "set terminal pngcairo size 640,600 noenhanced\nset size ratio -1\n"
                        "set palette defined (0 '#2166ac', 0.5 'white', 1 '#b2182b')\n"
                        "unset key\nset xrange [-0.5:%d.5]\nset yrange [-0.5:%d.5]\n"
                        "set cbrange [%g:%g]\n"
                        "set xlabel 'x = 2 pi a / N'\nset ylabel 'y = 2 pi b / N'\n",
                     N - 1, N - 1, -vorticity_scale, vorticity_scale);
        for (const std::string &s : snapshots)
            std::fprintf(g, "set output '%s/%s.png'\nset title '%s: vorticity (N = %d)'\n"
                            "plot '%s/%s.dat' matrix with image\n",
                         o.out_dir.c_str(), s.c_str(), s.c_str(), N, o.out_dir.c_str(), s.c_str());
        std::fclose(g);
        if (std::system(("gnuplot '" + script + "' 2>/dev/null").c_str()) == 0) {
            for (const std::string &s : snapshots) std::remove((o.out_dir + "/" + s + ".dat").c_str());
            std::printf("wrote %zu vorticity snapshots: %s/vorticity_*.png\n", snapshots.size(),
                        o.out_dir.c_str());
        }
    }
    return 0;
}

}  // namespace lpi_cli
