#include "run_data.hpp"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <memory>
#include <set>

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
        if (!d.topography.empty()) sets.push_back({"topography", array_of({N, N}, d.topography), {"x", "y"}, false});
    } else {
        sets.push_back({"component", array_of({d.snapshot_shape[0]}, indices(d.snapshot_shape[0], 1.0), true),
                        {}, true});
        sets.push_back({"state", array_of(shape, d.snapshots), {"snapshot_time", "component"}, false});
    }
    return sets;
}


// One array of a run's earlier data, in this run's format: for HDF5, the
// file's and, after it, its journal's (when the journal continues the file:
// its base is the rows, or the snapshots where `snapshots`, the file's
// array holds).
std::string read_data_array(const RunOptions &o, const std::string &name, bool snapshots, Array &a) {
    const std::string path = data_path(o);
    auto read_grown = [](const std::string &file, const std::string &name, Array &a) {
        const std::string why = read_npy(file, a, /*tail_allowed=*/true);
        return why.empty() ? "" : name + ".npy: " + why;
    };
    if (o.format == "npy") return read_grown(path + "/" + name + ".npy", name, a);
    bool found = false;
    std::string why = read_hdf5(path, name, a, &found);
    const std::string journal = journal_path(o);
    struct stat st;
    if (!why.empty() || a.shape.empty() || stat(journal.c_str(), &st) != 0) return why;
    // No base: a journal being made or removed when a kill came, ignored. A
    // base that cannot be read is refused, not ignored: the rows it stands
    // for would be lost.
    Array base, tail;
    const std::string base_file = journal + "/base.npy";
    if (stat(base_file.c_str(), &st) != 0 && errno == ENOENT) return "";
    why = read_grown(base_file, journal + "/base", base);
    if (why.empty() && (base.shape != std::vector<std::size_t>{2} || !base.integer))
        why = base_file + ": not the two counts of a journal's base";
    if (!why.empty()) return why;
    if (base.values[snapshots ? 1 : 0] != static_cast<double>(a.shape[0])) return "";  // not this file's
    why = read_grown(journal + "/" + name + ".npy", journal + "/" + name, tail);
    if (!why.empty()) return why;
    if (tail.shape.size() != a.shape.size() || !std::equal(a.shape.begin() + 1, a.shape.end(), tail.shape.begin() + 1))
        return journal + "/" + name + ".npy: not shaped as " + path + "'s " + name;
    if (a.values.size() + tail.values.size() > kMaxArrayValues) return name + ": more than 2^28 values";
    a.shape[0] += tail.shape[0];
    a.values.insert(a.values.end(), tail.values.begin(), tail.values.end());
    return "";
}

}  // namespace

// Where a run's data lives: DIR/SCENE.h5, or the folder DIR/SCENE of .npy files.
std::string data_path(const RunOptions &o) {
    return o.out_dir + "/" + o.scene + (o.format == "h5" ? ".h5" : "");
}


std::vector<std::string> data_files(const RunOptions &o, const RunData &d) {
    if (o.format == "h5") return {data_path(o)};
    std::vector<std::string> files;
    for (const Dataset &set : datasets_of(RunData::shaped_like(d))) files.push_back(data_path(o) + "/" + set.name + ".npy");
    files.push_back(data_path(o) + "/attributes.json");
    return files;
}

std::string journal_path(const RunOptions &o) { return data_path(o) + "-pending"; }

std::vector<std::string> data_folders(const RunOptions &o) {
    return {o.format == "h5" ? journal_path(o) : data_path(o)};
}

