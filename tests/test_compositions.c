/* The composition methods through the public API: the registry, recursive
 * names, user compositions (and their bad input), first-same-as-last savings,
 * measured convergence orders on the rigid body and the pendulum against a
 * long-double RK4 reference written here, Casimirs to round-off and bounded
 * energy errors over 10^6 steps. */
#include "lpi_test.h"

/* ---- an independent reference: RK4 in long double ------------------------ */

static void rigid_body_field(const long double *m, long double *dm) {
    const long double w[3] = {m[0] / 1.0L, m[1] / 2.0L, m[2] / 3.0L}; /* I = 1, 2, 3 */
    dm[0] = m[1] * w[2] - m[2] * w[1];
    dm[1] = m[2] * w[0] - m[0] * w[2];
    dm[2] = m[0] * w[1] - m[1] * w[0];
}

static void pendulum_field(const long double *x, long double *dx) {
    dx[0] = -x[1] * x[2];
    dx[1] = x[0] * x[2];
    dx[2] = -x[0];
}

typedef void (*field_fn)(const long double *, long double *);

static void rk4_long(field_fn f, long double *x, long double T, long steps) {
    long double k1[3], k2[3], k3[3], k4[3], y[3];
    const long double h = T / steps;
    for (long s = 0; s < steps; ++s) {
        f(x, k1);
        for (int i = 0; i < 3; ++i) y[i] = x[i] + h / 2 * k1[i];
        f(y, k2);
        for (int i = 0; i < 3; ++i) y[i] = x[i] + h / 2 * k2[i];
        f(y, k3);
        for (int i = 0; i < 3; ++i) y[i] = x[i] + h * k3[i];
        f(y, k4);
        for (int i = 0; i < 3; ++i) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
}

/* The error of a run is the largest distance from the reference over K
 * equally spaced checkpoints (one final time alone can hit a lucky phase). */
enum { K = 8 };

typedef struct {
    int pendulum;
    double x0[3];
    double T;
    double ref[K][3];
    double ref_error; /* estimated error of the reference */
} scene;

static void make_scene(scene *s, int pendulum, double T) {
    s->pendulum = pendulum;
    s->T = T;
    if (pendulum) {
        s->x0[0] = sin(2.0); s->x0[1] = -cos(2.0); s->x0[2] = 0.3;
    } else {
        s->x0[0] = 1.0; s->x0[1] = 0.5; s->x0[2] = -0.3;
    }
    /* h = 1/16384: the reference's error, about d/15 for the difference d
     * from a run with 2h, is checked to be far below the errors fitted. */
    long double x[3] = {s->x0[0], s->x0[1], s->x0[2]}, half[3];
    memcpy(half, x, sizeof x);
    const long steps = (long)(T / K * 16384);
    for (int k = 0; k < K; ++k) {
        rk4_long(pendulum ? pendulum_field : rigid_body_field, x, T / K, steps);
        for (int i = 0; i < 3; ++i) s->ref[k][i] = (double)x[i];
    }
    rk4_long(pendulum ? pendulum_field : rigid_body_field, half, T, K * steps / 2);
    long double d = 0;
    for (int i = 0; i < 3; ++i) d += fabsl(half[i] - x[i]);
    s->ref_error = (double)(d / 15); /* RK4: err(h) ~ (x(2h) - x(h)) / 15 */
}

static lpi_system *make_system(int pendulum) {
    lpi_system *sys = NULL;
    assert_int_equal(pendulum ? lpi_pendulum_create(&sys) : lpi_rigid_body_create(&sys, 1, 2, 3),
                     LPI_OK);
    return sys;
}

/* Error of n steps per checkpoint (dt = T / (K n)). */
static double scene_error(lpi_system *sys, const scene *s, long n) {
    double x[3], worst = 0;
    assert_int_equal(lpi_set_state(sys, s->x0, 3), LPI_OK);
    for (int k = 0; k < K; ++k) {
        assert_int_equal(lpi_step(sys, s->T / (K * (double)n), n), LPI_OK);
        assert_int_equal(lpi_get_state(sys, x, 3), LPI_OK);
        const double e = lpi_test_distance(x, s->ref[k], 3);
        if (e > worst) worst = e;
    }
    return worst;
}

/* ---- the registry ----------------------------------------------------------- */

static const struct {
    const char *name;
    int order, stages;
} kExpected[] = {
    {"lie-trotter", 1, 1},    {"lie-trotter-adjoint", 1, 1},    {"leapfrog", 2, 1},
    {"triple-jump-4", 4, 3},  {"suzuki-4", 4, 5},               {"mclachlan-4", 4, 5},
    {"yoshida-6", 6, 7},      {"kahan-li-6", 6, 9},             {"yoshida-8", 8, 15},
    {"mclachlan-8", 8, 15},   {"kahan-li-8", 8, 17},            {"sofroniou-spaletta-10", 10, 35},
    {"rk4", 4, 1},            {"implicit-midpoint", 2, 1},      {"isomp", 2, 1},
    {"rk4-matrix", 4, 1},     {"direct-eq5", 4, 1},
};
enum { kExpectedCount = sizeof kExpected / sizeof kExpected[0] };

static void test_registry(void **state) {
    (void)state;
    assert_int_equal(lpi_method_count(), kExpectedCount);
    for (int i = 0; i < kExpectedCount; ++i) {
        assert_string_equal(lpi_method_name(i), kExpected[i].name);
        assert_int_equal(lpi_method_order(i), kExpected[i].order);
        assert_int_equal(lpi_method_stages(i), kExpected[i].stages);
        const char *ref = lpi_method_reference(i);
        assert_non_null(ref);
        assert_true(strlen(ref) > 10);
    }
    assert_non_null(strstr(lpi_method_reference(8), "Table 2, solution D"));
    assert_non_null(strstr(lpi_method_reference(6), "Table 1, solution A"));
    assert_int_equal(lpi_method_stages(-1), -1);
    assert_int_equal(lpi_method_stages(kExpectedCount), -1);
    assert_null(lpi_method_reference(-1));
    assert_null(lpi_method_reference(kExpectedCount));
}

/* Recursive names are built on demand; malformed ones are refused. */
static void test_recursive_names(void **state) {
    (void)state;
    lpi_system *sys = make_system(0);
    const struct { const char *name; size_t flows; } good[] = {
        {"triple-jump-2", 2}, {"triple-jump-6", 18}, {"triple-jump-16", 2 * 2187},
        {"suzuki-2", 2},      {"suzuki-6", 50},      {"suzuki-8", 250},
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; ++i) {
        size_t flows = 0;
        assert_int_equal(lpi_set_method(sys, good[i].name), LPI_OK);
        assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
        assert_int_equal(flows, good[i].flows);
    }
    const char *bad[] = {"triple-jump-5", "triple-jump-18", "triple-jump-0", "triple-jump-",
                         "triple-jump-06", "triple-jump-4x", "suzuki-3", "suzuki--4",
                         "suzuki-100", "suzuki-4 "};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        LPI_ASSERT_FAILS(sys, lpi_set_method(sys, bad[i]), LPI_ERR_INVALID, "lpi_set_method");
        assert_non_null(strstr(lpi_last_error(sys), bad[i]));
    }
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "triple-jump-7"), LPI_ERR_INVALID, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "must be even, from 2 to 16"));
    /* A malformed order is an unknown name, not a wrong order (p = 4 is
     * right), and control characters are shown escaped, on one line. */
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "triple-jump-4 "), LPI_ERR_INVALID, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "unknown method 'triple-jump-4 ' (known: "));
    assert_null(strstr(lpi_last_error(sys), "must be even"));
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "leapfrog\n\x01"), LPI_ERR_INVALID, "lpi_set_method");
    assert_non_null(strstr(lpi_last_error(sys), "unknown method 'leapfrog\\n\\x01' (known: "));
    assert_null(strchr(lpi_last_error(sys), '\n'));
    LPI_ASSERT_FAILS(sys, lpi_set_method(sys, "custom"), LPI_ERR_INVALID, "lpi_set_method");
    lpi_destroy(sys);
}

