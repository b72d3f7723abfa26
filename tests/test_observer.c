/* lpi_set_observer: the observer sees, at every k-th step, exactly the state
 * and time of a fresh system stepped that many steps in one call (its whole
 * checkpoint, compensated carry included, bit for bit), for a merging
 * splitting method and for baselines, and every mode of a sine-Euler system;
 * observing changes no bit of the trajectory; a non-zero return stops
 * lpi_step with LPI_STOPPED at that step; inside the observer the handle can be read but not changed
 * (LPI_ERR_BUSY, nothing changed); a failing step names the step and time. */
#include "lpi_test.h"

enum { kMaxObservations = 64, kMaxBytes = 8192 };

static const double kInertia[3] = {1.0, 2.0, 3.5};
static const double kM0[3] = {0.3, 1.1, -0.7};

typedef struct {
    int count;
    int stop_after;  /* return non-zero at this observation (0: never) */
    int64_t steps[kMaxObservations];
    double times[kMaxObservations];
    unsigned char checkpoints[kMaxObservations][256];
    size_t checkpoint_size[kMaxObservations];
    double states[kMaxObservations][3];
    double energies[kMaxObservations];
    int read_status;    /* worst status of the read-only calls made inside */
} record;

static int record_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    record *r = user;
    if (r->count >= kMaxObservations) return 1;
    const int i = r->count++;
    r->steps[i] = step;
    r->times[i] = t;
    int status = lpi_get_state(sys, r->states[i], 3);
    if (status == LPI_OK) status = lpi_energy(sys, &r->energies[i]);
    if (status == LPI_OK && lpi_time(sys) != t) status = LPI_ERR_INTERNAL;
    size_t size = 0;
    if (status == LPI_OK) status = lpi_save_buffer(sys, r->checkpoints[i], 256, &size);
    r->checkpoint_size[i] = size;
    if (status != LPI_OK) r->read_status = status;
    return r->stop_after && r->count == r->stop_after;
}

static lpi_system *rigid_body(const char *method) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, kInertia[0], kInertia[1], kInertia[2]), LPI_OK);
    assert_int_equal(lpi_set_state(sys, kM0, 3), LPI_OK);
    assert_int_equal(lpi_set_method(sys, method), LPI_OK);
    return sys;
}

/* The checkpoint of a fresh rigid body stepped `steps` steps in one call. */
static size_t fresh_checkpoint(const char *method, double dt, int64_t steps, unsigned char *buf) {
    lpi_system *fresh = rigid_body(method);
    assert_int_equal(lpi_step(fresh, dt, steps), LPI_OK);
    size_t size = 0;
    assert_int_equal(lpi_save_buffer(fresh, buf, kMaxBytes, &size), LPI_OK);
    lpi_destroy(fresh);
    return size;
}

static void test_observed_states_are_those_of_fresh_runs(void **state) {
    (void)state;
    /* leapfrog and yoshida-6 merge the flows at step seams; rk4 and
     * implicit-midpoint are stepped in chunks. */
    const char *methods[] = {"leapfrog", "yoshida-6", "rk4", "implicit-midpoint"};
    const double dt = 0.0371;
    const int64_t every = 7, n = 40; /* 5 observations, then 5 more steps */
    for (size_t m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
        lpi_system *sys = rigid_body(methods[m]);
        static record r;
        memset(&r, 0, sizeof r);
        assert_int_equal(lpi_set_observer(sys, every, record_observer, &r), LPI_OK);
        assert_int_equal(lpi_step(sys, dt, n), LPI_OK);
        assert_int_equal(r.read_status, LPI_OK);
        assert_int_equal(r.count, n / every);
        unsigned char expected[kMaxBytes];
        for (int i = 0; i < r.count; ++i) {
            const int64_t k = every * (i + 1);
            assert_int_equal(r.steps[i], k);
            const double t = dt * (double)k;
            assert_memory_equal(&r.times[i], &t, sizeof t);
            const size_t size = fresh_checkpoint(methods[m], dt, k, expected);
            assert_int_equal(r.checkpoint_size[i], size);
            if (memcmp(r.checkpoints[i], expected, size) != 0)
                fail_msg("%s: the state observed at step %lld differs from a run of %lld steps",
                         methods[m], (long long)k, (long long)k);
        }
        /* Observing changed no bit of the trajectory. */
        unsigned char after[kMaxBytes];
        size_t size = 0;
        assert_int_equal(lpi_save_buffer(sys, after, sizeof after, &size), LPI_OK);
        assert_int_equal(fresh_checkpoint(methods[m], dt, n, expected), size);
        assert_memory_equal(after, expected, size);
        /* Removed: no more calls. */
        assert_int_equal(lpi_set_observer(sys, 0, NULL, NULL), LPI_OK);
        assert_int_equal(lpi_step(sys, dt, 20), LPI_OK);
        assert_int_equal(r.count, n / every);
        lpi_destroy(sys);
    }
}