namespace {

// An array of the data that grows with the run (rows along "time",
// snapshots along "snapshot_time"), seen where RunData holds it: a write
// that adds the values since the last one copies nothing else.
struct GrowingArray {
    std::string name;
    const std::vector<double> *values;
    std::vector<std::size_t> row_shape;  // the shape of one row or snapshot
    bool integer, snapshots;
    std::size_t width() const {
        std::size_t n = 1;
        for (std::size_t k : row_shape) n *= k;
        return n;
    }
};

// datasets_of's growing arrays, by the same names.
std::vector<GrowingArray> growing_arrays(const RunData &d) {
    const std::vector<std::size_t> row = {}, casimirs = {d.casimir_count};
    return {
        {"time", &d.time, row, false, false},
        {"step", &d.step, row, true, false},
        {"energy", &d.energy, row, false, false},
        {"energy_error", &d.energy_error, row, false, false},
        {"casimirs", &d.casimirs, casimirs, false, false},
        {"casimir_drift", &d.casimir_drift, row, false, false},
        {"snapshot_time", &d.snapshot_time, row, false, true},
        {"snapshot_step", &d.snapshot_step, row, true, true},
        {d.vorticity ? "vorticity" : "state", &d.snapshots, d.snapshot_shape, false, true},
    };
}

// The .npy header of `a` holding `count` rows or snapshots.
std::string header_of(const GrowingArray &a, std::size_t count) {
    Array shape;
    shape.shape = {count};
    shape.shape.insert(shape.shape.end(), a.row_shape.begin(), a.row_shape.end());
    shape.integer = a.integer;
    return npy_header(shape);
}

// Where a set of .npy files holds the rows and snapshots of `d` from
// (first_row, first_shot) on: the run's data (both 0), or the journal of an
// HDF5 file that holds those before them.
struct NpyRange {
    std::string dir;
    std::size_t first_row = 0, first_shot = 0;
    std::size_t rows(const RunData &d) const { return d.step.size() - first_row; }
    std::size_t shots(const RunData &d) const { return d.snapshot_step.size() - first_shot; }
};

std::string array_file(const NpyRange &range, const GrowingArray &a) { return range.dir + "/" + a.name + ".npy"; }

// The bytes of a's rows or snapshots [from, to) of the range.
std::string values_of(const NpyRange &range, const GrowingArray &a, std::size_t from, std::size_t to) {
    const std::size_t first = a.snapshots ? range.first_shot : range.first_row;
    return npy_values(*a.values, a.integer, (first + from) * a.width(), (first + to) * a.width());
}

// Grows the .npy set that `set` describes by the rows and snapshots of `d`
// since: every growing file is checked to be as it was left (FileGrowth),
// its new values appended after the old and flushed, then each header
// rewritten with the new length (the same size: a header is padded to 64
// bytes, which the length's digits fit). false, nothing touched, where a
// file is not as it was left or a header would change size: the set is then
// replaced whole. A failure puts every file back and throws. A kill between
// two files' headers leaves arrays of two writes, of different lengths, as
// a kill between two renames of a whole write does.
bool grow_npy_set(const NpyRange &range, const RunData &d, NpySet &set) {
    const std::vector<GrowingArray> arrays = growing_arrays(d);
    const std::size_t rows = range.rows(d), shots = range.shots(d);
    if (set.files.size() != arrays.size() || set.rows > rows || set.shots > shots) return false;
    std::vector<std::unique_ptr<FileGrowth>> growing;
    std::vector<std::string> headers;
    for (std::size_t i = 0; i < arrays.size(); ++i) {
        const GrowingArray &a = arrays[i];
        const std::size_t old_count = a.snapshots ? set.shots : set.rows, count = a.snapshots ? shots : rows;
        growing.push_back(std::make_unique<FileGrowth>(array_file(range, a), set.files[i]));
        const std::string old_header = header_of(a, old_count);
        headers.push_back(header_of(a, count));
        if (!growing.back()->possible() || old_header.size() != headers.back().size() ||
            growing.back()->old_size() != old_header.size() + 8 * a.width() * old_count)
            return false;
    }
    // An array with nothing new (the snapshots between two) is not touched.
    auto grows = [&](const GrowingArray &a) { return a.snapshots ? shots > set.shots : rows > set.rows; };
    for (std::size_t i = 0; i < arrays.size(); ++i) {
        const GrowingArray &a = arrays[i];
        if (!grows(a)) continue;
        const std::string values = values_of(range, a, a.snapshots ? set.shots : set.rows, a.snapshots ? shots : rows);
        growing[i]->append(reinterpret_cast<const unsigned char *>(values.data()), values.size());
        growing[i]->sync();
    }
    for (std::size_t i = 0; i < arrays.size(); ++i) {
        if (!grows(arrays[i])) continue;
        growing[i]->overwrite(0, reinterpret_cast<const unsigned char *>(headers[i].data()), headers[i].size());
        growing[i]->sync();
    }
    for (std::size_t i = 0; i < arrays.size(); ++i) set.files[i] = growing[i]->commit();
    set.rows = rows;
    set.shots = shots;
    return true;
}

// Replaces the files of a set as a whole: every file is written and flushed
// beside its target first, and renamed into place only once all of them are,
// so that a failed write leaves the old set, never old and new files mixed.
// Only a kill between two renames can mix them: keep_snapshots then reads
// what the two sets share, the rows and snapshots up to the checkpoint.
// Records in `set` what the growing arrays' files are. Throws on failure.
void replace_npy_set(const NpyRange &range, const RunData &d,
                     const std::vector<std::pair<std::string, std::string>> &contents, NpySet &set) {
    if (mkdir(range.dir.c_str(), 0777) != 0 && errno != EEXIST)
        lpi::fail(LPI_ERR_IO, "cannot make the folder " + range.dir + ": " + std::strerror(errno));
    std::vector<std::unique_ptr<FileReplacement>> replacing;
    for (const auto &file : contents) {
        replacing.push_back(std::make_unique<FileReplacement>(range.dir + "/" + file.first));
        replacing.back()->write(reinterpret_cast<const unsigned char *>(file.second.data()), file.second.size());
        replacing.back()->sync();
    }
    set = NpySet();
    std::vector<FileIdentity> identities;
    for (auto &file : replacing) identities.push_back(file->commit());
    for (const GrowingArray &a : growing_arrays(d))
        for (std::size_t i = 0; i < contents.size(); ++i)
            if (contents[i].first == a.name + ".npy") set.files.push_back(identities[i]);
    set.rows = range.rows(d);
    set.shots = range.shots(d);
}

// The journal of an HDF5 file: the rows and snapshots after those the file
// holds, as .npy files, with base.npy giving how many rows and snapshots the
// HDF5 file holds that it continues (a journal left beside a later file, by
// a kill between the file's rename and the journal's removal, is ignored).
void write_journal(const NpyRange &range, const RunData &d, NpySet &set) {
    if (grow_npy_set(range, d, set)) return;
    std::vector<std::pair<std::string, std::string>> contents;
    for (const GrowingArray &a : growing_arrays(d))
        contents.push_back({a.name + ".npy", header_of(a, a.snapshots ? range.shots(d) : range.rows(d)) +
                                                 values_of(range, a, 0, a.snapshots ? range.shots(d) : range.rows(d))});
    // Renamed last (and removed first): a kill among the renames leaves the
    // old base, which no longer matches the file, or none; a base that
    // matches has every array of its journal beside it.
    Array base;
    base.shape = {2};
    base.values = {static_cast<double>(range.first_row), static_cast<double>(range.first_shot)};
    base.integer = true;
    contents.push_back({"base.npy", npy_file(base)});
    replace_npy_set(range, d, contents, set);
}

// Removes the journal (after the HDF5 file that holds its rows is in
// place): the files it writes, then the folder if nothing else is there.
// Best effort: one left behind is ignored, its base not the file's.
void remove_journal(const std::string &dir, const RunData &d) {
    unlink((dir + "/base.npy").c_str());
    for (const GrowingArray &a : growing_arrays(d)) unlink((dir + "/" + a.name + ".npy").c_str());
    // The temporary files (.lpi-XXXXXXXXXXXX) of a journal write that a kill
    // stopped: the folder is lpi's own, and would otherwise stay for them.
    if (DIR *folder = opendir(dir.c_str())) {
        while (const dirent *entry = readdir(folder)) {
            const std::string name = entry->d_name;
            if (name.size() == 17 && name.compare(0, 5, ".lpi-") == 0) unlink((dir + "/" + name).c_str());
        }
        closedir(folder);
    }
    rmdir(dir.c_str());
}

std::size_t values_held(const RunData &d, std::size_t rows, std::size_t shots) {
    std::size_t n = 0;
    for (const GrowingArray &a : growing_arrays(d)) n += a.width() * (a.snapshots ? shots : rows);
    return n;
}

}  // namespace