/* First-same-as-last: a symmetric composition of s leapfrog stages over p
 * pieces costs s (2p - 2) flows per step, not s (2p - 1). */
static void test_flows_per_step(void **state) {
    (void)state;
    const struct { int pendulum; const char *split, *method; size_t flows; } cases[] = {
        {0, "casimir-shift", "leapfrog", 2},     {0, "casimir-shift", "lie-trotter", 2},
        {0, "casimir-shift", "triple-jump-4", 6}, {0, "casimir-shift", "yoshida-8", 30},
        {0, "casimir-shift", "sofroniou-spaletta-10", 70},
        {0, "axes", "leapfrog", 4},              {0, "axes", "lie-trotter", 3},
        {0, "axes", "kahan-li-6", 36},           {0, "axes", "rk4", 4},
        {1, NULL, "leapfrog", 2},                {1, NULL, "mclachlan-4", 10},
        {1, NULL, "rk4", 4},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        lpi_system *sys = make_system(cases[i].pendulum);
        if (cases[i].split) assert_int_equal(lpi_set_split(sys, cases[i].split), LPI_OK);
        assert_int_equal(lpi_set_method(sys, cases[i].method), LPI_OK);
        size_t flows = 0;
        assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
        if (flows != cases[i].flows)
            fail_msg("%s (%s): %zu flows per step, expected %zu", cases[i].method,
                     cases[i].split ? cases[i].split : "pendulum", flows, cases[i].flows);
        lpi_destroy(sys);
    }
    size_t flows = 7;
    LPI_ASSERT_FAILS(NULL, lpi_flows_per_step(NULL, &flows), LPI_ERR_NULL, "lpi_flows_per_step");
    assert_int_equal(flows, 7);
    lpi_system *sys = make_system(0);
    LPI_ASSERT_FAILS(sys, lpi_flows_per_step(sys, NULL), LPI_ERR_NULL, "lpi_flows_per_step");
    assert_non_null(strstr(lpi_last_error(sys), "out is NULL"));
    lpi_destroy(sys);
}

