#include "run.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
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
    std::string method;       // empty: the system's default (leapfrog)
    double dt = 0.01;
    int64_t steps = -1;       // or...
    double until = -1.0;      // ...an end time
    int64_t every = 0;        // output interval in steps (0: about 100 rows)
    int threads = 1;
    int snapshot_every = 10;  // sine-Euler: a PNG every this many output rows (0: none)
    std::string out_dir = "lpi-run";
    std::string checkpoint;    // save here every checkpoint_every rows and at the end
    int checkpoint_every = 10;
    std::string resume;        // continue from this checkpoint
    SceneOptions scene_options;
};

void run_usage(FILE *to) {
    std::fprintf(to,
                 "usage: lpi run SCENE [options]\n"
                 "  integrate SCENE (lpi --help lists them) and write diagnostics\n"
                 "  --method NAME     integration method (default leapfrog; lpi methods lists them)\n"
                 "  --dt H            step size (default 0.01)\n"
                 "  --steps N         number of steps, or\n"
                 "  --until T         end time (default: the scene's final time)\n"
                 "  --every K         write a row every K steps (default: about 100 rows)\n"
                 "  --threads N       threads inside a step (sine-Euler; default 1)\n"
                 "  --N N             sine-Euler size (odd >= 3, default 31)\n"
                 "  --inertia A,B,C   rigid-body inertias (default 1,2,3)\n"
                 "  --snapshots K     sine-Euler: a vorticity PNG every K rows (default 10; 0: none)\n"
                 "  --out DIR         output directory (default ./lpi-run)\n"
                 "  --checkpoint FILE save a checkpoint (atomically) every 10 rows and at the end\n"
                 "  --checkpoint-every K   ... every K rows instead\n"
                 "  --resume FILE     continue from a checkpoint: the trajectory goes on bit for bit\n"
                 "                    (--until is then an absolute time, --steps a count of more\n"
                 "                    steps; rows are appended to DIR/SCENE.csv)\n"
                 "  writes DIR/SCENE.csv: step, time, energy, relative energy error (to the energy\n"
                 "  where this run starts), Casimirs;\n"
                 "  a progress bar with the time left is shown on a terminal only.\n");
}

