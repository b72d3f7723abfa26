/* Loading the library starts no thread: it loads LAPACK only when a Casimir
 * spectrum or a matrix baseline first needs it (a threaded OpenBLAS starts a
 * thread per further processor when it is loaded, and under a process limit
 * printed and ended every program that merely linked the library). The
 * threads are counted before anything else runs (/proc/self/task); then the
 * spectrum that loads LAPACK is computed. */
#include <dirent.h>
#include <stdio.h>
#include <unistd.h>

#include <liepoisson.h>

static int thread_count(void) {
    DIR *tasks = opendir("/proc/self/task");
    if (!tasks) return -1;
    int n = 0;
    for (struct dirent *e; (e = readdir(tasks)) != NULL;) n += e->d_name[0] != '.';
    closedir(tasks);
    return n;
}

int main(void) {
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
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, 5) == LPI_OK) {
        double x[25] = {0.0, 1.0, 0.5, -0.25};
        double spectrum[5];
        const int status = lpi_set_state(sys, x, 25) == LPI_OK ? lpi_casimirs(sys, spectrum, 5) : -1;
        printf("the Casimir spectrum, which loads LAPACK: %s\n",
               status == LPI_OK ? "computed" : lpi_last_error(sys));
        lpi_destroy(sys);
        if (status != LPI_OK && status != LPI_ERR_UNSUPPORTED) return 1;
    }
    return 0;
}
