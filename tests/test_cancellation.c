/* pthread_cancel and the library's own cancellation points (its waits and
 * file operations). The calls that touch files or set the thread count act
 * on a cancel pending as they begin, before anything is done: the thread
 * ends, nothing changed, nothing left behind. A cancel that comes while the
 * library waits or touches files is held off until the call returns,
 * complete, and acts at the thread's next cancellation point. Acted on
 * inside, it ended the process (a file closed in a destructor:
 * std::terminate; the thread probe's join, its gate on the ending stack) or
 * left the call half done. close(2) and pthread_join(3) are interposed here
 * to make a cancel come at that moment. */
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <pthread.h>
#include <unistd.h>

#include "lpi_test.h"

/* Armed on one thread: its next close or join first requests its own cancel. */
static __thread const char *cancel_at;

static void cancel_if_armed(const char *function) {
    if (cancel_at && strcmp(cancel_at, function) == 0) {
        cancel_at = NULL;
        pthread_cancel(pthread_self());
    }
}

int close(int fd) {
    static int (*real_close)(int);
    if (!real_close) real_close = (int (*)(int))dlsym(RTLD_NEXT, "close");
    cancel_if_armed("close");
    return real_close(fd);
}

int pthread_join(pthread_t thread, void **result) {
    static int (*real_join)(pthread_t, void **);
    if (!real_join) real_join = (int (*)(pthread_t, void **))dlsym(RTLD_NEXT, "pthread_join");
    cancel_if_armed("pthread_join");
    return real_join(thread, result);
}

typedef int (*call_fn)(void *);

struct victim {
    call_fn call;
    void *argument;
    const char *cancel_at; /* NULL: a cancel pending before the call */
    int status;
    int returned;
};

static void *run_victim(void *argument) {
    struct victim *v = argument;
    if (v->cancel_at) {
        cancel_at = v->cancel_at;
    } else {
        pthread_setcancelstate(PTHREAD_CANCEL_DISABLE, NULL);
        pthread_cancel(pthread_self());
        pthread_setcancelstate(PTHREAD_CANCEL_ENABLE, NULL); /* deferred: pending */
    }
    v->status = v->call(v->argument);
    v->returned = 1;
    pthread_testcancel();
    return NULL; /* not reached: the cancel ends the thread */
}

enum { kEndsAtEntry, kReturns };

/* Runs call on a thread of its own, cancelled as asked; fails the test
 * unless the cancel ended the thread, at the call's entry or after it
 * returned as expected. */
static struct victim run(call_fn call, void *argument, const char *at, int expected) {
    struct victim v = {call, argument, at, -1000, 0};
    pthread_t thread;
    void *result = NULL;
    assert_int_equal(pthread_create(&thread, NULL, run_victim, &v), 0);
    assert_int_equal(pthread_join(thread, &result), 0);
    assert_ptr_equal(result, PTHREAD_CANCELED);
    assert_int_equal(v.returned, expected == kReturns);
    return v;
}

static int entries(const char *dir) {
    DIR *d = opendir(dir);
    assert_non_null(d);
    int count = 0;
    for (struct dirent *e; (e = readdir(d));) count += e->d_name[0] != '.';
    closedir(d);
    return count;
}

struct file_call {
    lpi_system *sys;
    const char *path;
    lpi_system *loaded;
};

static int save(void *p) {
    struct file_call *c = p;
    return lpi_save(c->sys, c->path);
}
static int load(void *p) {
    struct file_call *c = p;
    return lpi_load(&c->loaded, c->path);
}
static int export_wisdom(void *p) { return lpi_fftw_wisdom_export_file(((struct file_call *)p)->path); }
static int import_wisdom(void *p) { return lpi_fftw_wisdom_import_file(((struct file_call *)p)->path); }