/* Sine-Euler: the flows keep one half of the modes during a run; the
 * observer still sees every mode, as a fresh run of that many steps leaves
 * them (the other half written before it is called). */
enum { kSineN = 15, kSineModes = 2 * kSineN * kSineN, kSineObservations = 4 };
static double sine_observed[kSineObservations][kSineModes];
static int sine_observed_count, sine_read_status;

static int sine_modes_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)step, (void)t, (void)user;
    if (sine_observed_count >= kSineObservations) return 1;
    const int status = lpi_sine_euler_get_modes(sys, sine_observed[sine_observed_count++], kSineModes);
    if (status != LPI_OK) sine_read_status = status;
    return 0;
}

/* A sine-Euler system of N = 15 with a few modes set; NULL without FFTW. */
static lpi_system *sine_euler_15(void) {
    lpi_system *sys = NULL;
    if (lpi_sine_euler_create(&sys, kSineN) != LPI_OK) return NULL;
    double w[kSineModes] = {0};
    w[2 * (2 * kSineN + 1)] = 1.0, w[2 * (13 * kSineN + 14)] = 1.0;  /* (2, 1), (-2, -1) */
    w[2 * 3] = 0.5, w[2 * 12] = 0.5;                                  /* (0, 3), (0, -3) */
    w[2 * (kSineN + 4) + 1] = 0.3, w[2 * (14 * kSineN + 11) + 1] = -0.3; /* (1, 4), (-1, -4) */
    assert_int_equal(lpi_sine_euler_set_modes(sys, w, kSineModes), LPI_OK);
    return sys;
}

static void test_observed_sine_euler_modes_are_those_of_fresh_runs(void **state) {
    (void)state;
    lpi_system *sys = sine_euler_15();
    if (!sys) LPI_SKIP("built without FFTW: no sine-Euler system");
    const double dt = 0.05;
    const int64_t every = 3;
    sine_observed_count = 0, sine_read_status = LPI_OK;
    assert_int_equal(lpi_set_observer(sys, every, sine_modes_observer, NULL), LPI_OK);
    assert_int_equal(lpi_step(sys, dt, every * kSineObservations + 1), LPI_OK);
    assert_int_equal(sine_read_status, LPI_OK);
    assert_int_equal(sine_observed_count, kSineObservations);
    for (int i = 0; i < kSineObservations; ++i) {
        lpi_system *fresh = sine_euler_15();
        assert_int_equal(lpi_step(fresh, dt, every * (i + 1)), LPI_OK);
        double expected[kSineModes];
        assert_int_equal(lpi_sine_euler_get_modes(fresh, expected, kSineModes), LPI_OK);
        if (memcmp(sine_observed[i], expected, sizeof expected) != 0)
            fail_msg("the modes observed at step %lld differ from a run of that many steps",
                     (long long)(every * (i + 1)));
        lpi_destroy(fresh);
    }
    lpi_destroy(sys);
}

static void test_stop_gives_the_state_of_that_many_steps(void **state) {
    (void)state;
    const char *methods[] = {"kahan-li-6", "rk4"};
    const double dt = -0.05; /* backwards, to check the time as well */
    for (size_t m = 0; m < 2; ++m) {
        lpi_system *sys = rigid_body(methods[m]);
        assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK); /* a nonzero start time */
        const double start = lpi_time(sys);
        static record r;
        memset(&r, 0, sizeof r);
        r.stop_after = 3;
        assert_int_equal(lpi_set_observer(sys, 4, record_observer, &r), LPI_OK);
        assert_int_equal(lpi_step(sys, dt, 1000), LPI_STOPPED);
        assert_int_equal(r.count, 3);
        const double t = start + dt * 12.0;
        const double now = lpi_time(sys);
        assert_memory_equal(&now, &t, sizeof t);

        lpi_system *fresh = rigid_body(methods[m]);
        assert_int_equal(lpi_step(fresh, 0.1, 3), LPI_OK);
        assert_int_equal(lpi_step(fresh, dt, 12), LPI_OK);
        unsigned char a[kMaxBytes], b[kMaxBytes];
        size_t sa = 0, sb = 0;
        assert_int_equal(lpi_save_buffer(sys, a, sizeof a, &sa), LPI_OK);
        assert_int_equal(lpi_save_buffer(fresh, b, sizeof b, &sb), LPI_OK);
        assert_int_equal(sa, sb);
        assert_memory_equal(a, b, sa);
        /* Stopping at the last step of the call is still a stop. */
        memset(&r, 0, sizeof r);
        r.stop_after = 1;
        assert_int_equal(lpi_step(sys, dt, 4), LPI_STOPPED);
        lpi_destroy(fresh);
        lpi_destroy(sys);
    }
}

