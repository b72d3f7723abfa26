// FFTW behind the LineTransforms interface, the grid transforms and wisdom.
#include "transforms.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <new>

#include <pthread.h>


#include "../../core/error.hpp"
#include "../../core/files.hpp"
#include "../../core/headroom.hpp"
#include "../../core/text.hpp"
#include "../sine_euler.hpp"
#include "lpi_config.h"
#include "kernels.hpp"
#include "projective_line.hpp"

#if LPI_HAVE_FFTW
#include <fftw3.h>
#endif

#if LPI_HAVE_FFTW_PLANNER_HOOKS
// Exported by libfftw3 since 3.3.5 (what fftw_make_planner_thread_safe of
// libfftw3_threads installs its lock with), not declared in fftw3.h.
extern "C" void fftw_set_planner_hooks(void (*before)(void), void (*after)(void));
#endif

namespace lpi {

namespace {

// The lock's owner is a thread id, which the child of a fork(2) does not
// have, and a thread may fork from a signal handler while it holds the
// lock: so the fork waits for other threads' planning (the child gets a
// planner no thread was changing), the child gets a fresh lock, held as
// often as its thread held it, and the parent's is released.
std::recursive_mutex &planner_mutex() {
    static std::recursive_mutex mutex;
    return mutex;
}
thread_local int planner_depth = 0;  // this thread's holds
thread_local bool locked_for_fork = false;  // by this thread's prepare handler
void lock_before_fork() {
    locked_for_fork = planner_depth == 0;
    if (locked_for_fork) planner_mutex().lock();
}
void unlock_in_parent() {
    if (locked_for_fork) planner_mutex().unlock();
}
void renew_in_child() {
    new (&planner_mutex()) std::recursive_mutex;
    for (int i = 0; i < planner_depth; ++i) planner_mutex().lock();
}

#if LPI_HAVE_FFTW_PLANNER_HOOKS
// FFTW's planner is the process's: a host planning on another thread beside
// the library corrupted its heap ("double free"). FFTW calls these around
// every plan and destroy_plan, whoever calls them. An `after` whose `before`
// ran before they were installed (a host's plan under way as the library
// loads) finds no hold of its thread to release.
void before_planner() { fftw_planner_lock().lock(); }
void after_planner() {
    if (planner_depth > 0) fftw_planner_lock().unlock();
}
#endif

[[maybe_unused]] const bool planner_lock_installed = [] {
    pthread_atfork(lock_before_fork, unlock_in_parent, renew_in_child);
#if LPI_HAVE_FFTW_PLANNER_HOOKS
    fftw_set_planner_hooks(before_planner, after_planner);
#endif
    return true;
}();

}  // namespace

void FftwPlannerLock::lock() {
    planner_mutex().lock();
    ++planner_depth;
}

void FftwPlannerLock::unlock() {
    --planner_depth;
    planner_mutex().unlock();
}

FftwPlannerLock &fftw_planner_lock() {
    static FftwPlannerLock lock;
    return lock;
}

namespace {
constexpr const char *kPlanningNames[] = {"estimate", "measure", "patient"};
}  // namespace

std::size_t fftw_planning_headroom(int N) {
    return std::max<std::size_t>(std::size_t{4} << 20, std::size_t{2048} * static_cast<std::size_t>(N));
}

void require_fftw_execution_headroom(int N, int threads) {
    // Below 64 KiB FFTW's execution buffers are heap blocks of the sizes the
    // last execution freed, found again without growing the heap; a mapping
    // per call would cost a small system more than its check is worth (5 us
    // a call in a VM, where a step at N = 7 takes 5 us).
    const std::size_t bytes =
        std::size_t{1024} * static_cast<std::size_t>(N) * static_cast<std::size_t>(std::max(threads, 1));
    if (bytes < (std::size_t{64} << 10)) return;
    require_fftw_headroom(bytes, "the flows' transforms of length " + std::to_string(N));
}

void require_fftw_headroom(std::size_t bytes, const std::string &what) {
    if (!address_space_available(bytes))
        fail(LPI_ERR_NO_MEMORY, "FFTW may take " + std::to_string(bytes) + " bytes for " + what +
                                    ", which this process cannot have (FFTW ends the process when its "
                                    "own allocation fails, so it is not called)");
}

const char *planning_name(FftPlanning planning) { return kPlanningNames[static_cast<int>(planning)]; }

FftPlanning planning_from_name(const std::string &name) {
    for (int i = 0; i < 3; ++i)
        if (name == kPlanningNames[i]) return static_cast<FftPlanning>(i);
    fail(LPI_ERR_INVALID, "unknown FFTW planning " + quoted(name) + " (estimate, measure or patient)");
}

#if LPI_HAVE_FFTW

namespace sine_euler {

namespace {
fftw_complex *complex_of(double *x) { return reinterpret_cast<fftw_complex *>(x); }

unsigned planner_flags(FftPlanning planning) {
    switch (planning) {
    case FftPlanning::Measure: return FFTW_MEASURE;
    case FftPlanning::Patient: return FFTW_PATIENT;
    case FftPlanning::Estimate: break;
    }
    return FFTW_ESTIMATE;
}
}  // namespace

struct LineTransforms::Plans {
    fftw_plan spectrum = nullptr;
    fftw_plan forward[2] = {nullptr, nullptr};  // [0]: full block, [1]: remainder
    fftw_plan backward[2] = {nullptr, nullptr};
};

LineTransforms::LineTransforms(int N, int lines, FftPlanning planning)
    : N_(N), lines_(lines), plans_(new Plans) {
    try {
        spectrum_ = reinterpret_cast<double *>(fftw_alloc_complex(N));
        phase_ = static_cast<double *>(fftw_malloc(sizeof(double) * phase_table_doubles(N)));
        if (!spectrum_ || !phase_) throw std::bad_alloc();
        handover_.reset(new std::atomic<int>[static_cast<std::size_t>((lines + kBlock - 1) / kBlock + 1)]);
        reserve_threads(1);
        require_fftw_headroom(fftw_planning_headroom(N), "the plans of length " + std::to_string(N));
        std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
        const unsigned flags = planner_flags(planning);
        fftw_complex *b = complex_of(spectrum_), *x = complex_of(blocks_[0]);
        // The spectrum is one FFT per flow: planned by the heuristic always,
        // so that processes sharing a field compute the same phases.
        plans_->spectrum = fftw_plan_dft_1d(N, b, b, FFTW_FORWARD, FFTW_ESTIMATE);
        const int sizes[2] = {lines_ >= kBlock ? kBlock : 0, lines_ % kBlock};
        for (int i = 0; i < 2; ++i) {
            const int howmany = sizes[i];
            if (howmany == 0) continue;
            // Transform along s (stride howmany); the lines of a block are
            // adjacent, as gathered from a row.
            plans_->forward[i] = fftw_plan_many_dft(1, &N, howmany, x, nullptr, howmany, 1, x, nullptr,
                                                    howmany, 1, FFTW_FORWARD, flags);
            plans_->backward[i] = fftw_plan_many_dft(1, &N, howmany, x, nullptr, howmany, 1, x,
                                                     nullptr, howmany, 1, FFTW_BACKWARD, flags);
            if (!plans_->forward[i] || !plans_->backward[i]) break;
        }
    } catch (...) {
        release();
        throw;
    }
    if (!plans_->spectrum || (lines_ >= kBlock && !plans_->forward[0]) ||
        (lines_ % kBlock && !plans_->forward[1])) {
        release();
        fail(LPI_ERR_INTERNAL, "FFTW could not create a plan for N = " + std::to_string(N));
    }
}

LineTransforms::~LineTransforms() { release(); }

void LineTransforms::release() {
    std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
    if (plans_)
        for (fftw_plan p : {plans_->spectrum, plans_->forward[0], plans_->forward[1],
                            plans_->backward[0], plans_->backward[1]})
            if (p) fftw_destroy_plan(p);
    plans_.reset();
    fftw_free(spectrum_);
    fftw_free(phase_);
    for (double *x : blocks_) fftw_free(x);
    spectrum_ = phase_ = nullptr;
    blocks_.clear();
}

void LineTransforms::reserve_threads(std::size_t threads) {
    const std::size_t buffers = threads > 1 ? 2 * threads : 1;
    // The slot first: a push_back that threw after the buffer was allocated
    // would leave the buffer owned by nothing.
    if (blocks_.capacity() < buffers) blocks_.reserve(buffers);
    while (blocks_.size() < buffers) {
        fftw_complex *x = fftw_alloc_complex(static_cast<std::size_t>(N_) * kBlock);
        if (!x) throw std::bad_alloc();
        blocks_.push_back(reinterpret_cast<double *>(x));
    }
}

void LineTransforms::transform_spectrum() {
    fftw_execute_dft(plans_->spectrum, complex_of(spectrum_), complex_of(spectrum_));
}

void LineTransforms::forward(int lines, double *block) {
    fftw_execute_dft(plans_->forward[lines == kBlock ? 0 : 1], complex_of(block), complex_of(block));
}

void LineTransforms::backward(int lines, double *block) {
    fftw_execute_dft(plans_->backward[lines == kBlock ? 0 : 1], complex_of(block), complex_of(block));
}

namespace {

// A 2D DFT of N x N complex values, in place, with a plan of its own.
void dft_2d(int N, fftw_complex *buffer, int sign) {
    require_fftw_headroom(fftw_planning_headroom(N),
                          "the grid's " + std::to_string(N) + " x " + std::to_string(N) + " transform");
    fftw_plan plan;
    {
        std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
        plan = fftw_plan_dft_2d(N, N, buffer, buffer, sign, FFTW_ESTIMATE);
    }
    fftw_execute(plan);
    std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
    fftw_destroy_plan(plan);
}

struct FftwBuffer {
    fftw_complex *data;
    explicit FftwBuffer(std::size_t n) : data(fftw_alloc_complex(n)) {
        if (!data) throw std::bad_alloc();
    }
    ~FftwBuffer() { fftw_free(data); }
};

}  // namespace

namespace {

// A transform's sums of n values reach n times the largest: values beyond
// DBL_MAX / (2n) are scaled by a power of two below 1 / (2n) before it and
// back after, both exact (but for parts below the largest by 2^-1000). The
// exponent of that power, 0 where none is needed.
int transform_shift(const double *values, std::size_t count, std::size_t n) {
    double largest = 0.0;
    for (std::size_t i = 0; i < count; ++i) largest = std::max(largest, std::fabs(values[i]));
    if (largest > std::numeric_limits<double>::max() / (2.0 * static_cast<double>(n)))
        return std::ilogb(static_cast<double>(n)) + 2;
    return 0;
}

}  // namespace

// A finite grid's values can lie close to DBL_MAX where no mode does (a
// checkerboard of +-0.75 DBL_MAX at N = 9 was read back as an overflow).
void grid_from_modes(int N, const double *modes, double *grid) {
    const std::size_t n = static_cast<std::size_t>(N) * N;
    const int shift = transform_shift(modes, 2 * n, n);
    FftwBuffer buffer(n);
    if (shift == 0) {
        std::memcpy(buffer.data, modes, sizeof(fftw_complex) * n);
    } else {
        for (std::size_t i = 0; i < n; ++i) {
            buffer.data[i][0] = std::ldexp(modes[2 * i], -shift);
            buffer.data[i][1] = std::ldexp(modes[2 * i + 1], -shift);
        }
    }
    dft_2d(N, buffer.data, FFTW_BACKWARD);
    for (std::size_t i = 0; i < n; ++i) grid[i] = std::ldexp(buffer.data[i][0], shift);
}

void modes_from_grid(int N, const double *grid, double *modes) {
    const std::size_t n = static_cast<std::size_t>(N) * N;
    // No mode exceeds max |grid|, but the transform's sums, divided by n only
    // after it, reach n max |grid| (a uniform 4.2e306 at N = 9 was refused as
    // an overflow).
    const int shift = transform_shift(grid, n, n);
    const double down = std::ldexp(1.0, -shift);
    FftwBuffer buffer(n);
    for (std::size_t i = 0; i < n; ++i) buffer.data[i][0] = grid[i] * down, buffer.data[i][1] = 0.0;
    dft_2d(N, buffer.data, FFTW_FORWARD);
    const double scale = 1.0 / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) {
        modes[2 * i] = std::ldexp(buffer.data[i][0] * scale, shift);
        modes[2 * i + 1] = std::ldexp(buffer.data[i][1] * scale, shift);
    }
}

}  // namespace sine_euler