/* ---- user compositions -------------------------------------------------------- */

static void run(lpi_system *sys, const double *x0, double dt, int64_t n, double *out) {
    assert_int_equal(lpi_set_state(sys, x0, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, dt, n), LPI_OK);
    assert_int_equal(lpi_get_state(sys, out, 3), LPI_OK);
}

static void test_set_composition(void **state) {
    (void)state;
    const double x0[3] = {1.0, 0.5, -0.3};
    double a[3], b[3];
    lpi_system *sys = make_system(0), *ref = make_system(0);
    /* {1} is leapfrog, bit for bit. */
    const double one[1] = {1.0};
    assert_int_equal(lpi_set_composition(sys, 1, one), LPI_OK);
    run(sys, x0, 0.1, 100, a);
    run(ref, x0, 0.1, 100, b);
    assert_memory_equal(a, b, sizeof a);
    /* {1/2, 1/2} over dt is leapfrog over dt/2, bit for bit (flows merge). */
    const double halves[2] = {0.5, 0.5};
    assert_int_equal(lpi_set_composition(sys, 2, halves), LPI_OK);
    size_t flows = 0;
    assert_int_equal(lpi_flows_per_step(sys, &flows), LPI_OK);
    assert_int_equal(flows, 4);
    run(sys, x0, 0.1, 100, a);
    run(ref, x0, 0.05, 200, b);
    assert_memory_equal(a, b, sizeof a);
    /* A user's own triple jump converges at order 4. */
    const double w1 = 1.0 / (2.0 - cbrt(2.0));
    const double tj[3] = {w1, 1.0 - 2.0 * w1, w1};
    assert_int_equal(lpi_set_composition(sys, 3, tj), LPI_OK);
    scene s;
    make_scene(&s, 0, 16.0);
    double steps[4], errors[4];
    const long ns[4] = {16, 20, 25, 32};
    for (int i = 0; i < 4; ++i) {
        steps[i] = s.T / (K * (double)ns[i]);
        errors[i] = scene_error(sys, &s, ns[i]);
    }
    const double order = lpi_fit_order(steps, errors, 4);
    assert_true(fabs(order - 4.0) < 0.3);
    /* Mirrored pairs within the tolerance are accepted (and averaged). */
    const double nearly[3] = {0.25 * (1 + 4e-15), 0.5, 0.25};
    assert_int_equal(lpi_set_composition(sys, 3, nearly), LPI_OK);
    lpi_destroy(sys);
    lpi_destroy(ref);
}

