// `lpi run`: the stepping loop. Rows of the CSV at every --every steps,
// snapshots and checkpoints on that grid, a resumed run continued bit for bit,
// Ctrl-C honoured within a few steps (run_watch), the data written at the end
// (run_data).
#include "run.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

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
// options): same kind, size and Hamiltonian (its energy at the same state).
std::string mismatch(lpi_system *fresh, const lpi_system *loaded) {
    if (std::strcmp(lpi_kind(fresh), lpi_kind(loaded)) != 0) return "it holds another kind of system";
    int32_t n_fresh = 0, n_loaded = 0;
    if (lpi_sine_euler_size(fresh, &n_fresh) == LPI_OK && lpi_sine_euler_size(loaded, &n_loaded) == LPI_OK &&
        n_fresh != n_loaded)
        return "it has N = " + std::to_string(n_loaded) + ", not " + std::to_string(n_fresh);
    if (lpi_dim(fresh) != lpi_dim(loaded) || lpi_casimir_count(fresh) != lpi_casimir_count(loaded))
        return "its system has another dimension";
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
    const double dt = o.dt > 0.0 ? o.dt : it->run_step;
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
    if (!o.method.empty()) check_option(lpi_set_method(sys, o.method.c_str()), sys, "--method");
    if (o.threads != 1) check_option(lpi_set_threads(sys, o.threads), sys, "--threads");
    // Wisdom first, so that any planning (the first step's or --planning's)
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
    // The method in use: --method's, else a new system's default or the
    // checkpoint's (it holds the method).
    const std::string method = lpi_get_method(sys);

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

    // Every process makes it (or finds it there), each on its own disk.
    const std::string no_dir = make_output_dir(o.out_dir);
    if (const int agreed = agreed_failure(!no_dir.empty(), no_dir.empty() ? "" : "lpi run: --out " + no_dir))
        return agreed;
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

    // Every process has read what it keeps before rank 0 rewrites the file;
    // the others write their rows nowhere.
    synchronize();
    FILE *f = std::fopen(writes_output() ? csv.c_str() : "/dev/null", "w");
    const std::string no_csv = f ? "" : format("lpi run: cannot write %s: %s", csv.c_str(), std::strerror(errno));
    if (const int agreed = agreed_failure(!f, no_csv)) {
        if (f) std::fclose(f);
        return agreed;
    }
    if (kept.empty()) {
        std::fprintf(f, "step,time,energy,energy_error");
        for (std::size_t i = 0; i < data.casimir_count; ++i) std::fprintf(f, ",casimir_%zu", i);
        std::fprintf(f, "\n");
    }
    for (const std::string &line : kept) std::fprintf(f, "%s\n", line.c_str());
    // Flushed row by row: a killed run leaves complete rows.
    auto record = [&](int64_t step, double H, const std::vector<double> &c) {
        add_row(step, lpi_time(sys), H, c);
        std::fprintf(f, "%lld,%.17g,%.17g,%.6e", static_cast<long long>(step), lpi_time(sys), H,
                     data.energy_error.back());
        for (double v : c) std::fprintf(f, ",%.17g", v);
        std::fprintf(f, "\n");
        std::fflush(f);
    };
    auto row = [&](int64_t step) {
        const double H = energy_of(sys);  // collective: every process writes every row
        record(step, H, casimirs_of(sys));
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
    // A checkpoint that cannot be written stops the run: going on would lose
    // it. `status` is lpi_save's (rank 0 alone may save one), agreed by all.
    auto checkpoint_saved = [&](int status, const lpi_system *state, int64_t step) {
        const std::string why = status == LPI_OK ? ""
                                                 : format("lpi run: checkpoint not written at step %lld: %s",
                                                          static_cast<long long>(step), lpi_last_error(state));
        if (const int agreed = agreed_failure(status != LPI_OK, why)) std::exit(agreed);
    };
    auto save = [&](int64_t step, bool always) {
        if (o.checkpoint.empty()) return;
        if (!always && (o.checkpoint_every <= 0 || row_index(step) % o.checkpoint_every != 0)) return;
        checkpoint_saved(lpi_save(sys, o.checkpoint.c_str()), sys, step);
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
    // Writes the data (rank 0 alone): "" or the message saying why not.
    auto keep_data = [&]() -> std::string {
        if (!writes_output()) return "";
        const std::string why = write_data(o, data, attributes, bytes);
        if (why.empty()) return "";
        return format("lpi run: the data %s was not written: %s", data_path(o).c_str(), why.c_str());
    };

    std::printf("lpi run %s: steps %lld to %lld of %g with %s, output every %lld steps\n", o.scene.c_str(),
                static_cast<long long>(start), static_cast<long long>(end), dt, method.c_str(),
                static_cast<long long>(every));
    std::fflush(stdout);
    // Caught before the first row: once it is written, a signal stops the run
    // cleanly (before the first step, if it comes that early).
    catch_interrupts();
    save(start, true);
    // The start's row when the CSV has none, from H0 and C0 (this state's
    // then): the CSV each process read may differ, and energy_of is collective.
    if (kept.empty()) record(start, H0, C0);
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
    while (done < end && !(interrupted_by = agreed_signal(interrupted_by))) {
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
            // lpi_step's status is the same on every process: all stop here.
            const std::string why = keep_data();
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
    if (stopped_between_rows && !o.checkpoint.empty()) {
        Handle at_call_start;  // one process's system: rank 0 alone saves it
        int status = LPI_OK;
        if (writes_output()) {
            status = lpi_load_buffer(at_call_start.out(), call_start_checkpoint.data(),
                                     call_start_checkpoint.size());
            if (status == LPI_OK) status = lpi_save(at_call_start.get(), o.checkpoint.c_str());
        }
        checkpoint_saved(status, at_call_start.get(), done);
    } else if (!stopped_between_rows) {
        save(done, true);
    }
    // Rank 0 alone writes the CSV and the data.
    std::string why = close_written(f) ? "" : "lpi run: writing " + csv + " failed";
    if (why.empty()) why = keep_data();
    if (const int agreed = agreed_failure(!why.empty(), why)) return agreed;
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

    // Rank 0 alone draws the snapshots: main agrees on the exit status.
    if (writes_output() && data.vorticity && !data.snapshot_step.empty()) {
        if (!have_gnuplot()) {
            std::printf("gnuplot not found: no vorticity images (the snapshots are in %s)\n",
                        data_path(o).c_str());
            return 0;
        }
        switch (plot_vorticity(o, data, bytes, dt, method)) {
        case Plot::drawn:
            std::printf("wrote %zu vorticity snapshots: %s/vorticity_*.png and .svg\n", data.snapshot_step.size(),
                        o.out_dir.c_str());
            break;
        case Plot::gnuplot_failed: std::printf("gnuplot failed: see %s/vorticity.gp\n", o.out_dir.c_str()); break;
        case Plot::not_written: return 1;
        }
    }
    return 0;
}

}  // namespace lpi_cli
