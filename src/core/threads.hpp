// Thread counts: the bound every system shares, and the check that keeps the
// OpenMP runtime from ending the process. libgomp calls exit() when it cannot
// create a thread of a team ("Thread creation failed"), so before a parallel
// region could need new threads on the calling thread the library starts and
// joins the same number of threads itself, where a refusal is a status.
#pragma once

#include <string>

namespace lpi {

// Threads per processor a system may use at most: enough for any sensible
// oversubscription, while bounding the scratch memory kept per thread.
constexpr int kMaxThreadsPerProcessor = 4;

// kMaxThreadsPerProcessor x the processors available to the process.
int max_threads();

// Throws LPI_ERR_INVALID unless 1 <= n <= max_threads(), naming the bound.
void check_thread_count(int n);

// Makes an OpenMP team of n threads safe to start on the calling thread: when
// the runtime may need to create threads for it (this thread has not yet run
// a team of n through here since its last larger one), starts n - 1 threads
// with the stack size OpenMP uses and joins them, then starts the team once
// so the runtime keeps its threads. Throws LPI_ERR_NO_MEMORY, naming the
// cause, when the system refuses a thread. Without OpenMP, or n <= 1, nothing.
void prepare_thread_team(int n);

// The threads a team asked for n may have on the calling thread now: 1 where
// its OpenMP pool was lost to a fork(2) since the call prepared it (an
// observer that forks in the middle of a step: the child's team would wait
// for ever), else n. Results are the same for every thread count.
int team_size_here(int n);

// Starts `count` threads (default stack size) that all exist at once and
// joins them: for a library that starts as many when it is loaded, and ends
// the process when the system refuses one (a threaded OpenBLAS). Throws
// LPI_ERR_NO_MEMORY, saying that for_what needs them, when the system refuses,
// with `advice` (what starts them, how to ask for fewer) at the end.
void require_threads_can_start(int count, const std::string &for_what, const std::string &advice);

}  // namespace lpi