/* Inside the observer: every mutating call is refused and changes nothing. */
typedef struct {
    lpi_system *self; /* the observed handle, as a mutable pointer */
    lpi_system *other;
    int refused, allowed, calls;
} intruder;

static void expect(intruder *in, int status, int wanted) {
    in->calls++;
    if (status == wanted && wanted == LPI_ERR_BUSY) in->refused++;
    if (status == wanted && wanted == LPI_OK) in->allowed++;
}

static int mutating_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)step, (void)t;
    intruder *in = user;
    lpi_system *self = in->self;
    const double x[3] = {9, 9, 9}, gammas[1] = {1.0};
    double out[3];
    size_t flows;
    expect(in, lpi_set_state(self, x, 3), LPI_ERR_BUSY);
    expect(in, lpi_step(self, 0.1, 1), LPI_ERR_BUSY);
    expect(in, lpi_set_method(self, "rk4"), LPI_ERR_BUSY);
    expect(in, lpi_set_split(self, "axes"), LPI_ERR_BUSY);
    expect(in, lpi_set_composition(self, 1, gammas), LPI_ERR_BUSY);
    expect(in, lpi_set_implicit_options(self, 1e-10, 5), LPI_ERR_BUSY);
    expect(in, lpi_set_threads(self, 1), LPI_ERR_BUSY);
    expect(in, lpi_set_observer(self, 1, NULL, NULL), LPI_ERR_BUSY);
    expect(in, lpi_destroy(self), LPI_ERR_BUSY);
    if (strstr(lpi_last_error(sys), "lpi_destroy") == NULL) in->calls += 100;
    /* Reading is allowed, and another handle is not affected. */
    expect(in, lpi_get_state(sys, out, 3), LPI_OK);
    expect(in, lpi_flows_per_step(sys, &flows), LPI_OK);
    expect(in, lpi_rigid_body_exact(sys, 0.5, out), LPI_OK);
    expect(in, lpi_step(in->other, 0.1, 2), LPI_OK);
    return 0;
}

static void test_observer_cannot_change_the_handle(void **state) {
    (void)state;
    lpi_system *sys = rigid_body("leapfrog");
    lpi_system *other = rigid_body("leapfrog");
    intruder in = {sys, other, 0, 0, 0};
    assert_int_equal(lpi_set_observer(sys, 2, mutating_observer, &in), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.05, 4), LPI_OK);
    assert_int_equal(in.calls, 2 * 13);
    assert_int_equal(in.refused, 2 * 9);
    assert_int_equal(in.allowed, 2 * 4);
    /* The refusals changed nothing: the run equals an unobserved one. */
    unsigned char a[kMaxBytes], b[kMaxBytes];
    size_t sa = 0, sb = fresh_checkpoint("leapfrog", 0.05, 4, b);
    assert_int_equal(lpi_save_buffer(sys, a, sizeof a, &sa), LPI_OK);
    assert_int_equal(sa, sb);
    assert_memory_equal(a, b, sa);
    /* After the call the handle is free again. */
    assert_int_equal(lpi_set_observer(sys, 1, NULL, NULL), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK);
    assert_int_equal(lpi_destroy(other), LPI_OK);
    assert_int_equal(lpi_destroy(sys), LPI_OK);
}

/* A generic so(3) whose gradient callback fails at its `fail_at`-th call. */
typedef struct {
    int calls, fail_at;
} countdown;

static int failing_gradient(size_t n, const double *x, double *g, void *user) {
    countdown *c = user;
    if (++c->calls == c->fail_at) return 7;
    return lpi_test_axis_gradient(n, x, g, (void *)&kInertia[0]);
}
static int energy_0(size_t n, const double *x, double *h, void *user) {
    (void)user;
    return lpi_test_axis_energy(n, x, h, (void *)&kInertia[0]);
}

static int count_observer(const lpi_system *sys, int64_t step, double t, void *user) {
    (void)sys, (void)step, (void)t;
    ++*(int *)user;
    return 0;
}

