#include "run_watch.hpp"

#include <unistd.h>

#include "processes.hpp"

namespace lpi_cli {

volatile std::sig_atomic_t interrupted_by = 0;

namespace {

extern "C" void on_interrupt(int signal_number) { interrupted_by = signal_number; }

}  // namespace

void catch_interrupts() {
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

int interrupted_drawing(bool drawn, const std::string &script) {
    if (drawn)
        std::printf("interrupted after the images were drawn\n");
    else
        // The script is written for the data before drawing (lpi run), or
        // reads it by its columns (rollup): where it is there, it draws them.
        std::printf("interrupted while the images were drawn: none was replaced%s\n",
                    access(script.c_str(), F_OK) == 0 ? (" (" + script + " draws them)").c_str() : "");
    return 128 + interrupted_by;
}

extern "C" int watch_steps(const lpi_system *, int64_t step, double, void *user) {
    Watch *watch = static_cast<Watch *>(user);
    // Every process observes the same steps: they stop at the same one.
    interrupted_by = agreed_signal(interrupted_by);
    if (interrupted_by) {
        watch->stopped_at = watch->call_start + step;
        return 1;
    }
    watch->progress->update(watch->call_start + step);
    return 0;
}

extern "C" int stop_at_signal(const lpi_system *, int64_t, double, void *) { return interrupted_by ? 1 : 0; }

int64_t observation_interval(const lpi_system *sys) {
    std::size_t flows = 0;
    if (lpi_flows_per_step(sys, &flows) != LPI_OK || flows == 0) return 1;
    return static_cast<int64_t>((64 + flows - 1) / flows);
}

}  // namespace lpi_cli