static void test_checkpoint_files(void **state) {
    (void)state;
    char dir[] = "cancellation_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/run.lpi", dir);
    struct file_call c = {NULL, path, NULL};
    assert_int_equal(lpi_rigid_body_create(&c.sys, 1.0, 2.0, 3.0), LPI_OK);
    const double m0[3] = {1.0, 0.5, -0.3};
    assert_int_equal(lpi_set_state(c.sys, m0, 3), LPI_OK);
    assert_int_equal(lpi_step(c.sys, 0.01, 3), LPI_OK);

    /* Pending: the save ends the thread before it touches anything. */
    run(save, &c, NULL, kEndsAtEntry);
    assert_int_equal(entries(dir), 0);

    /* Coming at a close inside: the calls complete. */
    assert_int_equal(run(save, &c, "close", kReturns).status, LPI_OK);
    assert_int_equal(run(load, &c, "close", kReturns).status, LPI_OK);
    assert_non_null(c.loaded);
    double saved[3], loaded[3];
    assert_int_equal(lpi_get_state(c.sys, saved, 3), LPI_OK);
    assert_int_equal(lpi_get_state(c.loaded, loaded, 3), LPI_OK);
    assert_memory_equal(saved, loaded, sizeof saved);
    lpi_destroy(c.loaded);
    c.loaded = NULL;
    assert_int_equal(entries(dir), 1); /* no temporary left beside it */

    /* Pending at a load: no handle made (LeakSanitizer would see one). */
    run(load, &c, NULL, kEndsAtEntry);
    assert_null(c.loaded);

    lpi_destroy(c.sys);
    assert_int_equal(unlink(path), 0);
    assert_int_equal(rmdir(dir), 0);
}

/* A sine-Euler system, or a skip where this build has none (no FFTW). */
static lpi_system *sine_euler_or_skip(void) {
    lpi_system *sys = NULL;
    const int status = lpi_sine_euler_create(&sys, 9);
    if (status == LPI_ERR_UNSUPPORTED) LPI_SKIP("a build without sine-Euler: %s", lpi_last_error(NULL));
    assert_int_equal(status, LPI_OK);
    return sys;
}

static void test_wisdom_files(void **state) {
    (void)state;
    lpi_system *sys = sine_euler_or_skip(); /* its plans make wisdom */
    char dir[] = "cancellation_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char wisdom[64];
    snprintf(wisdom, sizeof wisdom, "%s/wisdom", dir);
    struct file_call c = {NULL, wisdom, NULL};

    run(export_wisdom, &c, NULL, kEndsAtEntry);
    assert_int_equal(entries(dir), 0);
    assert_int_equal(run(export_wisdom, &c, "close", kReturns).status, LPI_OK);
    assert_int_equal(run(import_wisdom, &c, "close", kReturns).status, LPI_OK);
    assert_int_equal(entries(dir), 1);

    lpi_destroy(sys);
    assert_int_equal(unlink(wisdom), 0);
    assert_int_equal(rmdir(dir), 0);
}

static int set_two_threads(void *sys) { return lpi_set_threads(sys, 2); }
static int step(void *sys) { return lpi_step(sys, 0.01, 2); }

/* The probe that starts and joins threads before a team may need them: in
 * lpi_set_threads, and in a thread's first lpi_step with more than one. */
static void test_thread_probe(void **state) {
    (void)state;
    lpi_system *sys = sine_euler_or_skip();
    const int status = lpi_set_threads(sys, 2);
    if (status == LPI_ERR_UNSUPPORTED) {
        lpi_destroy(sys);
        LPI_SKIP("a build without OpenMP: %s", lpi_last_error(NULL));
    }
    assert_int_equal(status, LPI_OK);
    double x[81];
    for (int i = 0; i < 81; ++i) x[i] = 0.01 * ((i * 13) % 7 - 3);
    assert_int_equal(lpi_set_state(sys, x, 81), LPI_OK);

    /* Pending: lpi_set_threads ends the thread as it begins. lpi_step is no
     * cancellation point: a new thread's first step with two threads set
     * probes them with the cancel held off, and completes. */
    assert_int_equal(lpi_set_threads(sys, 1), LPI_OK);
    run(set_two_threads, sys, NULL, kEndsAtEntry);
    assert_int_equal(lpi_set_threads(sys, 2), LPI_OK);
    assert_int_equal(run(step, sys, NULL, kReturns).status, LPI_OK);
    assert_true(lpi_time(sys) == 0.02);

    /* Coming at a join inside: the calls complete. */
    assert_int_equal(run(set_two_threads, sys, "pthread_join", kReturns).status, LPI_OK);
    assert_int_equal(run(step, sys, "pthread_join", kReturns).status, LPI_OK);
    assert_int_equal(lpi_step(sys, 0.01, 2), LPI_OK); /* the handle is free */
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_checkpoint_files),
        cmocka_unit_test(test_wisdom_files),
        cmocka_unit_test(test_thread_probe),
    };
    return lpi_run_tests(tests);
}