namespace {

// Far beyond any wisdom FFTW writes (some hundred bytes a plan): a larger file
// is refused before it is read into memory.
constexpr std::size_t kMaxWisdomBytes = std::size_t{64} << 20;

}  // namespace

// Read as a regular file only (a FIFO is refused, not waited on), then
// imported as a string.
void fftw_wisdom_import_file(const char *path) {
    RegularFileReader file(path);
    if (file.size() > kMaxWisdomBytes)
        fail(LPI_ERR_INVALID, quoted(path) + " is not FFTW wisdom: " +
                                  std::to_string(file.size()) + " bytes, more than wisdom takes");
    // Bounded by what is read, not by the size the file reports: a file of
    // /proc reports 0 bytes and may not end (/proc/self/pagemap).
    const std::string text = file.read_rest(kMaxWisdomBytes);
    if (text.size() > kMaxWisdomBytes)
        fail(LPI_ERR_INVALID, quoted(path) + " is not FFTW wisdom: more than " +
                                  std::to_string(kMaxWisdomBytes) + " bytes, more than wisdom takes");
    require_fftw_headroom(fftw_planning_headroom(0) + 8 * text.size(), "its wisdom");
    std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
    if (text.find('\0') != std::string::npos || !fftw_import_wisdom_from_string(text.c_str()))
        fail(LPI_ERR_INVALID, quoted(path) + " is not FFTW wisdom");
}