/* Bad input: exact status, a message naming the function and the fault, and
 * the handle as it was (state, time and method). */
static void test_set_composition_bad_input(void **state) {
    (void)state;
    const double x0[3] = {1.0, 0.5, -0.3};
    lpi_system *sys = make_system(0);
    assert_int_equal(lpi_set_method(sys, "yoshida-6"), LPI_OK);
    assert_int_equal(lpi_set_state(sys, x0, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 3), LPI_OK);
    const double good[3] = {0.25, 0.5, 0.25};
    LPI_ASSERT_FAILS(NULL, lpi_set_composition(NULL, 3, good), LPI_ERR_NULL, "lpi_set_composition");
    assert_non_null(strstr(lpi_last_error(NULL), "system is NULL"));

    const struct {
        size_t n;
        double g[5];
        int status;
        const char *detail;
    } bad[] = {
        {0, {1.0}, LPI_ERR_INVALID, "n >= 1"},
        {3, {0.25, NAN, 0.25}, LPI_ERR_NONFINITE, "gammas[1]"},
        {3, {INFINITY, 0.5, 0.25}, LPI_ERR_NONFINITE, "gammas[0]"},
        {3, {0.3, 0.5, 0.3}, LPI_ERR_INVALID, "sum to 1.1"},
        {1, {0.999999}, LPI_ERR_INVALID, "not 1"},
        {3, {0.25 + 1e-13, 0.5 - 1e-13, 0.25}, LPI_ERR_INVALID, "not symmetric"},
        {4, {0.2, 0.3, 0.2, 0.3}, LPI_ERR_INVALID, "gammas[0] = 0.20000000000000001 but gammas[3]"},
        {5, {0.28, 0.62546642846767, -0.81093285693534, 0.28, 0.62546642846767}, LPI_ERR_INVALID,
         "not symmetric"},
        /* Huge weights whose sum is off by far more than 1e-10 (1e-14 of
         * their magnitude would pass them): not consistent. */
        {3, {1e14, -2e14, 1e14}, LPI_ERR_INVALID, "sum to 0,"},
        {3, {1e13, 1.0 - 2e13 + 0.05, 1e13}, LPI_ERR_INVALID, "to 1e-10 at most"},
    };
    size_t flows_before = 0, flows_after = 0;
    assert_int_equal(lpi_flows_per_step(sys, &flows_before), LPI_OK);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        LPI_ASSERT_FAILS(sys, lpi_set_composition(sys, bad[i].n, bad[i].g), bad[i].status,
                         "lpi_set_composition");
        if (!strstr(lpi_last_error(sys), bad[i].detail))
            fail_msg("case %zu: message '%s' lacks '%s'", i, lpi_last_error(sys), bad[i].detail);
        assert_int_equal(lpi_flows_per_step(sys, &flows_after), LPI_OK);
        assert_int_equal(flows_after, flows_before); /* still yoshida-6 */
    }
    LPI_ASSERT_FAILS(sys, lpi_set_composition(sys, 3, NULL), LPI_ERR_NULL, "lpi_set_composition");
    assert_non_null(strstr(lpi_last_error(sys), "gammas is NULL"));
    /* The method is unchanged: the next steps match an untouched yoshida-6 run. */
    lpi_system *ref = make_system(0);
    assert_int_equal(lpi_set_method(ref, "yoshida-6"), LPI_OK);
    double a[3], b[3];
    assert_int_equal(lpi_set_state(ref, x0, 3), LPI_OK);
    assert_int_equal(lpi_step(ref, 0.1, 3), LPI_OK);
    assert_int_equal(lpi_step(sys, 0.1, 5), LPI_OK);
    assert_int_equal(lpi_step(ref, 0.1, 5), LPI_OK);
    assert_int_equal(lpi_get_state(sys, a, 3), LPI_OK);
    assert_int_equal(lpi_get_state(ref, b, 3), LPI_OK);
    assert_memory_equal(a, b, sizeof a);
    lpi_destroy(ref);
    lpi_destroy(sys);
}

