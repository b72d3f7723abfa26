/* Loading the library starts no thread: it loads LAPACK only when a Casimir
 * spectrum or a matrix baseline first needs it (a threaded OpenBLAS starts a
 * thread per further processor when it is loaded, and under a process limit
 * printed and ended every program that merely linked the library). The
 * threads are counted before anything else runs (/proc/self/task); then the
 * spectrum that loads LAPACK is computed. With the argument "thread-limit"
 * (test_library_load_thread_limit): in a child process that may start no
 * further thread, the spectrum that would load LAPACK must fail with
 * LPI_ERR_NO_MEMORY, the threads refused by the library's own check,
 * whatever LAPACK it was built against (a threaded OpenBLAS, which
 * liblapack.so.3 may be, printed and raised SIGINT). With "address-limit"
 * (test_library_load_address_limit): in a child whose address space has
 * 64 MiB to spare, the spectrum must fail with LPI_ERR_NO_MEMORY, not wait
 * for ever (OpenBLAS retried its 128 MiB buffers without end), and succeed
 * once the limit is lifted. */
#define _GNU_SOURCE
#include <dirent.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <liepoisson.h>

#include "mapped_bytes.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define UNDER_A_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define UNDER_A_SANITIZER 1
#endif
#endif

static int thread_count(void) {
    DIR *tasks = opendir("/proc/self/task");
    if (!tasks) return -1;
    int n = 0;
    for (struct dirent *e; (e = readdir(tasks)) != NULL;) n += e->d_name[0] != '.';
    closedir(tasks);
    return n;
}

/* The Casimir spectrum of a sine-Euler field, N = 5 (LAPACK's zheevd). */
static int spectrum_status(char *message, size_t size) {
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, 5) != LPI_OK) return LPI_ERR_UNSUPPORTED; /* no FFTW */
    double x[25] = {0.0, 1.0, 0.5, -0.25};
    double spectrum[5];
    const int status = lpi_set_state(sys, x, 25) == LPI_OK ? lpi_casimirs(sys, spectrum, 5) : -1;
    snprintf(message, size, "%s", status == LPI_OK ? "computed" : lpi_last_error(sys));
    lpi_destroy(sys);
    return status;
}

#ifndef UNDER_A_SANITIZER
/* In a child: 0 when the spectrum is refused with LPI_ERR_NO_MEMORY for the
 * threads LAPACK may start, 77 where nothing can be checked, else 1 .. 3.
 * The limit is the one a threaded OpenBLAS dies of: no further thread for
 * this user (RLIMIT_NPROC, which does not bind root: as root the child
 * becomes nobody first). */
static int spectrum_under_a_thread_limit(void) {
    /* As OpenBLAS counts them, without the variables that ask it for fewer. */
    unsetenv("OPENBLAS_NUM_THREADS");
    unsetenv("GOTO_NUM_THREADS");
    unsetenv("OMP_NUM_THREADS");
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) return 77;
    struct rlimit one;
    if (getrlimit(RLIMIT_NPROC, &one) != 0) return 77;
    one.rlim_cur = 1;
    if (setrlimit(RLIMIT_NPROC, &one) != 0) return 77;
    char message[1024];
    const int status = spectrum_status(message, sizeof message);
    printf("with no thread to spare (ulimit -u 1), the Casimir spectrum: %s\n", message);
    fflush(stdout);
    /* Without LAPACK in the build: nothing to load. */
    if (status == LPI_ERR_UNSUPPORTED && !strstr(message, "cannot be loaded")) return 77;
    if (status != LPI_ERR_NO_MEMORY) return 1;
    if (!strstr(message, "refused to start thread")) return 2;
    if (!strstr(message, "OPENBLAS_NUM_THREADS=1")) return 3;
    return 0;
}
#endif

#ifndef UNDER_A_SANITIZER
/* In a child: 0 when the spectrum is refused with LPI_ERR_NO_MEMORY while the
 * address space has 64 MiB to spare and computed once it has more, 77 where
 * nothing can be checked, else 1 .. 3. A hang ends by SIGALRM. */