std::string write_data(const RunOptions &o, const RunData &d, const std::vector<Attribute> &attributes,
                       WrittenData &written, bool final) {
    const std::string path = data_path(o);
    const std::size_t rows = d.step.size(), shots = d.snapshot_step.size();
    if (o.format == "h5") {
        // The file is written whole the first time, at the end, and once the
        // rows and snapshots since its last write hold as many values as it
        // does: n values cost at most 2n written so. In between they grow
        // its journal in place.
        const bool whole = final || !written.h5_written || written.h5_rows > rows || written.h5_shots > shots ||
                           values_held(d, rows, shots) >= 2 * values_held(d, written.h5_rows, written.h5_shots);
        const NpyRange journal{journal_path(o), written.h5_rows, written.h5_shots};
        if (!whole) return failure_of([&] { write_journal(journal, d, written.npy); });
        std::vector<std::uint64_t> offsets;
        const std::vector<Dataset> sets = datasets_of(d);
        const std::string why = write_hdf5(path, sets, attributes, &offsets);
        if (!why.empty()) return why;
        written.bytes = {o.scene + ".h5", offsets.back()};
        written.h5_written = true;
        written.h5_rows = rows;
        written.h5_shots = shots;
        written.npy = NpySet();
        remove_journal(journal.dir, d);
        return "";
    }
    const NpyRange range{path, 0, 0};
    bool grown = false;
    std::string why = failure_of([&] { grown = grow_npy_set(range, d, written.npy); });
    if (!why.empty() || grown) return why;
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
    const std::vector<Dataset> sets = datasets_of(d);
    std::vector<std::pair<std::string, std::string>> contents;
    for (const Dataset &set : sets) contents.push_back({set.name + ".npy", npy_file(set.array)});
    contents.push_back({"attributes.json", json});
    why = failure_of([&] { replace_npy_set(range, d, contents, written.npy); });
    if (!why.empty()) return why;
    // gnuplot, run in the output directory, reads the snapshots by this name.
    written.bytes = {o.scene + "/" + sets.back().name + ".npy", npy_header(sets.back().array).size()};
    return "";
}

