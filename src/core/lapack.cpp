// LAPACK loaded when first needed (see the header).
#include "lapack.hpp"

#include <dlfcn.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <new>
#include <string>

#include "error.hpp"
#include "headroom.hpp"
#include "lpi_config.h"
#include "threads.hpp"

namespace lpi {
namespace lapack {

namespace {

using Zheevd = void(const char *, const char *, const int *, cplx *, const int *, double *, cplx *, const int *,
                    double *, const int *, int *, const int *, int *, std::size_t, std::size_t);
using Zgemm = void(const char *, const char *, const int *, const int *, const int *, const cplx *,
                   const cplx *, const int *, const cplx *, const int *, const cplx *, cplx *, const int *,
                   std::size_t, std::size_t);

struct Routines {
    Zheevd *zheevd = nullptr;
    Zgemm *zgemm = nullptr;
};

// The threads a threaded OpenBLAS starts on loading: one per processor this
// process may run on, or per thread its environment asks for (the first of
// OPENBLAS_NUM_THREADS, GOTO_NUM_THREADS, OMP_NUM_THREADS set to a positive
// number, as OpenBLAS reads them), at most one per processor, less the
// calling thread. Counted whatever LAPACK the library was built against:
// which one a name such as liblapack.so.3 loads is the system's choice when
// the library runs (Debian's alternatives), and OpenBLAS's is one of them.
// Another LAPACK starts none, and the count only asks the system for threads
// it gives back at once.
int threads_started_on_loading() {
    cpu_set_t set;
    const int processors = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 1;
    int asked = 0;
    for (const char *name : {"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"}) {
        const char *text = std::getenv(name);
        if (text && (asked = std::atoi(text)) > 0) break;
    }
    return std::min(asked > 0 ? asked : processors, processors) - 1;
}

// OpenBLAS takes a buffer of BUFFER_SIZE (128 MiB on x86-64) and a page
// from the system for each thread it starts as it loads, and one for the
// first call, which later calls reuse; where the system refuses one (a
// process under an address-space limit) it retries for ever: the call never
// returns, nor does the process's exit, which waits for its threads. So
// before loading it the library asks for that much, with the 40 MiB the
// load maps itself and a stack of 8 MiB a thread (headroom.hpp), and
// refuses where it cannot have it. Calls on several threads
// at once need a buffer each, which memory run short since the first call
// may not have (not covered). Counted for any LAPACK, as the threads are.
constexpr std::size_t kMiB = std::size_t{1} << 20;
constexpr std::size_t kOpenBlasBuffer = 128 * kMiB + 4096;
constexpr std::size_t kOpenBlasLoading = 48 * kMiB, kOpenBlasThread = kOpenBlasBuffer + 8 * kMiB;

void require_openblas_memory(std::size_t bytes, const std::string &for_what, const std::string &advice) {
    if (!address_space_available(bytes))
        fail(LPI_ERR_NO_MEMORY, for_what + " may need " + std::to_string(bytes) +
                                    " bytes for OpenBLAS's buffers, which this process cannot have (it "
                                    "would wait for them for ever)" + advice);
}

// A fork(2) while another thread held the loader's lock left the child's
// copy locked for ever: the child gets a fresh one (held where its own thread
// held it: a fork from a signal handler). The fork does not wait for it, as
// it waits for the FFTW planner: the lock is held across dlopen, whose
// library may register fork handlers, which glibc 2.28 .. 2.35 refuse while
// a fork runs its handlers.
std::mutex loader_mutex;
thread_local bool holds_loader = false;
struct LoaderLock {
    LoaderLock() { loader_mutex.lock(), holds_loader = true; }
    ~LoaderLock() { holds_loader = false, loader_mutex.unlock(); }
};
[[maybe_unused]] const int loader_renewed_in_child = pthread_atfork(nullptr, nullptr, [] {
    new (&loader_mutex) std::mutex;
    if (holds_loader) loader_mutex.lock();
});

const Routines &routines() {
    static Routines loaded;
    LoaderLock lock;
    if (loaded.zheevd) return loaded;
    const std::string name = LPI_LAPACK_LIBRARY;
    const int threads = threads_started_on_loading();
    require_threads_can_start(threads, "loading " + name,
                              "a threaded OpenBLAS starts them as it loads, and ends the process where it "
                              "cannot; OPENBLAS_NUM_THREADS=1 asks for none");
    // Its threads' buffers, and the one of the call that follows.
    require_openblas_memory(kOpenBlasLoading + static_cast<std::size_t>(threads) * kOpenBlasThread +
                                kOpenBlasBuffer,
                            "loading " + name,
                            threads > 0 ? "; OPENBLAS_NUM_THREADS=1 asks for the first call's alone" : "");
    void *library = ::dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        const char *why = ::dlerror();
        fail(LPI_ERR_UNSUPPORTED, "LAPACK (" + name + ") cannot be loaded: " + (why ? why : "no reason given"));
    }
    Routines found;
    found.zheevd = reinterpret_cast<Zheevd *>(::dlsym(library, "zheevd_"));
    found.zgemm = reinterpret_cast<Zgemm *>(::dlsym(library, "zgemm_"));
    if (!found.zheevd || !found.zgemm)
        fail(LPI_ERR_UNSUPPORTED, "LAPACK (" + name + ") has no " + (found.zheevd ? "zgemm_" : "zheevd_"));
    loaded = found;  // the library stays loaded for the life of the process
    return loaded;
}

}  // namespace

void zheevd(const char *jobz, const char *uplo, const int *n, cplx *a, const int *lda, double *w,
            cplx *work, const int *lwork, double *rwork, const int *lrwork, int *iwork, const int *liwork,
            int *info, std::size_t jobz_len, std::size_t uplo_len) {
    routines().zheevd(jobz, uplo, n, a, lda, w, work, lwork, rwork, lrwork, iwork, liwork, info, jobz_len,
                      uplo_len);
}

void zgemm(const char *transa, const char *transb, const int *m, const int *n, const int *k, const cplx *alpha,
           const cplx *a, const int *lda, const cplx *b, const int *ldb, const cplx *beta, cplx *c,
           const int *ldc, std::size_t transa_len, std::size_t transb_len) {
    routines().zgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, transa_len, transb_len);
}

}  // namespace lapack
}  // namespace lpi
