// The transforms of the sine-Euler line flows, behind a small interface so
// that another backend (MPI, GPU) can replace them and keep the geometry and
// the kernels: FFTW plans and aligned buffers, created once per system, for
// the spectrum of one direction's line through the origin (length N) and for
// a block of lines (kBlock, or the remainder, transforms of length N along s,
// stride the block's line count). Plan creation, destruction and wisdom hold
// fftw_planner_lock(). Everything here needs FFTW3 except the wisdom
// functions, which refuse with LPI_ERR_UNSUPPORTED in a build without it.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "../sine_euler.hpp"

namespace lpi {
namespace sine_euler {

class LineTransforms {
public:
    // Plans at the given rigor and buffers for `lines` lines of length N (the
    // (N - 1) / 2 integrated lines of a direction, or one process's share of
    // them), with one block buffer.
    LineTransforms(int N, int lines, FftPlanning planning);
    ~LineTransforms();
    LineTransforms(const LineTransforms &) = delete;
    LineTransforms &operator=(const LineTransforms &) = delete;

    // The block buffers (N * kBlock complex each) of a flow on `threads`
    // threads: one, or a ring of two per thread (see run_line_flows).
    void reserve_threads(std::size_t threads);
    std::size_t buffers() const { return blocks_.size(); }
    // The line spectrum b: N complex (interleaved), transformed in place.
    double *spectrum() { return spectrum_; }
    void transform_spectrum();
    // The phase tables (phase_table_doubles(N); see write_phase).
    double *phase() { return phase_; }
    // Block buffer of a thread, and its forward / backward transform in place
    // for a block of `lines` lines (kBlock, or the remainder M mod kBlock).
    double *block(std::size_t thread) { return blocks_[thread]; }
    void forward(int lines, double *block);
    void backward(int lines, double *block);
    // One flag per block of lines, for handing blocks between threads
    // (run_line_flows): allocated with the plans, so that a flow allocates
    // nothing.
    std::atomic<int> *handover() { return handover_.get(); }

private:
    struct Plans;
    void release();
    int N_, lines_;
    std::unique_ptr<Plans> plans_;
    double *spectrum_ = nullptr, *phase_ = nullptr;
    std::vector<double *> blocks_;
    std::unique_ptr<std::atomic<int>[]> handover_;
};

// The 2D DFTs between the mode array (2 N^2 doubles) and the real grid:
// grid[a N + b] = Re sum_m w_m exp(2 pi i (m1 a + m2 b) / N), and its inverse
// modes = (1 / N^2) sum_x grid_x exp(-2 pi i (m . x) / N).
void grid_from_modes(int N, const double *modes, double *grid);
void modes_from_grid(int N, const double *grid, double *modes);

}  // namespace sine_euler

// FFTW wisdom of the process. A file that cannot be opened, read or written
// is LPI_ERR_IO (naming the path and the system's reason); text that is not
// wisdom is LPI_ERR_INVALID.
void fftw_wisdom_import_file(const char *path);
void fftw_wisdom_export_file(const char *path);
void fftw_wisdom_import_string(const char *wisdom);
std::string fftw_wisdom_export_string();

}  // namespace lpi