namespace {

// Data that is there but cannot be read back: refused (status 1), for the
// run would replace it, and the rows and snapshots in it would be lost.
int unreadable(const RunOptions &o, int64_t start, const std::string &why, std::string &refusal) {
    refusal = format("lpi run: --resume: the data %s cannot be read back (%s): resumed, the run would "
                     "replace it, and the rows and snapshots %s in it would be lost; move it aside "
                     "(or remove it) to resume without them",
                     data_path(o).c_str(), why.c_str(),
                     start < 0 ? "" : format("up to step %lld", static_cast<long long>(start)).c_str());
    return 1;
}

}  // namespace

int read_data_record(const RunOptions &o, const RunData &d, DataRecord &record, std::string &refusal) {
    refusal.clear();
    record = DataRecord();
    // No file of the data there (a run killed before it wrote any): nothing
    // to keep, and nothing that writing the data replaces.
    for (const std::string &file : data_files(o, d)) {
        struct stat st;
        if (stat(file.c_str(), &st) == 0 || errno != ENOENT) record.there = true;
    }
    if (!record.there) return 0;
    for (auto *array : {&record.steps, &record.times, &record.energies, &record.casimirs}) {
        const char *name = array == &record.steps ? "step" : array == &record.times ? "time"
                           : array == &record.energies                              ? "energy"
                                                                                    : "casimirs";
        const std::string wrong = read_data_array(o, name, false, *array);
        if (!wrong.empty()) return unreadable(o, -1, wrong, refusal);
    }
    const std::size_t width = d.casimir_count;
    if (record.casimirs.shape.size() != 2 || record.casimirs.shape[1] != width)
        return unreadable(o, -1, format("its casimirs are not rows of %zu values", width), refusal);
    for (const char *name : {"scene", "method"}) record.attributes.push_back({name, "", 0.0, true});
    for (const char *name : {"dt", "every", "snapshot_every"}) record.attributes.push_back({name, "", 0.0, false});
    const std::string wrong =
        o.format == "h5" ? read_hdf5_attributes(data_path(o), record.attributes, record.found)
                         : read_json_attributes(data_path(o) + "/attributes.json", record.attributes, record.found);
    if (!wrong.empty()) return unreadable(o, -1, wrong, refusal);
    return 0;
}