/* ---- measured orders ------------------------------------------------------------ */

/* Per method and system: the time T and four step counts per checkpoint,
 * chosen in the asymptotic range and with every error at least ~10x above
 * the round-off floor (~1e-15 here). High orders need large steps (orders 8
 * and 10) or long times for their errors to stand clear of round-off. */
typedef struct {
    const char *method;
    int order;
    double T;
    long n[4];
} order_case;

static const order_case kRigidBody[] = {
    {"lie-trotter", 1, 16, {16, 20, 25, 32}},       {"lie-trotter-adjoint", 1, 16, {16, 20, 25, 32}},
    {"leapfrog", 2, 16, {8, 10, 13, 16}},           {"rk4", 4, 16, {8, 10, 13, 16}},
    {"triple-jump-4", 4, 16, {16, 20, 25, 32}},     {"suzuki-4", 4, 16, {8, 10, 13, 16}},
    {"mclachlan-4", 4, 16, {8, 10, 13, 16}},        {"yoshida-6", 6, 16, {4, 5, 6, 8}},
    {"kahan-li-6", 6, 16, {4, 5, 6, 8}},            {"triple-jump-6", 6, 16, {6, 8, 10, 12}},
    {"suzuki-6", 6, 16, {3, 4, 5, 6}},              {"yoshida-8", 8, 16, {10, 13, 16, 20}},
    {"mclachlan-8", 8, 16, {3, 4, 5, 6}},           {"kahan-li-8", 8, 16, {3, 4, 5, 6}},
    {"triple-jump-8", 8, 16, {16, 20, 25, 32}},     {"suzuki-8", 8, 128, {16, 20, 25, 32}},
    {"sofroniou-spaletta-10", 10, 400, {50, 63, 79, 100}},
    {"triple-jump-10", 10, 16, {5, 6, 8, 10}},
    {"implicit-midpoint", 2, 16, {8, 10, 13, 16}},
};

static const order_case kPendulum[] = {
    {"lie-trotter", 1, 16, {32, 40, 50, 64}},       {"lie-trotter-adjoint", 1, 16, {32, 40, 50, 64}},
    {"leapfrog", 2, 16, {8, 10, 13, 16}},           {"rk4", 4, 16, {128, 161, 203, 256}},
    {"triple-jump-4", 4, 16, {16, 20, 25, 32}},     {"suzuki-4", 4, 16, {8, 10, 13, 16}},
    {"mclachlan-4", 4, 16, {16, 20, 25, 32}},       {"yoshida-6", 6, 16, {8, 10, 13, 16}},
    {"kahan-li-6", 6, 16, {6, 8, 10, 12}},          {"triple-jump-6", 6, 16, {12, 15, 19, 24}},
    {"suzuki-6", 6, 16, {6, 8, 10, 12}},            {"yoshida-8", 8, 16, {16, 20, 25, 32}},
    {"mclachlan-8", 8, 16, {8, 10, 13, 16}},        {"kahan-li-8", 8, 16, {8, 10, 13, 16}},
    {"triple-jump-8", 8, 16, {20, 25, 32, 40}},     {"suzuki-8", 8, 128, {40, 50, 63, 80}},
    {"sofroniou-spaletta-10", 10, 16, {6, 7, 8, 9}},
    {"triple-jump-10", 10, 16, {20, 25, 32, 40}},
    {"implicit-midpoint", 2, 16, {32, 40, 50, 64}},
};

