#include "run_data.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <memory>

#include "output.hpp"
#include "plots.hpp"

namespace lpi_cli {

namespace {

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
        const std::vector<double> x = indices(N, 2.0 * kPi / static_cast<double>(N));
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


// One array of a run's earlier data, in this run's format.
std::string read_data_array(const RunOptions &o, const std::string &name, Array &a) {
    const std::string path = data_path(o);
    if (o.format == "npy") {
        const std::string why = read_npy(path + "/" + name + ".npy", a);
        return why.empty() ? "" : name + ".npy: " + why;
    }
    bool found = false;
    return read_hdf5(path, name, a, &found);
}

}  // namespace

// Where a run's data lives: DIR/SCENE.h5, or the folder DIR/SCENE of .npy files.
std::string data_path(const RunOptions &o) {
    return o.out_dir + "/" + o.scene + (o.format == "h5" ? ".h5" : "");
}


std::vector<std::string> data_files(const RunOptions &o, const RunData &d) {
    if (o.format == "h5") return {data_path(o)};
    std::vector<std::string> files;
    for (const Dataset &set : datasets_of(d)) files.push_back(data_path(o) + "/" + set.name + ".npy");
    files.push_back(data_path(o) + "/attributes.json");
    return files;
}

std::string write_data(const RunOptions &o, const RunData &d, const std::vector<Attribute> &attributes,
                       SnapshotBytes &bytes) {
    const std::vector<Dataset> sets = datasets_of(d);
    const std::string path = data_path(o);
    // gnuplot, run in the output directory, reads the snapshots by this name.
    const std::string in_out_dir = o.scene + (o.format == "h5" ? ".h5" : "/" + sets.back().name + ".npy");
    if (o.format == "h5") {
        std::vector<std::uint64_t> offsets;
        const std::string why = write_hdf5(path, sets, attributes, &offsets);
        if (!why.empty()) return why;
        bytes = {in_out_dir, offsets.back()};
        return "";
    }
    if (mkdir(path.c_str(), 0777) != 0 && errno != EEXIST) return std::strerror(errno);
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
    json += "}\n";
    // The set is replaced as a whole: every file is written and flushed beside
    // its target first, and renamed into place only once all of them are, so
    // that a failed write leaves the old set, never old and new files mixed.
    // Only a kill between two renames can mix them: keep_snapshots then reads
    // what the two sets share, the rows and snapshots up to the checkpoint.
    const std::vector<std::string> files = data_files(o, d);
    std::vector<std::unique_ptr<FileReplacement>> written;
    const std::string why = failure_of([&] {
        for (std::size_t i = 0; i < files.size(); ++i) {
            const std::string content = i < sets.size() ? npy_file(sets[i].array) : json;
            written.push_back(std::make_unique<FileReplacement>(files[i]));
            written.back()->write(reinterpret_cast<const unsigned char *>(content.data()), content.size());
            written.back()->sync();
        }
        for (auto &file : written) file->commit();
    });
    if (!why.empty()) return why;
    bytes = {in_out_dir, npy_header(sets.back().array).size()};
    return "";
}

// The snapshots of the interrupted run up to `start`, from its data; a note
// on stdout (not an error) when there is no data or it is another run's.
// Data that is there but cannot be read back is refused (status 1): the run
// would replace it, and the snapshots in it would be lost.
int keep_snapshots(const RunOptions &o, int64_t start, double start_time, RunData &d, std::string &refusal) {
    refusal.clear();
    // No file of the data there (a run killed before it wrote any): nothing
    // to keep, and nothing that writing the data replaces.
    bool there = false;
    for (const std::string &file : data_files(o, d)) {
        struct stat st;
        if (stat(file.c_str(), &st) == 0 || errno != ENOENT) there = true;
    }
    auto unreadable = [&](const std::string &why) {
        refusal = format("lpi run: --resume: the data %s cannot be read back (%s): resumed, the run would "
                         "replace it, and the snapshots up to step %lld in it would be lost; move it aside (or "
                         "remove it) to resume without them",
                         data_path(o).c_str(), why.c_str(), static_cast<long long>(start));
        return 1;
    };
    auto read = [&](const char *name, Array &a) { return there ? read_data_array(o, name, a) : std::string(); };
    Array row_steps, row_times, row_energies;
    std::string why;  // why the data's snapshots are not this run's
    for (auto *array : {&row_steps, &row_times, &row_energies}) {
        const char *name = array == &row_steps ? "step" : array == &row_times ? "time" : "energy";
        const std::string wrong = read(name, *array);
        if (!wrong.empty()) return unreadable(wrong);
    }
    // A set that a kill cut between two of its files' renames (write_data)
    // holds the arrays of two consecutive writes, of different lengths, which
    // agree on every row and snapshot up to the checkpoint's step: only those
    // are read, and each array must hold them.
    for (std::size_t i = 0; i < row_steps.values.size() && why.empty(); ++i) {
        const double step = row_steps.values[i];
        if (step > static_cast<double>(start)) continue;
        if (i >= row_times.values.size() || i >= row_energies.values.size())
            return unreadable(format("its arrays time and energy end before its row at step %.17g", step));
        if (d.step.empty()) {
            // No CSV: the data's row at the checkpoint's step holds its
            // time, as the CSV's does (run.cpp): another time there is
            // another --dt.
            if (step == static_cast<double>(start) && row_times.values[i] != start_time) {
                refusal = format("lpi run: --resume: the checkpoint's time %.17g is step %lld of this run's --dt, "
                                 "but %s has t = %.17g at that step: resume with the options of the interrupted "
                                 "run",
                                 start_time, static_cast<long long>(start), data_path(o).c_str(),
                                 row_times.values[i]);
                return 2;
            }
            continue;
        }
        // The CSV's rows (in d) are this run's: they hold the checkpoint's
        // time. Data whose rows at the same steps differ is another run's,
        // left there by a run killed before it wrote its own data.
        const auto at = std::lower_bound(d.step.begin(), d.step.end(), step);
        if (at == d.step.end() || *at != step) continue;
        const std::size_t row = static_cast<std::size_t>(at - d.step.begin());
        if (std::memcmp(&d.time[row], &row_times.values[i], sizeof(double)) != 0 ||
            std::memcmp(&d.energy[row], &row_energies.values[i], sizeof(double)) != 0)
            why = format("its row at step %lld is not that of the CSV: it is the data of another run",
                         static_cast<long long>(step));
    }
    Array steps, times, shots;
    for (auto *array : {&steps, &times, &shots}) {
        const char *name = array == &steps ? "snapshot_step" : array == &times ? "snapshot_time"
                           : d.vorticity                   ? "vorticity"
                                                           : "state";
        const std::string wrong = read(name, *array);
        if (!wrong.empty()) return unreadable(wrong);
    }
    if (!there) why = "no data there";
    const std::size_t size = d.snapshot_size();
    std::size_t n = 0;  // the snapshots up to the checkpoint's step
    while (n < steps.values.size() && steps.values[n] <= static_cast<double>(start)) ++n;
    if (why.empty() && (times.values.size() < n || shots.values.size() % size != 0 || shots.values.size() < n * size))
        why = "its snapshot arrays do not match this run";
    // The steps become 64-bit integers (the images' names, the data's
    // /snapshot_step): whole, increasing and in range; data lpi wrote has
    // no others.
    for (std::size_t k = 0; k < n && why.empty(); ++k) {
        const double step = steps.values[k], before = k ? steps.values[k - 1] : -1.0;
        if (!(step >= 0.0 && step < 0x1p62 && step == std::trunc(step) && step > before &&
              std::isfinite(times.values[k])))
            return unreadable(format("its snapshot %zu has no whole step in order or no finite time", k));
    }
    if (!why.empty()) {
        std::printf("%s: %s; the data keeps the snapshots from step %lld on\n", data_path(o).c_str(),
                    why.c_str(), static_cast<long long>(start));
        return 0;
    }
    d.snapshot_step.assign(steps.values.begin(), steps.values.begin() + static_cast<std::ptrdiff_t>(n));
    d.snapshot_time.assign(times.values.begin(), times.values.begin() + static_cast<std::ptrdiff_t>(n));
    d.snapshots.assign(shots.values.begin(), shots.values.begin() + static_cast<std::ptrdiff_t>(n * size));
    d.keep_up_to(start);
    return 0;
}


// The initial grid of --init into `grid`, checked against the system's N:
// 0, or the exit status with the message in `why`.
int initial_grid(const std::string &path, int *N, std::vector<double> &grid, std::string &why) {
    auto refused = [&](int status, const std::string &message) {
        why = "lpi run: --init " + path + ": " + message;
        return status;
    };
    Array a;
    std::string error;
    if (is_hdf5_file(path)) {
        bool found = false;
        error = read_hdf5(path, "init", a, &found);
        if (!found && error.rfind("no dataset", 0) == 0) error = read_hdf5(path, "vorticity", a, &found);
        if (!error.empty() && found) return refused(2, error);
        if (!error.empty() && error.rfind("no dataset", 0) == 0)
            return refused(2, "no dataset /init or /vorticity");
        // A run's /vorticity holds snapshots (S, N, N): start from the last.
        if (error.empty() && a.shape.size() == 3 && a.shape[0] > 0) {
            const std::size_t size = a.shape[1] * a.shape[2];
            a.values.erase(a.values.begin(), a.values.end() - static_cast<std::ptrdiff_t>(size));
            a.shape.erase(a.shape.begin());
        }
    } else {
        error = read_npy(path, a);
    }
    if (!error.empty()) return refused(1, error);
    std::string shape;
    for (std::size_t d : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    if (a.shape.size() != 2 || a.shape[0] != a.shape[1] || a.shape[0] < 3 || a.shape[0] % 2 == 0 ||
        a.shape[0] > 2147483647u)
        return refused(2, "the array has shape (" + shape + "), not (N, N) with N odd >= 3");
    if (*N > 0 && static_cast<std::size_t>(*N) != a.shape[0])
        return refused(2, "the grid is " + std::to_string(a.shape[0]) + " x " + std::to_string(a.shape[0]) +
                              ", but --N is " + std::to_string(*N));
    *N = static_cast<int>(a.shape[0]);
    grid = std::move(a.values);
    return 0;
}


// Draws every vorticity snapshot of the data as PNG and SVG with gnuplot,
// which reads the doubles straight from the data file (nothing is copied
// and nothing deleted).
std::string plot_vorticity(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                           const std::string &method) {
    const std::size_t N = d.snapshot_shape[0], shots = d.snapshot_step.size();
    if (shots == 0 || bytes.offset == UINT64_MAX) return "no snapshot data to draw from in " + data_path(o);
    double scale = 0.0;  // one symmetric colour range for every snapshot
    for (double v : d.snapshots) scale = std::max(scale, std::fabs(v));
    if (!(scale > 0.0)) scale = 1.0;
    PlotScript script(o.out_dir, "vorticity.gp");
    // Grid point (a, b) is x = 2 pi a / N, y = 2 pi b / N: the axes count
    // x / 2 pi, each pixel centred on its point. The array is [a][b], b
    // fastest: gnuplot reads it with x and y swapped back (transpose).
    script += format("set size ratio -1\nset palette defined (0 '#2166ac', 0.5 'white', 1 '#b2182b')\n"
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
        script += format("set title '%s, N = %zu, %s, dt = %g: t = %.6g (step %lld)' noenhanced\n", o.scene.c_str(),
                         N, method.c_str(), dt, d.snapshot_time[k], static_cast<long long>(row));
        for (const auto &terminal : terminals) {
            script += format("set terminal %s\n", terminal[0]) + script.output(name + std::string(".") + terminal[1]);
            script += format("plot '%s' binary array=(%zu,%zu) format='%%float64' endian=little skip=%llu "
                             "transpose dx=%.17g dy=%.17g origin=(0,0) with image\n",
                             bytes.file.c_str(), N, N, static_cast<unsigned long long>(bytes.offset + 8 * k * N * N),
                             1.0 / N, 1.0 / N);
        }
    }
    script += "set output\n";
    return script.draw();
}

}  // namespace lpi_cli