int data_rows_up_to(const RunOptions &o, int64_t start, const RunData &d, const DataRecord &record,
                    std::vector<KeptRow> &rows, std::string &refusal) {
    refusal.clear();
    rows.clear();
    const std::size_t width = d.casimir_count;
    const std::vector<double> &steps = record.steps.values, &times = record.times.values,
                              &energies = record.energies.values, &casimirs = record.casimirs.values;
    // A set that a kill cut between two of its files' renames (write_data)
    // holds the arrays of two consecutive writes, of different lengths, which
    // agree on every row and snapshot up to the checkpoint's step: only those
    // are read, and each array must hold them.
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const double step = steps[i], before = i ? steps[i - 1] : -1.0;
        if (!(step >= 0.0 && step < 0x1p62 && step == std::trunc(step) && step > before))
            return unreadable(o, start, format("its row %zu has no whole step in order", i), refusal);
        if (step > static_cast<double>(start)) break;
        if (i >= times.size() || i >= energies.size() || (i + 1) * width > casimirs.size())
            return unreadable(o, start, format("its arrays end before its row at step %.17g", step), refusal);
        KeptRow row;
        row.step = static_cast<int64_t>(step);
        row.time = times[i];
        row.energy = energies[i];
        row.casimirs.assign(casimirs.begin() + static_cast<std::ptrdiff_t>(i * width),
                            casimirs.begin() + static_cast<std::ptrdiff_t>((i + 1) * width));
        rows.push_back(std::move(row));
    }
    return 0;
}

bool data_there(const RunOptions &o, const RunData &d, std::string &other) {
    other.clear();
    auto exists = [](const std::string &path) {
        struct stat st;
        return stat(path.c_str(), &st) == 0 || errno != ENOENT;
    };
    RunOptions h5 = o, npy = o;
    h5.format = "h5";
    npy.format = "npy";
    bool there = false;
    for (const RunOptions *format : {&h5, &npy}) {
        bool this_one = exists(data_path(*format)) || (format == &h5 && exists(journal_path(*format)));
        for (const std::string &file : data_files(*format, d)) this_one = this_one || exists(file);
        if (this_one && format->format != o.format && other.empty()) other = data_path(*format);
        there = there || this_one;
    }
    return there;
}

int keep_snapshots(const RunOptions &o, int64_t start, const std::string &not_kept, RunData &d,
                   std::string &refusal) {
    refusal.clear();
    std::string why = not_kept;  // why the data's snapshots are not this run's
    Array steps, times, shots;
    for (auto *array : {&steps, &times, &shots}) {
        if (!why.empty()) break;
        const char *name = array == &steps ? "snapshot_step" : array == &times ? "snapshot_time"
                           : d.vorticity                   ? "vorticity"
                                                           : "state";
        const std::string wrong = read_data_array(o, name, true, *array);
        if (!wrong.empty()) return unreadable(o, start, wrong, refusal);
    }
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
            return unreadable(o, start, format("its snapshot %zu has no whole step in order or no finite time", k),
                              refusal);
    }
    if (!why.empty()) {
        std::printf("%s: %s; the data keeps the snapshots from step %lld on\n", data_path(o).c_str(),
                    why.c_str(), static_cast<long long>(start));
        return 0;
    }
    d.snapshot_step.assign(steps.values.begin(), steps.values.begin() + static_cast<std::ptrdiff_t>(n));
    d.snapshot_time.assign(times.values.begin(), times.values.begin() + static_cast<std::ptrdiff_t>(n));
    d.snapshots.assign(shots.values.begin(), shots.values.begin() + static_cast<std::ptrdiff_t>(n * size));
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