static void check_orders(int pendulum, const order_case *cases, size_t count) {
    lpi_system *sys = make_system(pendulum);
    scene s;
    s.T = -1;
    for (size_t c = 0; c < count; ++c) {
        if (cases[c].T != s.T) make_scene(&s, pendulum, cases[c].T);
        assert_int_equal(lpi_set_method(sys, cases[c].method), LPI_OK);
        double steps[4], errors[4];
        for (int i = 0; i < 4; ++i) {
            steps[i] = s.T / (K * (double)cases[c].n[i]);
            errors[i] = scene_error(sys, &s, cases[c].n[i]);
            if (errors[i] < 1e-14) /* round-off must not dominate the fit */
                fail_msg("%s: error %.2e at dt = %.3g is at round-off level", cases[c].method,
                         errors[i], steps[i]);
            if (errors[i] < 1000 * s.ref_error)
                fail_msg("%s: error %.2e is not far above the reference's %.2e", cases[c].method,
                         errors[i], s.ref_error);
        }
        const double order = lpi_fit_order(steps, errors, 4);
        print_message("%-10s %-22s order %2d measured %6.3f  (dt %.3g..%.3g, errors %.2e..%.2e)\n",
                      pendulum ? "pendulum" : "rigid body", cases[c].method, cases[c].order, order,
                      steps[0], steps[3], errors[0], errors[3]);
        if (fabs(order - cases[c].order) > 0.3)
            fail_msg("%s: measured order %.3f, nominal %d", cases[c].method, order, cases[c].order);
    }
    lpi_destroy(sys);
}

static void test_orders_rigid_body(void **state) {
    (void)state;
    check_orders(0, kRigidBody, sizeof kRigidBody / sizeof kRigidBody[0]);
}

static void test_orders_pendulum(void **state) {
    (void)state;
    check_orders(1, kPendulum, sizeof kPendulum / sizeof kPendulum[0]);
}

/* Every listed method is measured on both systems (rk4 included), except
 * those the systems refuse: the sine-Euler matrix-form baselines give
 * LPI_ERR_UNSUPPORTED here and are measured in test_sine_euler_baselines. */
static void test_every_method_is_measured(void **state) {
    (void)state;
    lpi_system *probe = make_system(0);
    for (int i = 0; i < lpi_method_count(); ++i) {
        if (lpi_set_method(probe, lpi_method_name(i)) == LPI_ERR_UNSUPPORTED) continue;
        int found = 0;
        for (size_t c = 0; c < sizeof kRigidBody / sizeof kRigidBody[0]; ++c)
            found += strcmp(kRigidBody[c].method, lpi_method_name(i)) == 0;
        for (size_t c = 0; c < sizeof kPendulum / sizeof kPendulum[0]; ++c)
            found += strcmp(kPendulum[c].method, lpi_method_name(i)) == 0;
        if (found != 2) fail_msg("%s is not measured on both systems", lpi_method_name(i));
    }
    lpi_destroy(probe);
}

/* ---- invariants ------------------------------------------------------------------- */

static const char *const kPoissonExtra[] = {"triple-jump-6", "triple-jump-8", "triple-jump-10",
                                            "suzuki-6", "suzuki-8", "strang"};

static double casimir_drift(lpi_system *sys, const double *x0, double dt, int64_t steps) {
    double c0, c;
    assert_int_equal(lpi_set_state(sys, x0, 3), LPI_OK);
    assert_int_equal(lpi_casimirs(sys, &c0, 1), LPI_OK);
    assert_int_equal(lpi_step(sys, dt, steps), LPI_OK);
    assert_int_equal(lpi_casimirs(sys, &c, 1), LPI_OK);
    return fabs(c - c0) / fabs(c0);
}

