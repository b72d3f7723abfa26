// `lpi run`: the stepping loop. Rows of the CSV at every --every steps,
// snapshots and checkpoints on that grid, a resumed run continued bit for bit,
// Ctrl-C honoured within a few steps (run_watch), the data written at the end
// (run_data).
#include "run.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../core/headroom.hpp"
#include "output.hpp"
#include "plots.hpp"
#include "processes.hpp"
#include "run_data.hpp"
#include "run_options.hpp"
#include "run_watch.hpp"
#include "scenes.hpp"

namespace lpi_cli {

namespace {

// Stops the command, naming the option, when the library refused it on any
// process: a usage error (exit status 2), or with `exit_status` 1 a file it
// names that could not be read or written. Collective (agreed_failure): a
// refusal may be one process's (--threads beyond its CPUs, a wisdom file).
void check_option(int status, const lpi_system *sys, const char *option, int exit_status = 2) {
    const std::string why = status == LPI_OK ? ""
                                             : format("lpi run: %s: %s (%s)", option, lpi_last_error(sys),
                                                      lpi_status_name(status));
    if (const int agreed = agreed_failure(status == LPI_OK ? 0 : exit_status, why)) std::exit(agreed);
}

// Whether `loaded` is a state of the system `fresh` (the scene with these
// options): same kind, size and Hamiltonian. The Hamiltonians are compared by
// their energies at the loaded state and at three more states of its size and
// scale, drawn from a fixed seed: at one state alone, a parameter whose terms
// vanish or cancel there went unnoticed (--inertia 1,2,3 against 1,2,4 at m3
// = 0, or against 2,1,3 at m1 = m2), and the run went on with another
// Hamiltonian under the rows of the first.
std::string mismatch(lpi_system *fresh, const lpi_system *loaded) {
    if (std::strcmp(lpi_kind(fresh), lpi_kind(loaded)) != 0) return "it holds another kind of system";
    int32_t n_fresh = 0, n_loaded = 0;
    if (lpi_sine_euler_size(fresh, &n_fresh) == LPI_OK && lpi_sine_euler_size(loaded, &n_loaded) == LPI_OK &&
        n_fresh != n_loaded)
        return "it has N = " + std::to_string(n_loaded) + ", not " + std::to_string(n_fresh);
    if (lpi_dim(fresh) != lpi_dim(loaded) || lpi_casimir_count(fresh) != lpi_casimir_count(loaded))
        return "its system has another dimension";
    // A copy of the loaded system takes the other states (the loaded one
    // goes on from its own).
    std::size_t size = 0;
    check(lpi_save_buffer(loaded, nullptr, 0, &size), loaded, "checkpoint size");
    std::vector<unsigned char> bytes(size);
    check(lpi_save_buffer(loaded, bytes.data(), bytes.size(), &size), loaded, "checkpoint");
    Handle copy;
    check(lpi_load_buffer(copy.out(), bytes.data(), size), nullptr, "checkpoint copy");
    std::vector<double> x = state_of(loaded);
    double sum_of_squares = 0.0;
    for (double v : x) sum_of_squares += v * v;
    const double scale = sum_of_squares > 0.0 && std::isfinite(sum_of_squares)
                             ? std::sqrt(sum_of_squares / static_cast<double>(x.size()))
                             : 1.0;
    std::uint64_t seed = 2026;
    for (int probe = 0; probe < 4; ++probe) {
        if (probe > 0)
            for (double &v : x) v = scale * (2.0 * uniform_random(seed) - 1.0);
        check(lpi_set_state(fresh, x.data(), x.size()), fresh, "set state");
        check(lpi_set_state(copy.get(), x.data(), x.size()), copy.get(), "set state");
        double h_fresh = 0.0, h_loaded = 0.0;
        if (probe == 0) {
            h_fresh = energy_of(fresh);
            h_loaded = energy_of(copy.get());
        } else if (lpi_energy(fresh, &h_fresh) != LPI_OK || lpi_energy(copy.get(), &h_loaded) != LPI_OK) {
            continue;  // an energy beyond a double there (a state near the range's end)
        }
        if (std::fabs(h_fresh - h_loaded) > 1e-12 * std::max(std::fabs(h_fresh), std::fabs(h_loaded)))
            return "its Hamiltonian differs (other parameters, such as --inertia)";
    }
    return "";
}

// The step index a time is, to the rounding of the time's sum (compensated
// in the library: an ulp or so): a resumed run's start. A looser margin let
// a --dt 1e-11 off the interrupted run's resume, splicing two step sizes.
bool whole_steps(double time, double dt, int64_t &steps) {
    const double s = time / dt;
    if (!(s >= 0.0 && s < 0x1p62)) return false;
    steps = std::llround(s);
    return std::fabs(s - static_cast<double>(steps)) <= 8 * DBL_EPSILON * std::max(1.0, s);
}

// `v` in the fewest digits that read back as `v`.
std::string exact(double v) {
    for (int digits = 1;; ++digits) {
        const std::string text = format("%.*g", digits, v);
        if (digits >= 17 || std::strtod(text.c_str(), nullptr) == v) return text;
    }
}

// The CSV of an interrupted run, read back by the rules of the options
// (common.hpp): the header lpi run writes for `casimir_count` Casimirs, then
// rows of as many fields, each a complete finite decimal number, the steps
// whole, increasing and below 2^62. Its rows up to and including that of
// `step` (whether it has one is the caller's to check); none when the file
// is absent or has no rows; a last line cut short is left when it follows
// the row at `step`. `why` says what is wrong with a file that is there
// ("PATH:LINE: ..."): a value read wrongly would be the reference of every
// energy error after it.
std::vector<KeptRow> csv_up_to(const std::string &path, int64_t step, std::size_t casimir_count, std::string &why) {
    std::vector<KeptRow> rows;
    struct stat st;
    if (stat(path.c_str(), &st) != 0 && errno == ENOENT) return rows;
    std::string text;
    why = read_input(path, text);  // a regular file only: a FIFO is refused, not waited on
    if (!why.empty()) return rows;
    std::string columns;
    for (std::size_t i = 0; i < casimir_count; ++i) columns += format(",casimir_%zu", i);
    bool found = false;
    std::size_t line_number = 0;
    auto bad = [&](const std::string &what) {
        why = format("%s:%zu: %s", path.c_str(), line_number, what.c_str());
        rows.clear();
        return rows;
    };
    for (std::size_t from = 0; from < text.size();) {
        ++line_number;
        const std::size_t end = text.find('\n', from);
        // A last line cut short after the checkpoint's row is the tail of a
        // growth (output.hpp) that a kill stopped: replaced with the rows after.
        if (end == std::string::npos && found) break;
        if (end == std::string::npos) return bad("the line is cut short (no line end)");
        const std::string line = text.substr(from, end - from);
        from = end + 1;
        if (line_number == 1) {
            if (line != "step,time,energy,energy_error" + columns &&
                line != "step,time,energy,absolute_energy_error" + columns)
                return bad("'" + line + "' is not the header lpi run writes for this scene");
            continue;
        }
        std::vector<std::string> fields;
        for (std::size_t at = 0;;) {
            const std::size_t comma = line.find(',', at);
            fields.push_back(line.substr(at, comma - at));
            if (comma == std::string::npos) break;
            at = comma + 1;
        }
        if (fields.size() != 4 + casimir_count)
            return bad(format("%zu fields, not %zu", fields.size(), 4 + casimir_count));
        KeptRow row;
        std::string wrong = whole_problem(fields[0], 0, kMaxSteps, row.step);
        if (!wrong.empty()) return bad("step: " + wrong);
        if (!rows.empty() && row.step <= rows.back().step) return bad("the steps do not increase");
        std::vector<double> values(fields.size());
        for (std::size_t i = 1; i < fields.size(); ++i) {
            wrong = decimal_problem(fields[i], values[i]);
            if (!wrong.empty()) return bad("field " + std::to_string(i + 1) + ": " + wrong);
        }
        if (row.step > step) continue;  // replaced by this run; still checked
        row.time = values[1];
        row.energy = values[2];
        row.casimirs.assign(values.begin() + 4, values.end());
        found = row.step == step;
        rows.push_back(std::move(row));
    }
    if (line_number == 0) return bad("the file is empty");
    return rows;
}

// The most characters the CSV of `rows` rows takes: a field of %.17g is at
// most 24 (sign, 17 digits, point, exponent), and its comma; the header.
std::size_t csv_text_size(std::size_t rows, std::size_t casimir_count) {
    return 64 + 16 * casimir_count + rows * 25 * (4 + casimir_count);
}

// A path as the file system resolves it: the real path of the file, or of
// the nearest directory above it that exists, and the rest of the name with
// its empty and "." parts dropped and ".." taken back a part ("b//c/", "b/./c"
// and "b/x/../c" are "b/c" where b/c does not exist yet: what a file created
// there will be).
std::string resolved(const std::string &path) {
    if (path.empty()) return resolved(".");
    if (char *real = realpath(path.c_str(), nullptr)) {
        const std::string r = real;
        std::free(real);
        return r;
    }
    std::size_t end = path.size();
    while (end > 1 && path[end - 1] == '/') --end;  // "b/" names b
    const std::size_t slash = path.find_last_of('/', end - 1);
    const std::string name = path.substr(slash == std::string::npos ? 0 : slash + 1,
                                         end - (slash == std::string::npos ? 0 : slash + 1));
    const std::string above = resolved(slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash));
    if (name.empty() || name == "/" || name == ".") return above;
    if (name == "..") {
        const std::size_t up = above.find_last_of('/');
        return up == 0 || up == std::string::npos ? "/" : above.substr(0, up);
    }
    return above == "/" ? "/" + name : above + "/" + name;
}

// Whether two paths name one file: the same file when both exist (links
// included), else the same resolved path.
bool same_file(const std::string &a, const std::string &b) {
    struct stat sa, sb;
    if (stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    return resolved(a) == resolved(b);
}

// Whether `path` lies inside the directory `dir` (which need not exist).
bool inside(const std::string &path, const std::string &dir) {
    const std::string d = resolved(dir) + "/";
    return resolved(path).compare(0, d.size(), d) == 0;
}

// The files a run writes and the options naming them, checked before
// anything is written: --checkpoint (and --wisdom, which measured planning
// writes) may be none of the run's outputs nor the --init grid, nor a folder
// the run keeps its data in (`output_dirs`) or a file in one, and the --init
// grid none of the outputs, for the run would overwrite one with the other.
// A usage error: "" or the message.
std::string colliding_paths(const RunOptions &o, const std::vector<std::string> &outputs,
                            const std::vector<std::string> &output_dirs) {
    struct Named {
        std::string option, path;
    };
    // Read before the run, but the data of the run that made it would be lost.
    if (!o.init.empty()) {
        for (const std::string &output : outputs)
            if (same_file(o.init, output))
                return "lpi run: --init " + o.init + " is " + output +
                       ", which this run writes: copy it, or give --out another directory";
        for (const std::string &dir : output_dirs)
            if (inside(o.init, dir))
                return "lpi run: --init " + o.init + " is in " + dir +
                       ", where this run writes its data: copy it, or give --out another directory";
    }
    std::vector<Named> written;
    if (!o.checkpoint.empty()) written.push_back({"--checkpoint", o.checkpoint});
    if (!o.wisdom.empty()) written.push_back({"--wisdom", o.wisdom});
    for (std::size_t i = 0; i < written.size(); ++i) {
        const Named &w = written[i];
        if (same_file(w.path, o.out_dir))
            return "lpi run: " + w.option + " " + w.path + " is the --out directory: give it another name";
        for (const std::string &output : outputs)
            if (same_file(w.path, output))
                return "lpi run: " + w.option + " " + w.path + " is " + output +
                       ", which this run writes: give it another name";
        for (const std::string &dir : output_dirs)
            if (same_file(w.path, dir) || inside(w.path, dir))
                return "lpi run: " + w.option + " " + w.path + (same_file(w.path, dir) ? " is " : " is in ") + dir +
                       ", the folder where this run writes its data: give it another name";
        // The snapshot images are named by the scene and their steps:
        // SCENE_vorticity_STEP.png and .svg.
        const std::size_t slash = w.path.find_last_of('/');
        const std::string name = slash == std::string::npos ? w.path : w.path.substr(slash + 1);
        const std::string dir = slash == std::string::npos ? "." : w.path.substr(0, std::max<std::size_t>(slash, 1));
        if (is_vorticity_image(o.scene, name) && same_file(dir, o.out_dir))
            return "lpi run: " + w.option + " " + w.path + " is a name of the snapshot images this run draws in " +
                   o.out_dir + ": give it another name";
        if (!o.init.empty() && same_file(w.path, o.init))
            return "lpi run: " + w.option + " " + w.path + " is the --init grid, which it would overwrite";
        for (std::size_t j = 0; j < i; ++j)
            if (same_file(w.path, written[j].path))
                return "lpi run: " + w.option + " and " + written[j].option + " name one file (" + w.path + ")";
    }
    return "";
}

}  // namespace

int run_command(int argc, char **argv) {
    RunOptions o;
    if (!parse_run_options(argc, argv, o)) return 0;  // --help
    const bool n_given = o.given.count("--N") > 0;
    std::vector<Scene> all = builtin_scenes(o.scene_options);
    auto find_scene = [&] {
        return std::find_if(all.begin(), all.end(), [&](const Scene &s) { return s.name == o.scene; });
    };
    auto it = find_scene();
    if (it == all.end()) {
        std::fprintf(stderr, "lpi run: unknown scene '%s' (lpi --help lists them)\n", o.scene.c_str());
        return 2;
    }
    refuse_options_not_taken(o, *it);
    std::vector<double> init_grid;
    if (!o.init.empty()) {
        // The grid's N is the scene's.
        int N = n_given ? o.scene_options.sine_euler_n : 0;
        std::string why;
        const int status = initial_grid(o.init, &N, init_grid, why);  // each process reads it
        if (const int agreed = agreed_failure(status, why)) return agreed;
        o.scene_options.sine_euler_n = N;
        all = builtin_scenes(o.scene_options);
        it = find_scene();
    }
    if (it->run_own) {
        const std::string why = it->unavailable();
        if (!why.empty()) {
            std::fprintf(stderr, "lpi run: %s is not available in this build: %s\n", o.scene.c_str(), why.c_str());
            return 1;
        }
        if (process_count() > 1) {
            std::fprintf(stderr, "lpi run: %s runs on one process (not under mpirun)\n", o.scene.c_str());
            return 2;
        }
        return it->run_own({n_given ? o.scene_options.sine_euler_n : 0, o.steps, o.dt, o.out_dir});
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
    double dt = o.dt > 0.0 ? o.dt : it->run_step;  // without --dt, resumed: maybe the interrupted run's
    Handle h = it->create();
    if (!init_grid.empty()) {
        int32_t N = 0;  // a scene that takes --init is sine-Euler (Scene::options)
        check(lpi_sine_euler_size(h.get(), &N), h.get(), "sine-Euler size");
        if (static_cast<std::size_t>(N) * N != init_grid.size()) {
            std::fprintf(stderr, "lpi run: --init: %s has N = %d, the grid is not %d x %d\n", o.scene.c_str(), N,
                         N, N);
            return 2;
        }
        check_option(lpi_sine_euler_set_grid(h.get(), init_grid.data(), init_grid.size()), h.get(), "--init");
    }
    // A system the library cannot save (moments: its pieces are callbacks)
    // can neither write a checkpoint nor have one to resume: refused before
    // anything runs or is written.
    if (!o.checkpoint.empty() || !o.resume.empty()) {
        std::size_t size = 0;
        if (lpi_save_buffer(h.get(), nullptr, 0, &size) == LPI_ERR_UNSUPPORTED) {
            std::fprintf(stderr, "lpi run: %s: %s cannot be checkpointed (%s)\n",
                         o.checkpoint.empty() ? "--resume" : "--checkpoint", o.scene.c_str(), lpi_last_error(h.get()));
            return 2;
        }
    }
    if (!o.resume.empty()) {
        Handle loaded;
        // Not spread (another kind), the checkpoint is read by each process.
        const bool failed = load_checkpoint(loaded.out(), o.resume.c_str()) != LPI_OK;
        const std::string no_load = failed ? std::string("lpi run: --resume: ") + lpi_last_error(nullptr) : "";
        if (const int agreed = agreed_failure(failed, no_load)) return agreed;
        const std::string why = mismatch(h.get(), loaded.get());
        if (!why.empty()) {
            std::fprintf(stderr, "lpi run: --resume: %s is not a checkpoint of this scene: %s\n",
                         o.resume.c_str(), why.c_str());
            return 2;
        }
        h = std::move(loaded);
    }
    lpi_system *sys = h.get();
    RunData data;
    int32_t N = 0;
    data.vorticity = lpi_sine_euler_size(sys, &N) == LPI_OK;
    data.snapshot_shape = data.vorticity ? std::vector<std::size_t>{static_cast<std::size_t>(N),
                                                                    static_cast<std::size_t>(N)}
                                         : std::vector<std::size_t>{lpi_dim(sys)};
    data.casimir_count = lpi_casimir_count(sys);
    if (data.vorticity && it->topography) data.topography = it->topography();
    const std::string csv = o.out_dir + "/" + o.scene + ".csv";
    // What this run writes (the vorticity images besides, SCENE_vorticity_STEP by their steps).
    std::vector<std::string> outputs = data_files(o, data);
    outputs.insert(outputs.begin(), csv);
    const std::string vorticity_script = o.out_dir + "/" + vorticity_script_name(o.scene);
    outputs.push_back(vorticity_script);
    const std::string collision = colliding_paths(o, outputs, data_folders(o));
    if (!collision.empty()) {
        std::fprintf(stderr, "%s\n", collision.c_str());
        return 2;
    }
    if (!o.method.empty()) {
        const std::string resumed = lpi_get_method(sys);
        check_option(lpi_set_method(sys, o.method.c_str()), sys, "--method");
        // The checkpoint holds the interrupted run's method (compared by the
        // name an alias resolves to): another would splice rows of two methods.
        if (!o.resume.empty() && resumed != lpi_get_method(sys)) {
            std::fprintf(stderr, "lpi run: --resume: --method %s, but %s holds a run of %s: resume with the "
                                 "options of the interrupted run\n",
                         o.method.c_str(), o.resume.c_str(), resumed.c_str());
            return 2;
        }
    }
    if (o.threads != 1) check_option(lpi_set_threads(sys, o.threads), sys, "--threads");
    // The method in use: --method's, else a new system's default or the
    // checkpoint's (it holds the method).
    const std::string method = lpi_get_method(sys);

    // The interrupted run's data, read back before this run's layout is
    // settled: it records the --dt, --every and --snapshots of that run,
    // which a resume takes where they are not given (and refuses where they
    // are given otherwise). A run extended with a larger --steps has another
    // default --every, and a scene's default step may not be the run's.
    DataRecord earlier;  // the interrupted run's data
    std::string dt_whose = o.given.count("--dt") ? "" : ", the scene's";  // where --dt comes from, if not given
    if (!o.resume.empty()) {
        std::string why;
        const int status = read_data_record(o, data, earlier, why);
        if (const int agreed = agreed_failure(status, why)) return agreed;
        // The data's --dt where it is another and the data is the run's: its
        // row at the checkpoint's step under that --dt holds the
        // checkpoint's time, to the bit (the attribute is the double the run
        // stepped with). Without --dt, it is taken (the scene's step is no
        // choice of the user's); another --dt given is refused.
        const Attribute *recorded = earlier.attribute("dt"), *scene = earlier.attribute("scene");
        int64_t at = 0;
        std::vector<KeptRow> rows;
        std::string unread;  // the data's rows up to `at` are read again, and checked, below
        const bool recorded_fits =
            recorded && (!scene || scene->text == o.scene) && recorded->number > 0.0 &&
            std::isfinite(recorded->number) && std::memcmp(&recorded->number, &dt, sizeof dt) != 0 &&
            whole_steps(lpi_time(sys), recorded->number, at) &&
            data_rows_up_to(o, at, data, earlier, rows, unread) == 0 && !rows.empty() && rows.back().step == at &&
            rows.back().time == lpi_time(sys);
        if (recorded_fits && o.given.count("--dt"))
            why = format("lpi run: --resume: --dt %s, but the interrupted run's is %s (%s records it): resume "
                         "with its --dt, or without --dt (another --dt would splice rows of two step sizes)",
                         exact(dt).c_str(), exact(recorded->number).c_str(), data_path(o).c_str());
        if (const int agreed = agreed_failure(why.empty() ? 0 : 2, why)) return agreed;
        if (recorded_fits) {
            std::printf("lpi run: --resume: --dt %s, the interrupted run's (%s records it; the scene's is %s)\n",
                        exact(recorded->number).c_str(), data_path(o).c_str(), exact(dt).c_str());
            dt = recorded->number;
            dt_whose = ", the data's";
        }
        int64_t dt_bits = 0;
        std::memcpy(&dt_bits, &dt, sizeof dt);
        if (!same_everywhere(dt_bits)) {
            std::fprintf(stderr, "lpi run: --resume: the processes read different data of the interrupted run "
                                 "(another --dt): give --dt\n");
            return 2;
        }
    }

    // Steps are counted from the start of the whole run, and the lpi_step
    // calls (one per row) end at the multiples of `every` and at the end: an
    // interrupted run resumed with the same options makes the very same
    // calls, so it ends bit for bit where the uninterrupted run ends.
    int64_t start = 0;
    if (!whole_steps(lpi_time(sys), dt, start)) {
        std::fprintf(stderr, "lpi run: --resume: the checkpoint's time %.17g is not a whole number of "
                             "steps of %.17g (resume with the run's --dt)\n", lpi_time(sys), dt);
        return 2;
    }
    int64_t end = o.steps;
    if (end == 0) {
        end = step_count(o.until > 0.0 ? o.until : it->final_time, dt, "lpi run: --until / --dt");
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
    // The rows up to the checkpoint's step are the interrupted run's, kept:
    // the CSV and the data hold two copies of them. Either copy that
    // reaches the checkpoint (its row there has the checkpoint's time, to
    // the bit, and energy) gives them, the other checked against it before
    // it is rewritten. Where neither file of the run is there (a new or
    // empty --out), new files start at the checkpoint's step; where one is
    // there but neither gives the rows, the run is refused, every file left
    // as it was (started anew at the checkpoint's step, the files lost their
    // rows before it, and the energy error its reference at step 0).
    std::vector<KeptRow> kept;
    std::string not_kept;  // why the data's snapshots are not this run's
    bool data_is_this_runs = false;
    // The interrupted run's --every and --snapshots where its files tell
    // (0 and -1 where they do not), and what tells them.
    int64_t run_every = 0, run_snapshots = -1;
    std::string every_from;
    if (!o.resume.empty()) {
        const double H = energy_of(sys);  // collective
        std::string why;
        struct stat csv_stat;
        const bool csv_there = stat(csv.c_str(), &csv_stat) == 0 || errno != ENOENT;
        std::vector<KeptRow> csv_rows = csv_up_to(csv, start, data.casimir_count, why);
        if (!why.empty()) why = "lpi run: --resume: " + why;
        std::vector<KeptRow> data_rows;
        if (why.empty()) data_rows_up_to(o, start, data, earlier, data_rows, why);
        if (const int agreed = agreed_failure(!why.empty(), why)) return agreed;
        for (Array *array : {&earlier.steps, &earlier.times, &earlier.energies, &earlier.casimirs}) *array = Array();
        std::string other_format;  // the data in the other --format, where it is there
        const bool files_there = data_there(o, data, other_format) || csv_there;
        // "" where `rows`, read from `file`, reach the checkpoint, else why not.
        auto short_of_checkpoint = [&](const std::vector<KeptRow> &rows, const std::string &file) -> std::string {
            if (rows.empty() || rows.back().step != start)
                return format("%s has no row at step %lld, the checkpoint's (t = %.17g with --dt %s%s): the "
                              "file of a run with another --dt, or cut short or older than the checkpoint",
                              file.c_str(), static_cast<long long>(start), lpi_time(sys), exact(dt).c_str(),
                              dt_whose.c_str());
            // Written at the end of the same call as the checkpoint: another
            // time there is another --dt, whose rows would be spliced in.
            const KeptRow &last = rows.back();
            if (last.time != lpi_time(sys))
                return format("the checkpoint's time %.17g is step %lld of --dt %.17g, but %s has t = %.17g at "
                              "that step: resume with the options of the interrupted run",
                              lpi_time(sys), static_cast<long long>(start), dt, file.c_str(), last.time);
            // Its energy, written from the same state with 17 digits (the
            // margin for a sum over another number of processes).
            if (std::fabs(last.energy - H) > 1e-12 * std::max(std::fabs(last.energy), std::fabs(H)))
                return format("%s has the energy %.17g at step %lld, but the checkpoint's state has %.17g: it is "
                              "another run's",
                              file.c_str(), last.energy, static_cast<long long>(start), H);
            return "";
        };
        // The first difference of the two copies ("": none), up to the
        // last step both reach: a step that one holds and the other not, or
        // a value (time, energy, a Casimir) not the same to the bit.
        auto difference = [&]() -> std::string {
            const int64_t limit = std::min(csv_rows.empty() ? -1 : csv_rows.back().step,
                                           data_rows.empty() ? -1 : data_rows.back().step);
            const std::string data_file = data_path(o);
            for (std::size_t i = 0, j = 0;; ++i, ++j) {
                const bool in_csv = i < csv_rows.size() && csv_rows[i].step <= limit,
                           in_data = j < data_rows.size() && data_rows[j].step <= limit;
                if (!in_csv && !in_data) return "";
                if (!in_csv || !in_data || csv_rows[i].step != data_rows[j].step) {
                    const bool csv_has = in_csv && (!in_data || csv_rows[i].step < data_rows[j].step);
                    return format("%s has a row at step %lld, %s has none", (csv_has ? csv : data_file).c_str(),
                                  static_cast<long long>(csv_has ? csv_rows[i].step : data_rows[j].step),
                                  (csv_has ? data_file : csv).c_str());
                }
                const KeptRow &a = csv_rows[i], &b = data_rows[j];
                std::vector<std::pair<std::string, std::pair<double, double>>> values = {
                    {"time", {a.time, b.time}}, {"energy", {a.energy, b.energy}}};
                for (std::size_t k = 0; k < a.casimirs.size() && k < b.casimirs.size(); ++k)
                    values.push_back({format("casimir_%zu", k), {a.casimirs[k], b.casimirs[k]}});
                for (const auto &v : values)
                    if (std::memcmp(&v.second.first, &v.second.second, sizeof(double)) != 0)
                        return format("at step %lld, %s has %s %.17g, %s has %.17g", static_cast<long long>(a.step),
                                      csv.c_str(), v.first.c_str(), v.second.first, data_file.c_str(),
                                      v.second.second);
            }
        };
        const std::string csv_short = short_of_checkpoint(csv_rows, csv),
                          data_short = short_of_checkpoint(data_rows, data_path(o));
        const std::string differs = difference();
        const std::string another_run =
            differs.empty() ? "" : format("its rows are not those of the CSV (%s): it is the data of another run",
                                          differs.c_str());
        // Both copies reach the checkpoint but differ: one was changed since
        // lpi wrote it, and which is not for lpi to guess (taking either
        // overwrites the other).
        // The run's data in the other --format: ignored, its options were
        // not taken and its snapshots were split across two files.
        if (!earlier.there && !other_format.empty())
            why = format("lpi run: --resume: the data of the interrupted run is %s, of --format %s, and there is "
                         "none of --format %s: resume with --format %s, or move %s aside",
                         other_format.c_str(), o.format == "h5" ? "npy" : "h5", o.format.c_str(),
                         o.format == "h5" ? "npy" : "h5", other_format.c_str());
        else if (csv_short.empty() && data_short.empty() && !differs.empty())
            why = format("lpi run: --resume: the CSV and the data, two copies of the rows up to the checkpoint's "
                         "step, differ: %s. One was changed since lpi wrote it: remove %s to resume from the "
                         "data's rows, or move %s aside to resume from the CSV's (its snapshots then lost)",
                         differs.c_str(), csv.c_str(), data_path(o).c_str());
        if (const int agreed = agreed_failure(why.empty() ? 0 : 2, why)) return agreed;
        std::string rows_from;  // the file the kept rows are read from
        if (csv_short.empty()) {
            kept = std::move(csv_rows);
            rows_from = csv;
            not_kept = !earlier.there ? "no data there" : another_run;
            data_is_this_runs = not_kept.empty();
        } else if (data_short.empty() && differs.empty()) {
            // The CSV moved away or cut short: its rows are the data's.
            std::printf("%s %s: its rows up to step %lld are taken from %s\n", csv.c_str(),
                        !csv_there          ? "is not there"
                        : csv_rows.empty() ? "has no rows"
                                           : "ends before the checkpoint's step",
                        static_cast<long long>(start), data_path(o).c_str());
            kept = std::move(data_rows);
            rows_from = data_path(o);
            data_is_this_runs = true;
        } else if (!files_there && (!o.given.count("--dt") || !o.given.count("--every"))) {
            // The checkpoint (the library's format) holds no --dt nor
            // --every, and no file of the run records them: the scene's
            // defaults would go on at another step, the time wrong.
            why = format("lpi run: --resume: neither %s nor the data %s is there, and the checkpoint does not "
                         "record the interrupted run's --dt and --every: give them (--dt and --every as that run "
                         "had them) to start new files at the checkpoint's step",
                         csv.c_str(), data_path(o).c_str());
        } else if (!files_there) {
            // A new or empty --out: no rows to lose, and none to splice.
            std::printf("neither %s nor the data %s is there: new files from step %lld, the energy error "
                        "relative to that step\n",
                        csv.c_str(), data_path(o).c_str(), static_cast<long long>(start));
            not_kept = "no data there";
        } else {
            why = !csv_rows.empty()    ? csv_short
                  : !data_rows.empty() ? data_short
                                       : format("neither %s nor the data %s holds the interrupted run's rows",
                                                csv.c_str(), data_path(o).c_str());
            if (!csv_short.empty() && !data_short.empty() && !csv_rows.empty() && !data_rows.empty())
                why += "; and " + data_short;
            else if (!csv_short.empty() && data_short.empty())
                why += "; and " + another_run;
            why = "lpi run: --resume: " + why +
                  " (its rows up to the checkpoint's step, the reference of the energy errors, would be lost: "
                  "resume with the options and --out of the interrupted run, or into an --out without its "
                  "files to start new ones at that step)";
        }
        if (const int agreed = agreed_failure(why.empty() ? 0 : 2, why)) return agreed;
        // The interrupted run's --every and --snapshots: as its data records
        // them, else (--every) the step between its rows (the largest: the
        // first after a new file's start and the last, at a run's end, may be
        // shorter).
        if (data_is_this_runs) {
            auto whole = [](const Attribute *a, double least) {
                return a && a->number >= least && a->number < 0x1p62 && a->number == std::trunc(a->number);
            };
            const Attribute *recorded = earlier.attribute("every");
            if (whole(recorded, 1.0))
                run_every = static_cast<int64_t>(recorded->number), every_from = data_path(o) + " records it";
            recorded = earlier.attribute("snapshot_every");
            if (whole(recorded, 0.0)) run_snapshots = static_cast<int64_t>(recorded->number);
        }
        if (run_every == 0 && kept.size() >= 2) {
            for (std::size_t r = 1; r < kept.size(); ++r) run_every = std::max(run_every, kept[r].step - kept[r - 1].step);
            every_from = "the largest step between the rows of " + rows_from;
        }
        // Given otherwise, refused: another --every ends the library's calls
        // elsewhere (and the flows merged at their seams round otherwise),
        // another --snapshots splices another layout of snapshots.
        if (o.every > 0 && run_every > 0 && o.every != run_every)
            why = format("lpi run: --resume: --every %lld, but the interrupted run's is %lld (%s): resume with "
                         "its --every, or without --every (another would end the library's calls elsewhere, and "
                         "so not bit for bit where the uninterrupted run ends)",
                         static_cast<long long>(o.every), static_cast<long long>(run_every), every_from.c_str());
        if (why.empty() && run_snapshots >= 0 && o.given.count("--snapshots") && o.snapshot_every != run_snapshots)
            why = format("lpi run: --resume: --snapshots %lld, but the interrupted run's is %lld (%s records "
                         "it): resume with its --snapshots, or without --snapshots",
                         static_cast<long long>(o.snapshot_every), static_cast<long long>(run_snapshots),
                         data_path(o).c_str());
        if (run_snapshots >= 0 && !o.given.count("--snapshots")) o.snapshot_every = run_snapshots;
        if (data_is_this_runs && why.empty()) {
            const Attribute *recorded = earlier.attribute("scene");
            if (recorded && recorded->text != o.scene)
                why = format("lpi run: --resume: %s is a run of %s, not %s", data_path(o).c_str(),
                             recorded->text.c_str(), o.scene.c_str());
            recorded = earlier.attribute("dt");
            if (why.empty() && recorded && std::memcmp(&recorded->number, &dt, sizeof dt) != 0)
                why = format("lpi run: --resume: --dt %.17g, but %s records a run of --dt %.17g: resume with the "
                             "options of the interrupted run",
                             dt, data_path(o).c_str(), recorded->number);
        }
        if (const int agreed = agreed_failure(why.empty() ? 0 : 2, why)) return agreed;
    }
    const int64_t every = o.every > 0 ? o.every : run_every > 0 ? run_every : std::max<int64_t>(1, end / 100);
    if (!same_everywhere(every) || !same_everywhere(o.snapshot_every)) {
        std::fprintf(stderr, "lpi run: --resume: the processes read different files of the interrupted run "
                             "(another --every or --snapshots): give --every and --snapshots\n");
        return 2;
    }
    // The layout of the kept rows: every --every steps from the first,
    // counted from step 0 (the steps of the interrupted run's library calls),
    // the last one at the run's end where that came before the next.
    if (!o.resume.empty()) {
        std::string why;
        int64_t expected = kept.empty() ? 0 : kept.front().step / every * every;
        for (std::size_t r = 1; r < kept.size() && why.empty(); ++r) {
            expected += every;
            if (kept[r].step == expected || (r + 1 == kept.size() && kept[r].step == start && start < expected))
                continue;
            if (o.every > 0)
                why = format("lpi run: --resume: --every %lld, but the interrupted run's row %zu is at step %lld: "
                             "resume with its --every (another would end the library's calls elsewhere, and so not "
                             "bit for bit where the uninterrupted run ends)",
                             static_cast<long long>(every), r, static_cast<long long>(kept[r].step));
            else  // --every not given: the layout the rows themselves or the data gave is broken
                why = format("lpi run: --resume: the interrupted run's rows are not every %lld steps (%s): row %zu "
                             "is at step %lld, not %lld (a row removed or added since lpi wrote it?)",
                             static_cast<long long>(every), every_from.empty() ? "this run's default" : every_from.c_str(),
                             r, static_cast<long long>(kept[r].step), static_cast<long long>(expected));
        }
        if (const int agreed = agreed_failure(why.empty() ? 0 : 2, why)) return agreed;
    }
    // A checkpoint off the grid (the end of a run that an earlier lpi saved
    // there, or one the grid of another --every puts there) cannot be
    // continued bit for bit; its row, the end of a shorter call, is dropped
    // (and a snapshot there), and the run goes on to the next row on the
    // grid, so that the files keep the layout a later resume reads.
    const bool drop_start_row = !o.resume.empty() && start % every != 0 && kept.size() > 1 && kept.back().step == start;
    if (drop_start_row) kept.pop_back();
    // Row r is written after step min(r * every, end).
    auto row_index = [&](int64_t step) { return step / every + (step % every != 0); };
    // The rows and the snapshots are kept in memory until they are written,
    // and read back to resume: at most kMaxArrayValues (2 GiB of doubles) an
    // array, the most lpi reads back as one. A run past that would hold more
    // and could not be resumed.
    {
        const int64_t rows = row_index(end) + 1;
        const int64_t shots = o.snapshot_every > 0 ? (rows - 1) / o.snapshot_every + 1 : 0;
        const double most = static_cast<double>(kMaxArrayValues),
                     row_width = static_cast<double>(std::max<std::size_t>(data.casimir_count, 1)),
                     casimir_values = static_cast<double>(rows) * row_width,
                     snapshot_values = static_cast<double>(shots) * static_cast<double>(data.snapshot_size());
        if (casimir_values > most) {
            std::fprintf(stderr, "lpi run: --every: %lld rows of %zu Casimirs are %.3g values, more than the "
                                 "2^28 (2 GiB) lpi keeps as one array: write rows less often\n",
                         static_cast<long long>(rows), data.casimir_count, casimir_values);
            return 2;
        }
        if (snapshot_values > most) {
            std::fprintf(stderr, "lpi run: --snapshots: %lld snapshots of %zu values are %.3g values, more "
                                 "than the 2^28 (2 GiB) lpi keeps as one array: take them less often (or "
                                 "none: --snapshots 0)\n",
                         static_cast<long long>(shots), data.snapshot_size(), snapshot_values);
            return 2;
        }
        // All of it must fit besides, with what writing it takes: the rows
        // (5 values and the Casimirs each) and the snapshots, and at the end
        // the CSV as one text (csv_text_size) or the data's datasets copied
        // and made into the file (.npy: its bytes; HDF5: the file in memory,
        // its image and the integers converted). Short of that, a run ran
        // out of memory only after all its steps, and lost them.
        const double held = 8.0 * (static_cast<double>(rows) * (5.0 + row_width) +
                                    static_cast<double>(shots) * (2.0 + static_cast<double>(data.snapshot_size()))),
                     csv_text = static_cast<double>(csv_text_size(static_cast<std::size_t>(rows), data.casimir_count)),
                     needed = held + std::max(csv_text, (o.format == "h5" ? 4.0 : 2.0) * held);
        // Each process's own memory: all agree.
        const bool fits = needed < 0x1p62 && lpi::address_space_available(static_cast<std::size_t>(needed));
        const std::string no_room =
            fits ? ""
                 : format("lpi run: %lld rows and %lld snapshots of %zu values need about %.0f MiB of memory to keep "
                          "and write, more than is available: write rows less often (--every) or fewer snapshots "
                          "(--snapshots)",
                          static_cast<long long>(rows), static_cast<long long>(shots), data.snapshot_size(),
                          needed / 1048576.0);
        if (const int agreed = agreed_failure(!fits, no_room)) return agreed;
        // Taken at their full size now: grown by doubling, they held up to
        // twice as much.
        for (auto *v : {&data.step, &data.time, &data.energy, &data.energy_error, &data.casimir_drift})
            v->reserve(static_cast<std::size_t>(rows) + 1);
        data.casimirs.reserve((static_cast<std::size_t>(rows) + 1) * data.casimir_count);
        data.snapshot_step.reserve(static_cast<std::size_t>(shots));
        data.snapshot_time.reserve(static_cast<std::size_t>(shots));
        data.snapshots.reserve(static_cast<std::size_t>(shots) * data.snapshot_size());
    }

    // Every process makes it (or finds it there), each on its own disk; a
    // folder made here goes again when a path below is refused.
    struct stat out_before;
    const bool out_existed = stat(o.out_dir.c_str(), &out_before) == 0;
    std::string no_output = make_output_dir(o.out_dir);
    if (!no_output.empty()) no_output = "lpi run: --out " + no_output;
    // The files are written at the end: those that cannot be fail now, before
    // the work (rank 0 writes them).
    for (std::size_t i = 0; i < outputs.size() && no_output.empty() && writes_output(); ++i) {
        struct stat dir;  // the .npy files' folder is made when the data is written
        const std::string parent = outputs[i].substr(0, outputs[i].find_last_of('/'));
        if (stat(parent.c_str(), &dir) == 0 || errno != ENOENT) no_output = output_problem(outputs[i]);
        if (!no_output.empty()) no_output = "lpi run: " + no_output;
    }
    // The checkpoint too: its first save follows a write of the CSV, which a
    // checkpoint that cannot be made must not have replaced.
    if (no_output.empty() && writes_output() && !o.checkpoint.empty()) {
        no_output = output_problem(o.checkpoint);
        if (!no_output.empty()) no_output = "lpi run: --checkpoint: " + no_output;
    }
    // And the wisdom measured planning writes, probed as the outputs are.
    if (no_output.empty() && writes_output() && !o.wisdom.empty() && !o.planning.empty() && o.planning != "estimate") {
        no_output = output_problem(o.wisdom);
        if (!no_output.empty()) no_output = "lpi run: --wisdom: " + no_output;
    }
    if (const int agreed = agreed_failure(!no_output.empty(), no_output)) {
        if (!out_existed) rmdir(o.out_dir.c_str());  // only if empty
        return agreed;
    }
    // Wisdom once every path is checked (a wisdom file was written before
    // an --out that could not be made was refused), and before any planning (the first step's or --planning's)
    // uses it; measured plans are written back for the next run. A wisdom
    // file that cannot be read or written fails as any file does (exit
    // status 1); only a regular one is read (FFTW would wait on a FIFO).
    // Each process reads the file, and rank 0 alone writes it: all agree.
    if (!o.wisdom.empty()) {
        struct stat wisdom_file;
        const bool exists = stat(o.wisdom.c_str(), &wisdom_file) == 0;
        const bool regular = exists && S_ISREG(wisdom_file.st_mode);
        std::string why;
        if (exists && !regular) why = "lpi run: --wisdom: " + o.wisdom + " is not a regular file";
        if (const int agreed = agreed_failure(!why.empty(), why)) return agreed;
        check_option(regular ? lpi_fftw_wisdom_import_file(o.wisdom.c_str()) : LPI_OK, nullptr, "--wisdom", 1);
    }
    if (!o.planning.empty()) {
        check_option(lpi_sine_euler_set_planning(sys, o.planning.c_str()), sys, "--planning");
        if (!o.wisdom.empty() && o.planning != "estimate")
            check_option(writes_output() ? lpi_fftw_wisdom_export_file(o.wisdom.c_str()) : LPI_OK, nullptr,
                         "--wisdom", 1);
    }
    // The references of the errors and drifts: the first row of the CSV
    // when resuming (step 0, or the step a new file started at; to the bit:
    // written with 17 digits), else this state.
    double H0 = energy_of(sys);
    std::vector<double> C0 = casimirs_of(sys);
    const bool spectrum = data.vorticity;
    // The energy error is relative to |H(0)|; where H(0) = 0 (a zero field,
    // a vanishing Hamiltonian), as lpi stress does, it is H - H(0) itself,
    // and the CSV column and the data's attribute energy_error say so.
    auto absolute_error = [&] { return H0 == 0.0; };
    auto add_row = [&](int64_t step, double time, double H, const std::vector<double> &c) {
        data.step.push_back(static_cast<double>(step));
        data.time.push_back(time);
        data.energy.push_back(H);
        data.energy_error.push_back(absolute_error() ? H - H0 : (H - H0) / std::fabs(H0));
        data.casimirs.insert(data.casimirs.end(), c.begin(), c.end());
        data.casimir_drift.push_back(casimir_drift(spectrum, c, C0));
    };
    if (!kept.empty()) H0 = kept.front().energy, C0 = kept.front().casimirs;
    for (const KeptRow &r : kept) add_row(r.step, r.time, r.energy, r.casimirs);
    if (!o.resume.empty()) {
        std::string why;
        const int status = keep_snapshots(o, drop_start_row ? start - 1 : start, not_kept, data, why);
        if (const int agreed = agreed_failure(status, why)) return agreed;
        // Data that ends before the last snapshot this run's grid puts
        // before the start (a data file older than the checkpoint, a journal
        // left out) cannot be completed: say which snapshots it lacks.
        const int64_t rows_before = row_index(start) - 1;
        if (!data.snapshot_step.empty() && o.snapshot_every > 0 && rows_before >= 0) {
            const int64_t due = rows_before / o.snapshot_every * o.snapshot_every * every;
            const double last = data.snapshot_step.back();
            if (last < static_cast<double>(due))
                std::printf("%s: its snapshots end at step %.0f: those after it and before step %lld are not "
                            "in it, and the data goes on from step %lld\n",
                            data_path(o).c_str(), last, static_cast<long long>(start),
                            static_cast<long long>(start));
        }
    }
    // Every process has read what it keeps before rank 0 rewrites the files.
    synchronize();

    // The CSV holds every row of `data` (the kept rows too, written again to
    // the same bytes), written by rank 0 as the data is: with each
    // checkpoint, so that what a killed run leaves reaches the checkpoint it
    // resumes from, and at the end of the run, however it ends. It is written
    // whole the first time (and wherever the file is no longer as lpi left
    // it), then grown in place by the rows since (output.hpp): a write costs
    // its new rows, where rewriting every row at each checkpoint made a run
    // of n rows cost n^2 (20000 rows: 71 s against 0.1 s without checkpoints).
    auto csv_row = [&](std::size_t r) {
        std::string text = format("%lld,%.17g,%.17g,%.17g", static_cast<long long>(data.step[r]), data.time[r],
                                  data.energy[r], data.energy_error[r]);
        for (std::size_t i = 0; i < data.casimir_count; ++i)
            text += format(",%.17g", data.casimirs[r * data.casimir_count + i]);
        return text + "\n";
    };
    auto csv_text = [&] {
        std::string text;
        text.reserve(csv_text_size(data.step.size(), data.casimir_count));  // not twice that, grown by doubling
        text += absolute_error() ? "step,time,energy,absolute_energy_error" : "step,time,energy,energy_error";
        for (std::size_t i = 0; i < data.casimir_count; ++i) text += format(",casimir_%zu", i);
        text += "\n";
        for (std::size_t r = 0; r < data.step.size(); ++r) text += csv_row(r);
        return text;
    };
    FileIdentity csv_file;     // the CSV as this run left it
    std::size_t csv_rows = 0;  // the rows in it
    auto write_csv = [&]() -> std::string {
        if (!writes_output()) return "";
        std::string tail;
        if (csv_rows > data.step.size()) csv_file = FileIdentity();  // rows taken back: written whole
        for (std::size_t r = csv_rows; csv_file.known && r < data.step.size(); ++r) tail += csv_row(r);
        const std::string why = grow_output(csv, csv_file, tail, csv_text);
        if (!why.empty()) return "lpi run: " + why;
        csv_rows = data.step.size();
        return "";
    };
    // The scene's description where the run is the scene's own (its
    // initial state, the default method and step, as figure2's names them);
    // else what was run, the scene's text being wrong about it.
    std::string description = it->description;
    if (!o.init.empty() || method != "leapfrog" || dt != it->run_step) {
        description = format("%s (a %s system", o.scene.c_str(), lpi_kind(sys));
        if (data.vorticity) description += format(", N = %d", static_cast<int>(N));
        description += format("), %s, dt = %g, initial state %s, H(0) = %.6g", method.c_str(), dt,
                              o.init.empty() ? "the scene's" : ("the vorticity of " + o.init).c_str(), H0);
    }
    const std::vector<Attribute> attributes = {
        {"scene", o.scene, 0.0, true},
        {"method", method, 0.0, true},
        {"dt", "", dt, false},
        {"every", "", static_cast<double>(every), false, true},
        {"snapshot_every", "", static_cast<double>(o.snapshot_every), false, true},
        {"N", "", static_cast<double>(N), false, true},
        {"lpi_version", lpi_version_string(), 0.0, true},
        {"description", description, 0.0, true},
        {"energy_error", absolute_error() ? "absolute" : "relative", 0.0, true},
    };
    WrittenData written;  // what the last write of the data left
    // Writes the data (rank 0 alone): "" or the message saying why not.
    // `final` where the run ends: the HDF5 file takes its journal (run_data.hpp).
    auto keep_data = [&](bool final) -> std::string {
        if (!writes_output()) return "";
        const std::string why = write_data(o, data, attributes, written, final);
        if (why.empty()) return "";
        return format("lpi run: the data %s was not written: %s", data_path(o).c_str(), why.c_str());
    };
    Progress progress(start, end);
    // A failure once the run has gathered rows and snapshots stops it with
    // exit status `status` (its message printed already), but not before
    // they are written: the data (and, with `with_csv`, the CSV; not where
    // the CSV is what failed), each as far as it can be, whatever the other
    // does; not the data where it is what failed (`with_data` false), whose
    // file is then the one written with the last checkpoint. Nothing here is
    // collective: rank 0 writes, every process exits.
    auto stop_keeping_data = [&](int status, int64_t step, bool with_csv, bool with_data = true) {
        progress.finish();
        std::string why = with_csv ? write_csv() : "";
        const std::string no_data = with_data ? keep_data(true) : "";
        if (!no_data.empty()) why += (why.empty() ? "" : "\n") + no_data;
        if (!why.empty())
            std::fprintf(stderr, "%s\n", why.c_str());
        else if (writes_output() && with_data)
            std::fprintf(stderr, "lpi run: the rows and snapshots up to step %lld are in %s\n",
                         static_cast<long long>(step), data_path(o).c_str());
        std::exit(status);
    };
    // A library call of the run that fails: its message, then as above.
    auto checked = [&](int status, const char *what, int64_t step) {
        if (status == LPI_OK) return;
        std::fprintf(stderr, "lpi run: %s failed at step %lld: %s (%s)\n", what, static_cast<long long>(step),
                     lpi_last_error(sys), lpi_status_name(status));
        stop_keeping_data(1, step, true);
    };
    auto record = [&](int64_t step, double H, const std::vector<double> &c) { add_row(step, lpi_time(sys), H, c); };
    auto row = [&](int64_t step) {
        double H = 0.0;  // collective: every process writes every row
        checked(lpi_energy(sys, &H), "energy", step);
        std::vector<double> c(lpi_casimir_count(sys));
        checked(lpi_casimirs(sys, c.data(), c.size()), "casimirs", step);
        record(step, H, c);
    };
    auto snapshot = [&](int64_t step) {
        if (o.snapshot_every <= 0 || row_index(step) % o.snapshot_every != 0) return;
        const std::size_t size = data.snapshot_size(), at = data.snapshots.size();
        data.snapshots.resize(at + size);
        const int status = data.vorticity ? lpi_sine_euler_get_grid(sys, &data.snapshots[at], size)
                                          : lpi_get_state(sys, &data.snapshots[at], size);
        if (status != LPI_OK) data.snapshots.resize(at);  // the snapshots taken are kept
        checked(status, data.vorticity ? "get grid" : "get state", step);
        data.snapshot_step.push_back(static_cast<double>(step));
        data.snapshot_time.push_back(lpi_time(sys));
    };
    // A checkpoint that cannot be written stops the run: going on would lose
    // it; and so do the CSV and the data written with it. They go first, so
    // that a run stopped before the checkpoint (a failure, a kill, SIGKILL
    // included) leaves a CSV and data that reach the checkpoint it resumes
    // from (--resume replaces the rows and snapshots past it, and keeps those
    // up to it; a CSV without the checkpoint's row would be started anew, and
    // data written only at the end lost every snapshot of a killed run). A
    // failure of either still writes the other before the run exits
    // (stop_keeping_data). The checkpoint's path is probed before the run.
    // `save_file` runs lpi_save (rank 0 alone may save one) and names the
    // system saved; each outcome is agreed by all.
    // `final` for the run's last checkpoint (keep_data).
    auto write_checkpoint = [&](int64_t step, bool final, const std::function<int(const lpi_system *&)> &save_file) {
        const std::string no_csv = write_csv();
        if (const int agreed = agreed_failure(!no_csv.empty(), no_csv)) stop_keeping_data(agreed, step, false);
        const std::string no_data = keep_data(final);
        if (const int agreed = agreed_failure(!no_data.empty(), no_data))
            stop_keeping_data(agreed, step, false, false);
        const lpi_system *saved = sys;
        const int status = save_file(saved);
        const std::string why = status == LPI_OK ? ""
                                                 : format("lpi run: checkpoint not written at step %lld: %s",
                                                          static_cast<long long>(step), lpi_last_error(saved));
        if (const int agreed = agreed_failure(status != LPI_OK, why)) stop_keeping_data(agreed, step, false);
    };
    auto save = [&](int64_t step, bool always, bool final = false) {
        if (o.checkpoint.empty()) return;
        if (!always && (o.checkpoint_every <= 0 || row_index(step) % o.checkpoint_every != 0)) return;
        write_checkpoint(step, final, [&](const lpi_system *&) { return lpi_save(sys, o.checkpoint.c_str()); });
    };

    std::printf("lpi run %s: steps %lld to %lld of %g with %s, output every %lld steps\n", o.scene.c_str(),
                static_cast<long long>(start), static_cast<long long>(end), dt, method.c_str(),
                static_cast<long long>(every));
    std::fflush(stdout);
    // Caught before the first row: once it is written, a signal stops the run
    // cleanly (before the first step, if it comes that early).
    catch_interrupts();
    // The start's row when the CSV has none, from H0 and C0 (this state's
    // then): the CSV each process read may differ, and energy_of is collective.
    if (kept.empty()) record(start, H0, C0);
    // The start's snapshot, before the checkpoint, whose data then holds it:
    // step 0's, or, resumed, the checkpoint step's where the data kept none
    // (no data there, another run's, or one that ends before that step),
    // taken from this state, the one the interrupted run had there.
    if (!drop_start_row &&
        (o.resume.empty() || data.snapshot_step.empty() || data.snapshot_step.back() < static_cast<double>(start)))
        snapshot(start);
    save(start, true);
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
    while (done < end && !(interrupted_by = agreed_signal(interrupted_by))) {
        const int64_t next = std::min(end, (done / every + 1) * every);
        if (!o.checkpoint.empty()) {
            std::size_t size = 0;
            checked(lpi_save_buffer(sys, nullptr, 0, &size), "checkpoint size", done);
            call_start_checkpoint.resize(size);
            checked(lpi_save_buffer(sys, call_start_checkpoint.data(), size, &size), "checkpoint", done);
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
            std::fprintf(stderr, "lpi run: steps %lld to %lld failed: %s (%s); the state at step %lld is "
                                 "the last row of %s\n",
                         static_cast<long long>(done), static_cast<long long>(next), lpi_last_error(sys),
                         lpi_status_name(status), static_cast<long long>(done), csv.c_str());
            // lpi_step's status is the same on every process: all stop here.
            for (const std::string &why : {write_csv(), keep_data(true)})
                if (!why.empty()) std::fprintf(stderr, "%s\n", why.c_str());
            return 1;
        }
        done = next;
        row(done);
        snapshot(done);
        save(done, false);
        progress.update(done);
    }
    progress.finish();
    // A run that ends off the --every grid ends in a call shorter than the
    // uninterrupted longer run's (which goes on to the next multiple of
    // --every): a run extended from the end state would split that call in
    // two. So its final checkpoint too is that of the last call's start, the
    // last row on the grid, and an extension replaces the rows after it.
    const bool off_grid_end = !stopped_between_rows && done % every != 0 && !call_start_checkpoint.empty();
    const int64_t saved_step = stopped_between_rows || off_grid_end ? watch.call_start : done;
    if ((stopped_between_rows || off_grid_end) && !o.checkpoint.empty()) {
        Handle at_call_start;  // one process's system: rank 0 alone saves it
        write_checkpoint(done, true, [&](const lpi_system *&saved) {
            if (!writes_output()) return static_cast<int>(LPI_OK);
            int status = lpi_load_buffer(at_call_start.out(), call_start_checkpoint.data(),
                                         call_start_checkpoint.size());
            saved = at_call_start.get();
            if (status == LPI_OK) status = lpi_save(at_call_start.get(), o.checkpoint.c_str());
            return status;
        });
    } else if (!stopped_between_rows && !off_grid_end) {
        save(done, true, true);
    }
    // Rank 0 alone writes the CSV and the data: each, whether or not the
    // other could be (the data holds the snapshots, the CSV does not); with
    // --checkpoint the last save wrote both (a failure there ended the run).
    if (o.checkpoint.empty()) {
        std::string why = write_csv();
        const std::string no_data = keep_data(true);
        if (!no_data.empty()) why += (why.empty() ? "" : "\n") + no_data;
        if (const int agreed = agreed_failure(!why.empty(), why)) return agreed;
    }
    // The script and images drawn from the data, put in step with the data
    // now written (rank 0's; whatever comes of drawing them after).
    std::string unmatched;
    if (writes_output() && data.vorticity) unmatched = match_drawings(o, data, written.bytes, dt, method);
    if (!unmatched.empty()) std::fprintf(stderr, "lpi run: %s\n", unmatched.c_str());
    const double H = energy_of(sys);
    if (interrupted_by) {
        const int64_t stop = stopped_between_rows ? watch.stopped_at : done;
        std::printf("interrupted at step %lld (t = %.17g)", static_cast<long long>(stop), lpi_time(sys));
        if (!o.checkpoint.empty())
            std::printf("; %s holds step %lld (the last row on the --every grid): the same command with "
                        "--resume %s continues it",
                        o.checkpoint.c_str(), static_cast<long long>(saved_step), o.checkpoint.c_str());
        std::printf("\n");
        return 128 + interrupted_by;
    }
    if (!o.checkpoint.empty() && saved_step != done)
        std::printf("checkpoint: %s (step %lld, the last row on the --every grid: an extension of the run "
                    "resumes there)\n",
                    o.checkpoint.c_str(), static_cast<long long>(saved_step));
    else if (!o.checkpoint.empty())
        std::printf("checkpoint: %s\n", o.checkpoint.c_str());
    std::printf("done: t = %g, %.3f CPU seconds, %s energy error %.3e; wrote %s and %s\n", lpi_time(sys),
                cpu_seconds() - t0, absolute_error() ? "absolute (H(0) = 0)" : "relative",
                absolute_error() ? H - H0 : (H - H0) / std::fabs(H0), csv.c_str(), data_path(o).c_str());

    // Rank 0 alone draws the snapshots: main agrees on the exit status.
    if (writes_output() && data.vorticity && !data.snapshot_step.empty()) {
        if (!have_gnuplot()) {
            std::printf("gnuplot not found: no vorticity images (the snapshots are in %s; %s draws them)\n",
                        data_path(o).c_str(), vorticity_script.c_str());
            return unmatched.empty() ? 0 : 1;
        }
        const std::string not_drawn = plot_vorticity(o, data, written.bytes, dt, method);
        if (interrupted_by) return interrupted_drawing(not_drawn.empty(), vorticity_script);
        if (!not_drawn.empty()) {
            std::fprintf(stderr, "lpi run: %s\n", not_drawn.c_str());
            return 1;
        }
        std::printf("wrote %zu vorticity snapshots: %s/%s_vorticity_*.png and .svg\n", data.snapshot_step.size(),
                    o.out_dir.c_str(), o.scene.c_str());
    }
    return unmatched.empty() ? 0 : 1;
}

}  // namespace lpi_cli