std::string vorticity_script_name(const std::string &scene) { return scene + "_vorticity.gp"; }

bool is_vorticity_image(const std::string &scene, const std::string &name) {
    const std::string prefix = scene + "_vorticity_";
    const std::string suffix = name.size() > 4 ? name.substr(name.size() - 4) : "";
    return name.rfind(prefix, 0) == 0 && (suffix == ".png" || suffix == ".svg") &&
           name.size() > prefix.size() + 4 &&
           name.find_first_not_of("0123456789", prefix.size()) == name.size() - 4;
}

namespace {

// The image of this scene's snapshot at `step`, without its .png or .svg:
// SCENE_vorticity_STEP, named by the scene as its CSV and data are, so that
// scenes run into one --out each keep their own.
std::string vorticity_image(const std::string &scene, int64_t step) {
    return format("%s_vorticity_%06lld", scene.c_str(), static_cast<long long>(step));
}

// The script that draws every vorticity snapshot of the data as PNG and SVG
// with gnuplot, which reads the doubles straight from the data file.
PlotScript vorticity_script(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                            const std::string &method) {
    const std::size_t N = d.snapshot_shape[0], shots = d.snapshot_step.size();
    double scale = 0.0;  // one symmetric colour range for every snapshot
    for (double v : d.snapshots) scale = std::max(scale, std::fabs(v));
    if (!(scale > 0.0)) scale = 1.0;
    PlotScript script(o.out_dir, vorticity_script_name(o.scene));
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
        const int64_t row = static_cast<int64_t>(d.snapshot_step[k]);
        const std::string name = vorticity_image(o.scene, row);
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
    return script;
}

}  // namespace

std::string match_drawings(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                           const std::string &method) {
    std::set<std::string> drawn;
    for (double step : d.snapshot_step)
        for (const char *suffix : {".png", ".svg"})
            drawn.insert(vorticity_image(o.scene, static_cast<int64_t>(step)) + suffix);
    // The images the script of this scene's last run drew (its name and its
    // titles name the scene) that this data does not, and only those named
    // SCENE_vorticity_STEP: another scene's in the same --out, the unprefixed
    // vorticity_STEP images of earlier versions and images lpi did not write
    // are not this run's to remove.
    std::string why, old_script;
    struct stat st;
    const std::string script_path = o.out_dir + "/" + vorticity_script_name(o.scene);
    if (stat(script_path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && read_input(script_path, old_script).empty() &&
        old_script.find("\nset title '" + o.scene + ", ") != std::string::npos) {
        const std::string prefix = "set output '";
        for (std::size_t from = 0; from < old_script.size();) {
            std::size_t end = old_script.find('\n', from);
            if (end == std::string::npos) end = old_script.size();
            const std::string line = old_script.substr(from, end - from);
            from = end + 1;
            if (line.rfind(prefix, 0) != 0 || line.size() < prefix.size() + 1 || line.back() != '\'') continue;
            const std::string name = line.substr(prefix.size(), line.size() - prefix.size() - 1);
            if (is_vorticity_image(o.scene, name) && !drawn.count(name) &&
                unlink((o.out_dir + "/" + name).c_str()) != 0 && errno != ENOENT && why.empty())
                why = "cannot remove " + o.out_dir + "/" + name + ": " + std::strerror(errno);
        }
    }
    const std::string &script = script_path;
    if (d.snapshot_step.empty() || bytes.offset == UINT64_MAX) {
        if (unlink(script.c_str()) != 0 && errno != ENOENT && why.empty())
            why = "cannot remove " + script + ": " + std::strerror(errno);
        return why;
    }
    const std::string not_saved = vorticity_script(o, d, bytes, dt, method).save_script();
    return why.empty() ? not_saved : why;
}

std::string plot_vorticity(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                           const std::string &method) {
    if (d.snapshot_step.empty() || bytes.offset == UINT64_MAX) return "no snapshot data to draw from in " + data_path(o);
    return vorticity_script(o, d, bytes, dt, method).draw();
}

}  // namespace lpi_cli
