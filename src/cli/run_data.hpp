// lpi run's output: the data it keeps (rows and snapshots) written as HDF5 or
// .npy, read back when a run is resumed, the --init grid, and the vorticity
// snapshots drawn with gnuplot.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "../core/files.hpp"
#include "data_files.hpp"
#include "plots.hpp"
#include "run_options.hpp"

namespace lpi_cli {

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
    std::vector<double> topography;  // N x N: the scene's h, or none

    std::size_t snapshot_size() const {
        std::size_t n = 1;
        for (std::size_t d : snapshot_shape) n *= d;
        return n;
    }
    // Data of the same shapes (Casimirs, snapshots) without rows or snapshots.
    static RunData shaped_like(const RunData &d) {
        RunData shaped;
        shaped.casimir_count = d.casimir_count;
        shaped.snapshot_shape = d.snapshot_shape;
        shaped.vorticity = d.vorticity;
        shaped.topography = d.topography;
        return shaped;
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

// Where the snapshots' raw doubles start in the written data (for gnuplot).
struct SnapshotBytes {
    std::string file;  // relative to the output directory
    std::uint64_t offset = UINT64_MAX;
};

// A set of .npy files as lpi left it: each growing array's file (in
// growing_arrays' order, run_data.cpp) and the rows and snapshots it holds.
struct NpySet {
    std::vector<lpi::FileIdentity> files;
    std::size_t rows = 0, shots = 0;
};

// What the last write_data left: where the snapshots are, the .npy set (the
// data, or the HDF5 file's journal) and the rows and snapshots the HDF5
// file holds, so that the next write grows the files in place.
struct WrittenData {
    SnapshotBytes bytes;
    NpySet npy;
    bool h5_written = false;
    std::size_t h5_rows = 0, h5_shots = 0;
};

// Where a run's data lives: DIR/SCENE.h5, or the folder DIR/SCENE of .npy files.
std::string data_path(const RunOptions &o);

// Every file of a run's data: DIR/SCENE.h5, or the .npy files and
// attributes.json in DIR/SCENE.
std::vector<std::string> data_files(const RunOptions &o, const RunData &d);

// Writes the data, so that a write costs the rows and snapshots since the
// last, not all of them again (which made a run of n checkpoints cost n^2):
//  - .npy: the files and their attributes.json as one set, replaced whole
//    the first time, then grown in place (each growing array's values
//    appended, then its header's length; a failure puts every file back);
//  - HDF5: the file atomically (output.hpp) the first time, when `final`
//    (the run's end, however it ends), and whenever the rows and snapshots
//    since hold as many values as it does; in between, those are its journal
//    (journal_path), .npy files grown in place, which keep_snapshots reads
//    with the file, and which the next whole write removes.
// "" or the reason.
std::string write_data(const RunOptions &o, const RunData &d, const std::vector<Attribute> &attributes,
                       WrittenData &written, bool final);

// The folder of an HDF5 file's journal: DIR/SCENE.h5-pending.
std::string journal_path(const RunOptions &o);

// The folders lpi run writes its data in (their files named by it, and its
// temporary ones): the HDF5 file's journal, or the folder of .npy files.
std::vector<std::string> data_folders(const RunOptions &o);

// A row of the CSV and of the data (rows x Casimirs there): what a resumed
// run keeps of the interrupted one.
struct KeptRow {
    int64_t step = 0;
    double time = 0.0, energy = 0.0;
    std::vector<double> casimirs;
};

// The interrupted run's data as a resumed run reads it back: whether any
// file of it is there, its row arrays (step, time, energy, casimirs) as read,
// and the attributes it records (scene, method, dt, every, snapshot_every),
// those found listed in `found`.
struct DataRecord {
    bool there = false;
    Array steps, times, energies, casimirs;
    std::vector<Attribute> attributes;
    std::vector<std::string> found;
    const Attribute *attribute(const std::string &name) const {
        for (const std::string &f : found)
            if (f == name)
                for (const Attribute &a : attributes)
                    if (a.name == name) return &a;
        return nullptr;
    }
};

// Reads the row arrays and the attributes of the interrupted run's data
// (shaped as `d`). Returns 0, or 1 with the message in `refusal` when data is
// there but cannot be read back (damaged, or over the readers' cap of 2^28
// values per array): the run would replace it, and lose it.
int read_data_record(const RunOptions &o, const RunData &d, DataRecord &record, std::string &refusal);

// The rows of `record` up to `start` into `rows` (only those are checked: a
// .npy set that a kill cut between the renames of its files holds arrays of
// two writes, which agree up to the checkpoint's step). Returns 0, or 1 with
// the message in `refusal` as read_data_record.
int data_rows_up_to(const RunOptions &o, int64_t start, const RunData &d, const DataRecord &record,
                    std::vector<KeptRow> &rows, std::string &refusal);

// Whether a file of the run's data is there in either --format (HDF5, its
// journal, or the folder of .npy files), and the path of one in the other
// format than this run's in `other` (empty: none).
bool data_there(const RunOptions &o, const RunData &d, std::string &other);

// The snapshots of the interrupted run up to `start`, from its data, where
// its rows are this run's (`not_kept` empty); otherwise a note on stdout
// saying why not (`not_kept`: no data, another run's). Returns 0, or 1 with
// the message in `refusal` when the snapshots cannot be read back.
int keep_snapshots(const RunOptions &o, int64_t start, const std::string &not_kept, RunData &d,
                   std::string &refusal);

// The initial grid of --init into `grid`, checked against the system's N:
// 0, or the exit status with the message in `why` (each process reads the
// file, and lpi run agrees on the outcome): 1 when the file cannot be read,
// 2 when it holds no N x N grid for this run.
int initial_grid(const std::string &path, int *N, std::vector<double> &grid, std::string &why);

// The name of the script that draws a scene's snapshots, in --out:
// SCENE_vorticity.gp. Its images are SCENE_vorticity_STEP.png and .svg,
// named by the scene as its CSV and data are.
std::string vorticity_script_name(const std::string &scene);

// Whether `name` (a file name, no directory) is one of the scene's snapshot
// images: SCENE_vorticity_ followed by digits and .png or .svg.
bool is_vorticity_image(const std::string &scene, const std::string &name);

// Puts what is drawn from the data in step with it once it is written: the
// images that DIR/SCENE_vorticity.gp, where it is this scene's, drew of steps
// the data holds no snapshot of are removed (only SCENE_vorticity_STEP images:
// not another scene's, nor the unprefixed vorticity_STEP ones of earlier
// versions), and DIR/SCENE_vorticity.gp is written for it (removed where it
// holds no snapshot): gnuplot reads the snapshots at their byte offset, and a
// script or images left by an earlier run drew another run's data. "" or why
// not.
std::string match_drawings(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                           const std::string &method);

// Draws every vorticity snapshot of the data as PNG and SVG with gnuplot,
// which reads the doubles straight from the data file (nothing is copied
// and nothing deleted): "" or why not.
std::string plot_vorticity(const RunOptions &o, const RunData &d, const SnapshotBytes &bytes, double dt,
                           const std::string &method);

}  // namespace lpi_cli