static int spectrum_under_an_address_limit(void) {
    struct rlimit saved, tight;
    const size_t mapped = lpi_test_mapped_bytes();
    if (mapped == 0 || getrlimit(RLIMIT_AS, &saved) != 0) return 77;
    tight = saved;
    tight.rlim_cur = mapped + ((size_t)64 << 20);
    if (saved.rlim_cur != RLIM_INFINITY && saved.rlim_cur < tight.rlim_cur) return 77;
    if (setrlimit(RLIMIT_AS, &tight) != 0) return 77;
    alarm(60);
    char message[1024];
    int status = spectrum_status(message, sizeof message);
    printf("with 64 MiB of address space to spare, the Casimir spectrum: %s\n", message);
    fflush(stdout);
    if (status == LPI_ERR_UNSUPPORTED && !strstr(message, "cannot be loaded")) return 77;
    if (status != LPI_ERR_NO_MEMORY) return 1;
    if (!strstr(message, "OpenBLAS")) return 2;
    if (setrlimit(RLIMIT_AS, &saved) != 0) return 77;
    status = spectrum_status(message, sizeof message);
    printf("without the limit: %s\n", message);
    fflush(stdout); /* the child ends by _exit */
    return status == LPI_OK ? 0 : 3;
}
#endif

/* The spectrum under a limit, in a child: 0 passed, 77 skipped (the
 * reason printed), 1 failed. */
static int check_in_a_child(int address_limit) {
#ifdef UNDER_A_SANITIZER
    (void)address_limit;
    printf("skipped: the sanitizer's own threads, processes and mappings need room a limit denies\n");
    return 77;
#else
    cpu_set_t set;
    const int processors = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 1;
    const char *preload = getenv("LD_PRELOAD");
    if (processors < 2 && !address_limit) {
        printf("skipped: one processor, no thread to refuse\n");
        return 77;
    }
    if (preload && strstr(preload, "vgpreload")) {
        printf("skipped: a limit does not mix with valgrind\n");
        return 77;
    }
    fflush(stdout);
    const pid_t child = fork();
    if (child < 0) return 1;
    if (child == 0) _exit(address_limit ? spectrum_under_an_address_limit() : spectrum_under_a_thread_limit());
    int status = 0;
    if (waitpid(child, &status, 0) != child) return 1;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 77) {
        printf("skipped: no LAPACK in this build, or no limit could be set\n");
        return 77;
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        printf("FAILED: under the %s limit the child %s %d\n", address_limit ? "address-space" : "thread",
               WIFEXITED(status) ? "failed check" : "was killed by signal",
               WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
        return 1;
    }
    return 0;
#endif
}

/* No argument: loading starts no thread. "thread-limit", "address-limit":
 * the spectrum under a limit (a process of its own, as LAPACK must not be
 * loaded yet). */
int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "thread-limit") == 0) return check_in_a_child(0);
    if (argc > 1 && strcmp(argv[1], "address-limit") == 0) return check_in_a_child(1);
    const int threads = thread_count();
    if (threads < 0 || sysconf(_SC_NPROCESSORS_ONLN) < 2) {
        printf("skipped: %s\n", threads < 0 ? "no /proc/self/task to count threads in"
                                            : "one processor: a threaded BLAS starts no thread here either");
        return 77;
    }
    printf("liepoisson %s loaded; threads in the process: %d\n", lpi_version_string(), threads);
    if (threads != 1) {
        printf("FAILED: loading the library started %d threads\n", threads - 1);
        return 1;
    }
    char message[1024];
    const int status = spectrum_status(message, sizeof message);
    printf("the Casimir spectrum, which loads LAPACK: %s\n", message);
    if (status != LPI_OK && status != LPI_ERR_UNSUPPORTED) return 1;
    return 0;
}