static void test_casimirs_every_method(void **state) {
    (void)state;
    const double m0[3] = {1.0, 0.5, -0.3}, p0[3] = {sin(2.0), -cos(2.0), 0.3};
    for (int pendulum = 0; pendulum < 2; ++pendulum) {
        lpi_system *sys = make_system(pendulum);
        const int count = lpi_method_count() + (int)(sizeof kPoissonExtra / sizeof kPoissonExtra[0]);
        for (int i = 0; i < count; ++i) {
            const char *name = i < lpi_method_count() ? lpi_method_name(i)
                                                       : kPoissonExtra[i - lpi_method_count()];
            if (!lpi_method_is_poisson(i < lpi_method_count() ? i : 0) && i < lpi_method_count())
                continue; /* the baselines are not Poisson maps */
            assert_int_equal(lpi_set_method(sys, name), LPI_OK);
            const double drift = casimir_drift(sys, pendulum ? p0 : m0, 0.1, 20000);
            if (drift > 1e-13) fail_msg("%s: Casimir drift %.3e", name, drift);
        }
        /* And a user composition. */
        const double g[5] = {0.2, 0.2, 0.2, 0.2, 0.2};
        assert_int_equal(lpi_set_composition(sys, 5, g), LPI_OK);
        assert_true(casimir_drift(sys, pendulum ? p0 : m0, 0.1, 20000) <= 1e-13);
        /* The control: rk4 does drift. */
        assert_int_equal(lpi_set_method(sys, "rk4"), LPI_OK);
        assert_true(casimir_drift(sys, pendulum ? p0 : m0, 0.1, 20000) > 1e-10);
        lpi_destroy(sys);
    }
}

/* Energy error bounded over 10^6 steps: the worst error of the whole run is
 * within 1.5x of the worst over its first tenth (drift would give ~10x). */
static void test_energy_bounded(void **state) {
    (void)state;
    const struct { const char *method; double dt; } cases[] = {
        {"leapfrog", 0.05},   {"triple-jump-4", 0.1}, {"suzuki-4", 0.1},
        {"mclachlan-4", 0.1}, {"yoshida-6", 0.2},     {"kahan-li-6", 0.2},
    };
    const double m0[3] = {1.0, 0.5, -0.3}, p0[3] = {sin(2.0), -cos(2.0), 0.3};
    for (int pendulum = 0; pendulum < 2; ++pendulum) {
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
            lpi_system *sys = make_system(pendulum);
            assert_int_equal(lpi_set_method(sys, cases[c].method), LPI_OK);
            assert_int_equal(lpi_set_state(sys, pendulum ? p0 : m0, 3), LPI_OK);
            double h0, h, first = 0, all = 0;
            assert_int_equal(lpi_energy(sys, &h0), LPI_OK);
            for (int k = 1; k <= 1000; ++k) {
                assert_int_equal(lpi_step(sys, cases[c].dt, 1000), LPI_OK);
                assert_int_equal(lpi_energy(sys, &h), LPI_OK);
                const double e = fabs((h - h0) / h0);
                if (k <= 100 && e > first) first = e;
                if (e > all) all = e;
            }
            print_message("%-10s %-14s dt %.2f: energy error %.2e over 10^6 steps (first tenth %.2e)\n",
                          pendulum ? "pendulum" : "rigid body", cases[c].method, cases[c].dt, all,
                          first);
            assert_true(first > 1e-12); /* well above round-off, so the test can see growth */
            if (all > 1.5 * first)
                fail_msg("%s: energy error grows: %.3e over the run vs %.3e in the first tenth",
                         cases[c].method, all, first);
            lpi_destroy(sys);
        }
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry),
        cmocka_unit_test(test_recursive_names),
        cmocka_unit_test(test_flows_per_step),
        cmocka_unit_test(test_set_composition),
        cmocka_unit_test(test_set_composition_bad_input),
        cmocka_unit_test(test_every_method_is_measured),
        cmocka_unit_test(test_orders_rigid_body),
        cmocka_unit_test(test_orders_pendulum),
        cmocka_unit_test(test_casimirs_every_method),
        cmocka_unit_test(test_energy_bounded),
    };
    return lpi_run_tests(tests);
}
