#include "threads.hpp"

#include <cctype>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "cancellation.hpp"
#include "error.hpp"
#include "lpi_config.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <pthread.h>
#include <unistd.h>

#if LPI_HAVE_OPENMP
#include <omp.h>
#endif

namespace lpi {

int max_threads() {
#if LPI_HAVE_OPENMP
    const int processors = omp_get_num_procs();
#else
    const int processors = static_cast<int>(std::thread::hardware_concurrency());
#endif
    return kMaxThreadsPerProcessor * (processors > 0 ? processors : 1);
}

void check_thread_count(int n) {
    if (n < 1) fail(LPI_ERR_INVALID, "thread count must be >= 1, got " + std::to_string(n));
    const int bound = max_threads();
    if (n > bound)
        fail(LPI_ERR_INVALID, "thread count " + std::to_string(n) + " exceeds " +
                                  std::to_string(bound) + " (" +
                                  std::to_string(kMaxThreadsPerProcessor) +
                                  " x the processors available to the process)");
}

namespace {

#if LPI_HAVE_OPENMP
// The runtime the library's OpenMP calls are bound to is the one that
// counts, not the one it was compiled for: a GCC build calls GOMP_parallel,
// which LLVM's libomp and Intel's libiomp5 also define, and a host program
// built with Clang's -fopenmp (or one that loaded libiomp5 first) binds the
// library's calls to its own runtime. There libomp's thread stacks and
// fork(2) apply, and with libgomp's the probe passed where libomp then
// ended the process ("OMP: Error #34").
using StackSizeQuery = std::size_t (*)();
#if defined(KMP_VERSION_MAJOR)
// A Clang build calls __kmpc_* entries, which only libomp's kind defines.
StackSizeQuery kmp_stack_size_query() { return &kmp_get_stacksize_s; }
#else
// kmp_get_stacksize_s of the object that defines the omp_get_num_procs the
// library is bound to (dladdr of its address, the bound definition), or
// nullptr: libgomp, which has none. Found when the library is loaded, so
// that the fork handler below reads a value and calls nothing.
StackSizeQuery find_kmp_stack_size_query() {
    Dl_info info;
    if (!dladdr(reinterpret_cast<void *>(&omp_get_num_procs), &info) || !info.dli_fname) return nullptr;
    void *runtime = dlopen(info.dli_fname, RTLD_LAZY | RTLD_NOLOAD);
    if (!runtime) return nullptr;
    void *query = dlsym(runtime, "kmp_get_stacksize_s");
    dlclose(runtime);  // the reference RTLD_NOLOAD took; the runtime stays loaded
    return reinterpret_cast<StackSizeQuery>(query);
}
const StackSizeQuery kmp_query = find_kmp_stack_size_query();
StackSizeQuery kmp_stack_size_query() { return kmp_query; }
#endif
bool kmp_runtime() { return kmp_stack_size_query() != nullptr; }

// libomp (or libiomp5): its own stack size (KMP_STACKSIZE, OMP_STACKSIZE,
// else its default), plus 128 bytes for each global thread number below the
// worker's (KMP_STACKOFFSET, doubled). The probe asks a MiB more, enough for
// 8192 thread numbers: a thread stack that glibc keeps cached after the
// probe serves only a request no larger than itself, and a probe that
// passed on cached stacks the runtime cannot use would not stop libomp from
// ending the process.
//
// libgomp: OMP_STACKSIZE, else GOMP_STACKSIZE ("<number>[B|K|M|G]",
// kilobytes by default), read once as libgomp does when it loads; 0 when
// neither is set (default attributes).
std::size_t parse_stack_size(const char *text) {
    if (!text) return 0;
    while (std::isspace(static_cast<unsigned char>(*text))) ++text;
    char *end = nullptr;
    const unsigned long long value = std::strtoull(text, &end, 10);
    if (end == text) return 0;
    while (std::isspace(static_cast<unsigned char>(*end))) ++end;
    unsigned shift = 10;
    switch (std::tolower(static_cast<unsigned char>(*end))) {
    case '\0': break;
    case 'b': shift = 0; break;
    case 'k': shift = 10; break;
    case 'm': shift = 20; break;
    case 'g': shift = 30; break;
    default: return 0;
    }
    return static_cast<std::size_t>(value) << shift;
}

std::size_t openmp_stack_size() {
    if (const StackSizeQuery kmp = kmp_stack_size_query()) return kmp() + (std::size_t{1} << 20);
    static const std::size_t size = [] {
        const std::size_t omp = parse_stack_size(std::getenv("OMP_STACKSIZE"));
        return omp ? omp : parse_stack_size(std::getenv("GOMP_STACKSIZE"));
    }();
    return size;
}
#endif

// Probe threads wait until every one of them exists: an exited thread no
// longer counts against the process limits, and the team needs them all at
// once.
struct Gate {
    std::mutex mutex;
    std::condition_variable opened;
    bool open = false;
};

void *wait_at_gate(void *argument) {
    auto *gate = static_cast<Gate *>(argument);
    std::unique_lock<std::mutex> lock(gate->mutex);
    gate->opened.wait(lock, [gate] { return gate->open; });
    return nullptr;
}

// Starts `count` threads with `stack` bytes of stack (0: the default) that
// all exist at once, then joins them. Returns the error of the first refused
// thread (0 if none) and its index in *failed.
int probe_threads(int count, std::size_t stack, int *failed) {
    const CancellationHeldOff held_off;  // the gate and the joins outlive no cancel here
    pthread_attr_t attributes;
    if (int error = pthread_attr_init(&attributes)) return *failed = 0, error;
    if (stack) pthread_attr_setstacksize(&attributes, stack);
    Gate gate;
    std::vector<pthread_t> started;
    int error = 0;
    try {
        started.reserve(static_cast<std::size_t>(count));
    } catch (...) {
        pthread_attr_destroy(&attributes);
        throw;
    }
    for (int i = 0; i < count && !error; ++i) {
        pthread_t thread;
        error = pthread_create(&thread, &attributes, wait_at_gate, &gate);
        if (error)
            *failed = i;
        else
            started.push_back(thread);
    }
    {
        std::lock_guard<std::mutex> lock(gate.mutex);
        gate.open = true;
    }
    gate.opened.notify_all();
    for (pthread_t thread : started) pthread_join(thread, nullptr);
    pthread_attr_destroy(&attributes);
    return error;
}

// "; the process is at a limit ..." after the reason a thread was refused.
std::string thread_limit_text(int error) {
    return " (" + std::generic_category().message(error) +
           "); the process is at a limit on threads or memory (ulimit -u, ulimit -v, cgroup pids.max)";
}

}  // namespace

void require_threads_can_start(int count, const std::string &for_what, const std::string &advice) {
    if (count < 1) return;
    int failed = 0;
    if (const int error = probe_threads(count, 0, &failed))
        fail(LPI_ERR_NO_MEMORY, for_what + " needs " + std::to_string(count) +
                                    (count == 1 ? " thread" : " threads") +
                                    ", and the system refused to start thread " +
                                    std::to_string(failed + 1) + thread_limit_text(error) + "; " +
                                    advice);
}

#if LPI_HAVE_OPENMP

namespace {

// The largest team this thread's OpenMP pool is known to hold: libgomp keeps
// the threads of the last team started on a thread (a team of one starts
// none) and lets the surplus go when a smaller team starts.
thread_local int ready = 1;
// In a child of fork(2) no thread of the parent's teams exists. libgomp does
// not rebuild a thread's pool there: a team started on the forking thread
// waits forever for threads that were not copied, so the child handler marks
// that thread's pool lost when it may have had one (a new thread of the
// child starts a pool of its own). The library knows its own teams; a host's
// (its own parallel regions before the fork) it cannot see, so a parent with
// any other thread at the fork counts as one that may have had a team: a
// child's lpi_set_threads waited for ever there. libomp starts afresh in a
// child, and its teams need new threads, which the probe is to check first.
thread_local bool pool_lost = false;
// Threads of the process just before the last fork (0: unknown).
long threads_at_fork = 0;
// From /proc/self/stat (field 20), with calls that are safe in any fork
// handler; 0 when it cannot be read.
long count_threads() {
    const int fd = ::open("/proc/self/stat", O_RDONLY | O_CLOEXEC);
    if (fd < 0) return 0;
    char text[1024];
    const ssize_t length = ::read(fd, text, sizeof text - 1);
    ::close(fd);
    if (length <= 0) return 0;
    text[length] = '\0';
    // The name (field 2) is in parentheses and may hold spaces: count from
    // the last ')', which field 3 follows.
    const char *p = std::strrchr(text, ')');
    for (int field = 2; p && field < 20; ++field) p = std::strchr(p + 1, ' ');
    return p ? std::strtol(p + 1, nullptr, 10) : 0;
}
void count_threads_before_fork() { threads_at_fork = count_threads(); }
void forget_pool_in_child() {
    if (kmp_runtime())
        ready = 1;
    else if (ready > 1 || threads_at_fork != 1)
        pool_lost = true;
}
[[maybe_unused]] const int fork_handler = pthread_atfork(count_threads_before_fork, nullptr, forget_pool_in_child);

}  // namespace

void prepare_thread_team(int n) {
    if (n > 1 && pool_lost)
        fail(LPI_ERR_UNSUPPORTED, "cannot run " + std::to_string(n) + " threads on this thread of a child of "
                                  "fork(2): this thread may hold a team of OpenMP threads of the parent (the "
                                  "library's, or the host's: the parent had other threads at the fork), and "
                                  "libgomp does not start them again in a child, but waits for them for ever "
                                  "(use one thread here, or another thread of the child)");
    if (n <= ready) {
        if (n > 1) ready = n;
        return;
    }
    int failed = 0;
    if (const int error = probe_threads(n - 1, openmp_stack_size(), &failed))
        fail(LPI_ERR_NO_MEMORY, "cannot run " + std::to_string(n) +
                                    " threads: the system refused to start thread " +
                                    std::to_string(failed + 2) + " of " + std::to_string(n) +
                                    thread_limit_text(error) + ": use fewer threads");
    // Start the team once (a region with a body: an empty one is compiled
    // away). The runtime may cap it (OMP_THREAD_LIMIT); regions asking for n
    // then get the same team, so n is what this thread is ready for.
#pragma omp parallel num_threads(n)
    {
#pragma omp barrier
    }
    ready = n;
}

int team_size_here(int n) { return n > 1 && pool_lost ? 1 : n; }

#else

void prepare_thread_team(int) {}
int team_size_here(int n) { return n; }

#endif

}  // namespace lpi