// Written atomically, as checkpoints are: a failed export keeps the old file.
void fftw_wisdom_export_file(const char *path) {
    const std::string wisdom = fftw_wisdom_export_string();
    write_file_atomically(path, reinterpret_cast<const unsigned char *>(wisdom.data()), wisdom.size());
}

void fftw_wisdom_import_string(const char *wisdom) {
    require_fftw_headroom(fftw_planning_headroom(0) + 8 * std::strlen(wisdom), "its wisdom");
    std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
    if (!fftw_import_wisdom_from_string(wisdom))
        fail(LPI_ERR_INVALID, "the string is not valid FFTW wisdom");
}

std::string fftw_wisdom_export_string() {
    char *text;
    require_fftw_headroom(fftw_planning_headroom(0), "its wisdom");
    {
        std::lock_guard<FftwPlannerLock> lock(fftw_planner_lock());
        text = fftw_export_wisdom_to_string();
    }
    if (!text) throw std::bad_alloc();
    std::string wisdom(text);
    std::free(text);
    return wisdom;
}

#else  // !LPI_HAVE_FFTW

namespace {
[[noreturn]] void no_fftw(const char *what = "FFTW wisdom") {
    fail(LPI_ERR_UNSUPPORTED, std::string(what) + " needs FFTW3; this build has none");
}
}  // namespace

namespace sine_euler {
void grid_from_modes(int, const double *, double *) { no_fftw("the sine-Euler grid"); }
void modes_from_grid(int, const double *, double *) { no_fftw("the sine-Euler grid"); }
}  // namespace sine_euler

void fftw_wisdom_import_file(const char *) { no_fftw(); }
void fftw_wisdom_export_file(const char *) { no_fftw(); }
void fftw_wisdom_import_string(const char *) { no_fftw(); }
std::string fftw_wisdom_export_string() { no_fftw(); }

#endif  // LPI_HAVE_FFTW

}  // namespace lpi
