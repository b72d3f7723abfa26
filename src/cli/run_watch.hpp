// What watches an lpi run while it steps: Ctrl-C and SIGTERM, and a progress
// bar, both reached through the library's step observer.
#pragma once

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <string>

#include <liepoisson.h>

namespace lpi_cli {

// Set by SIGINT or SIGTERM; the observer then stops the steps (watch_steps).
extern volatile std::sig_atomic_t interrupted_by;

// One shot: a second Ctrl-C ends the command at once (SA_RESETHAND).
void catch_interrupts();

// lpi report's way out at SIGINT or SIGTERM: thrown where its work can stop
// (between runs, and after a run that stop_at_signal stopped) and caught by
// the command, which exits 128 + the signal. A scene writes its files at its
// end, all or none (PlotScript), so the interrupted one keeps the last
// report's.
struct Interrupted {};
inline void stop_if_interrupted() {
    if (interrupted_by) throw Interrupted{};
}
// An observer that stops lpi_step at a signal (LPI_STOPPED), for the runs
// that are not timed.
extern "C" int stop_at_signal(const lpi_system *, int64_t step, double, void *);

// After a signal that came while the images of a finished run were drawn
// (gnuplot is ended then, PlotScript::draw): says whether they were, and
// returns the exit status, 128 + the signal's number.
int interrupted_drawing(bool drawn, const std::string &script);

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

// The observer lpi run sets (user: the Watch): stops at a signal, else moves
// the progress bar on.
extern "C" int watch_steps(const lpi_system *, int64_t step, double, void *user);

// Observed every this many steps: about 64 piece flows apart, so the extra
// flow an observation costs (the seam it unmerges) stays near 1.5%.
int64_t observation_interval(const lpi_system *sys);

}  // namespace lpi_cli