static void test_failing_step_names_step_and_time(void **state) {
    (void)state;
    static const int32_t i[] = {0, 1, 2}, j[] = {1, 2, 0}, k[] = {2, 0, 1};
    static const double c[] = {1, 1, 1};
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    assert_int_equal(lpi_set_state(sys, kM0, 3), LPI_OK);
    countdown cd = {0, 5}; /* lie-trotter, one piece: one call per step */
    const int32_t axis[] = {0};
    assert_int_equal(lpi_add_piece(sys, 1, axis, failing_gradient, energy_0, &cd), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "lie-trotter"), LPI_OK);
    int observed = 0;
    assert_int_equal(lpi_set_observer(sys, 2, count_observer, &observed), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.25, 10), LPI_ERR_CALLBACK, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "in step 5 of this call (t = 1 .. 1.25)"));
    assert_non_null(strstr(lpi_last_error(sys), "rolled back"));
    assert_int_equal(observed, 2);
    const double zero = 0.0, now = lpi_time(sys);
    assert_memory_equal(&now, &zero, sizeof now);
    lpi_destroy(sys);

    /* Leapfrog merges one step's last flow with the next one's first: the
     * first flow of a call stands alone, and is step 1's. */
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    assert_int_equal(lpi_set_state(sys, kM0, 3), LPI_OK);
    cd = (countdown){0, 3};
    const int32_t second[] = {1};
    assert_int_equal(lpi_add_piece(sys, 1, axis, failing_gradient, energy_0, &cd), LPI_OK);
    assert_int_equal(lpi_add_piece(sys, 1, second, lpi_test_axis_gradient, lpi_test_axis_energy,
                                   (void *)&kInertia[1]),
                     LPI_OK);
    assert_int_equal(lpi_set_method(sys, "leapfrog"), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.25, 1), LPI_OK); /* flows 1 and 2 of the failing piece */
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.25, 10), LPI_ERR_CALLBACK, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "in step 1 of this call (t = 0.25 .. 0.5)"));
    lpi_destroy(sys);

    /* A non-finite state is found at the latest at the next observation. */
    sys = rigid_body("rk4");
    assert_int_equal(lpi_set_observer(sys, 3, count_observer, &observed), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1e200, 10), LPI_ERR_NONFINITE, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "after step 3 of this call (t = 3e+200"));
    lpi_destroy(sys);

    /* Without an observer: the check that found it (step 256), not the end
     * of the call (it named step 1000000). */
    sys = rigid_body("rk4");
    const double huge[3] = {1e150, 1e150, 1e150};
    assert_int_equal(lpi_set_state(sys, huge, 3), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 1.0, 1000000), LPI_ERR_NONFINITE, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "after step 256 of this call (t = 256;"));
    lpi_destroy(sys);

    /* The baselines name the step a callback failed in, as the splittings do
     * (it was the whole stretch between observations): rk4 calls the
     * gradient 4 times a step, so call 18 is step 5's. */
    assert_int_equal(lpi_generic_create(&sys, 3, 3, i, j, k, c), LPI_OK);
    assert_int_equal(lpi_set_state(sys, kM0, 3), LPI_OK);
    cd = (countdown){0, 18};
    assert_int_equal(lpi_add_piece(sys, 1, axis, failing_gradient, energy_0, &cd), LPI_OK);
    assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK);
    LPI_ASSERT_FAILS(sys, lpi_step(sys, 0.25, 10), LPI_ERR_CALLBACK, "lpi_step");
    assert_non_null(strstr(lpi_last_error(sys), "in step 5 of this call (t = 1 .. 1.25)"));
    lpi_destroy(sys);
}

static void test_observer_arguments(void **state) {
    (void)state;
    lpi_system *sys = rigid_body("leapfrog");
    int observed = 0;
    LPI_ASSERT_FAILS(sys, lpi_set_observer(sys, 0, count_observer, &observed), LPI_ERR_INVALID,
                     "lpi_set_observer");
    LPI_ASSERT_FAILS(sys, lpi_set_observer(sys, INT64_MIN, count_observer, &observed),
                     LPI_ERR_INVALID, "lpi_set_observer");
    LPI_ASSERT_FAILS(NULL, lpi_set_observer(NULL, 1, count_observer, &observed), LPI_ERR_NULL,
                     "lpi_set_observer");
    /* Removing ignores every; a call with fewer steps than every sees none. */
    assert_int_equal(lpi_set_observer(sys, -5, NULL, NULL), LPI_OK);
    assert_int_equal(lpi_set_observer(sys, 10, count_observer, &observed), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 9), LPI_OK);
    assert_int_equal(observed, 0);
    assert_int_equal(lpi_step(sys, 0.1, 10), LPI_OK);
    assert_int_equal(observed, 1);
    lpi_destroy(sys);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_observed_states_are_those_of_fresh_runs),
        cmocka_unit_test(test_observed_sine_euler_modes_are_those_of_fresh_runs),
        cmocka_unit_test(test_stop_gives_the_state_of_that_many_steps),
        cmocka_unit_test(test_observer_cannot_change_the_handle),
        cmocka_unit_test(test_failing_step_names_step_and_time),
        cmocka_unit_test(test_observer_arguments),
    };
    return lpi_run_tests(tests);
}