bool parse(int argc, char **argv, RunOptions &o) {
    for (int a = 0; a < argc; ++a) {
        const std::string arg = argv[a];
        auto value = [&](const char *what) -> const char * {
            if (a + 1 >= argc) {
                std::fprintf(stderr, "lpi run: %s needs a value\n", what);
                std::exit(2);
            }
            return argv[++a];
        };
        char *end = nullptr;
        auto number = [&](const char *what) {
            const char *text = value(what);
            const double v = std::strtod(text, &end);
            if (end == text || *end != '\0' || !std::isfinite(v)) {
                std::fprintf(stderr, "lpi run: %s: '%s' is not a number\n", what, text);
                std::exit(2);
            }
            return v;
        };
        if (arg == "--method") o.method = value("--method");
        else if (arg == "--dt") o.dt = number("--dt");
        else if (arg == "--steps") o.steps = static_cast<int64_t>(number("--steps"));
        else if (arg == "--until") o.until = number("--until");
        else if (arg == "--every") o.every = static_cast<int64_t>(number("--every"));
        else if (arg == "--threads") o.threads = static_cast<int>(number("--threads"));
        else if (arg == "--N") o.scene_options.sine_euler_n = static_cast<int>(number("--N"));
        else if (arg == "--snapshots") o.snapshot_every = static_cast<int>(number("--snapshots"));
        else if (arg == "--out") o.out_dir = value("--out");
        else if (arg == "--checkpoint") o.checkpoint = value("--checkpoint");
        else if (arg == "--checkpoint-every") o.checkpoint_every = static_cast<int>(number("--checkpoint-every"));
        else if (arg == "--resume") o.resume = value("--resume");
        else if (arg == "--inertia") {
            const char *text = value("--inertia");
            double *I = o.scene_options.inertia;
            if (std::sscanf(text, "%lf,%lf,%lf", &I[0], &I[1], &I[2]) != 3) {
                std::fprintf(stderr, "lpi run: --inertia wants A,B,C, got '%s'\n", text);
                std::exit(2);
            }
        } else if (arg == "--help" || arg == "-h") {
            run_usage(stdout);
            std::exit(0);
        } else if (arg[0] == '-') {
            std::fprintf(stderr, "lpi run: unknown option '%s'\n", arg.c_str());
            return false;
        } else if (o.scene.empty()) {
            o.scene = arg;
        } else {
            std::fprintf(stderr, "lpi run: one scene only ('%s' and '%s')\n", o.scene.c_str(), arg.c_str());
            return false;
        }
    }
    if (o.scene.empty()) {
        std::fprintf(stderr, "lpi run: which scene?\n");
        return false;
    }
    return true;
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
    if (!parse(argc, argv, o)) {
        run_usage(stderr);
        return 2;
    }
    const std::vector<Scene> all = builtin_scenes(o.scene_options);
    auto it = std::find_if(all.begin(), all.end(), [&](const Scene &s) { return s.name == o.scene; });
    if (it == all.end() || it->custom_run) {
        std::fprintf(stderr, "lpi run: unknown scene '%s' (lpi --help lists them)\n", o.scene.c_str());
        return 2;
    }
    const std::string why_not = it->unavailable();
    if (!why_not.empty()) {
        std::fprintf(stderr, "lpi run: %s is not available in this build: %s\n", o.scene.c_str(),
                     why_not.c_str());
        return 1;
    }
    Handle h;
    if (o.resume.empty()) {
        h = it->create();
    } else if (lpi_load(h.out(), o.resume.c_str()) != LPI_OK) {
        std::fprintf(stderr, "lpi run: --resume: %s\n", lpi_last_error(nullptr));
        return 1;
    }
    lpi_system *sys = h.get();
    if (!o.method.empty()) check(lpi_set_method(sys, o.method.c_str()), sys, "--method");
    if (o.threads != 1) check(lpi_set_threads(sys, o.threads), sys, "--threads");
    const double until = o.until > 0 ? o.until : it->final_time;
    const int64_t total =
        o.steps >= 0 ? o.steps : std::max<int64_t>(0, std::llround((until - lpi_time(sys)) / o.dt));
    const int64_t every = o.every > 0 ? o.every : std::max<int64_t>(1, total / 100);
    int32_t N = 0;
    const bool vorticity = lpi_sine_euler_size(sys, &N) == LPI_OK;

    mkdir(o.out_dir.c_str(), 0777);
    const std::string csv = o.out_dir + "/" + o.scene + ".csv";
    const bool append = !o.resume.empty() && access(csv.c_str(), F_OK) == 0;
    FILE *f = std::fopen(csv.c_str(), append ? "a" : "w");
    if (!f) {
        std::fprintf(stderr, "lpi run: cannot write %s\n", csv.c_str());
        return 1;
    }
    // On --resume the step column continues from the saved time; the energy
    // error is relative to the energy where this run starts.
    const int64_t first_step = std::llround(lpi_time(sys) / o.dt);
    const double H0 = energy_of(sys);
    std::vector<double> c = casimirs_of(sys);
    if (!append) {
        std::fprintf(f, "step,time,energy,energy_error");
        for (std::size_t i = 0; i < c.size(); ++i) std::fprintf(f, ",casimir_%zu", i);
        std::fprintf(f, "\n");
    }
    auto row = [&](int64_t step) {
        const double H = energy_of(sys);
        c = casimirs_of(sys);
        std::fprintf(f, "%lld,%.17g,%.17g,%.6e", static_cast<long long>(first_step + step), lpi_time(sys), H,
                     (H - H0) / std::fabs(H0));
        for (double v : c) std::fprintf(f, ",%.17g", v);
        std::fprintf(f, "\n");
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

    std::printf("lpi run %s: %lld steps of %g with %s, output every %lld steps\n", o.scene.c_str(),
                static_cast<long long>(total), o.dt, o.method.empty() ? "leapfrog" : o.method.c_str(),
                static_cast<long long>(every));
    int64_t rows = 0;
    auto save = [&](bool last) {
        if (o.checkpoint.empty()) return;
        if (!last && (o.checkpoint_every <= 0 || rows % o.checkpoint_every != 0)) return;
        const int status = lpi_save(sys, o.checkpoint.c_str());
        if (status != LPI_OK)
            std::fprintf(stderr, "\nlpi run: checkpoint not written: %s\n", lpi_last_error(sys));
    };
    Progress progress(total);
    if (!append) row(0);
    snapshot(0);
    const double t0 = cpu_seconds();
    int64_t done = 0;
    while (done < total) {
        const int64_t n = std::min(every, total - done);
        const int status = lpi_step(sys, o.dt, n);
        if (status != LPI_OK) {
            progress.finish();
            std::fclose(f);
            std::fprintf(stderr, "lpi run: step %lld failed: %s (%s); the state at step %lld is kept in %s\n",
                         static_cast<long long>(done), lpi_last_error(sys), lpi_status_name(status),
                         static_cast<long long>(done), csv.c_str());
            return 1;
        }
        done += n;
        row(done);
        snapshot(++rows);
        save(false);
        progress.update(done, cpu_seconds() - t0);
    }
    progress.finish();
    std::fclose(f);
    save(true);
    if (!o.checkpoint.empty()) std::printf("checkpoint: %s\n", o.checkpoint.c_str());
    const double H = energy_of(sys);
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
