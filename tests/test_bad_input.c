/* Every public function against every class of bad input: NULL handle, NULL
 * buffers, wrong sizes, NaN/Inf, out-of-range values, the wrong kind of
 * system, the wrong call order, failing user callbacks, bad files. Each case
 * checks the documented status, a message naming the function, and that the
 * handle is unchanged to the bit (its whole checkpoint where it has one:
 * state with the compensated carry, time, method, split). Functions that
 * return values instead of a status are checked for their documented
 * sentinel. The table must name every lpi_* function the header declares
 * (argv[1] is the header): the test fails when the header grows.
 * Prints the number of cases. */
#include <ctype.h>
#include <limits.h>

#include "lpi_test.h"

/* ---- the handles the cases act on --------------------------------------- */

enum target {
    NONE,     /* sys = NULL */
    RB,       /* rigid body, stepped (nonzero time and carry) */
    PEND,     /* pendulum, stepped */
    RB_RK4,   /* rigid body with rk4 (blows up at a huge step) */
    RB_IMP,   /* rigid body with implicit-midpoint and max_iterations = 1 */
    GEN,      /* generic so(3) with one good piece */
    GEN_FAIL, /* generic so(3) whose piece and Casimir callbacks fail */
    GEN_EMPTY,/* generic so(3) with no pieces yet */
    MOM,      /* the moment algebra, no pieces */
    SE,       /* sine-Euler N = 9, stepped */
    SE_RK4,   /* sine-Euler N = 5 with rk4 */
    SE_IMP,   /* sine-Euler N = 5 with implicit-midpoint */
    RB_HUGE,  /* rigid body at |m| ~ 1e200: energy and Casimir overflow */
    SE_HUGE,  /* sine-Euler N = 5 with modes 1e308: every derived value overflows */
    TARGETS
};
static const char *const kTargetName[TARGETS] = {"NULL", "rigid body", "pendulum", "rigid body/rk4",
    "rigid body/implicit", "generic", "generic (failing callbacks)", "generic (no pieces)",
    "moments", "sine-Euler", "sine-Euler/rk4", "sine-Euler/implicit", "rigid body (huge)",
    "sine-Euler (huge)"};
static lpi_system *handles[TARGETS];
static int have_fftw;

static int grad_ok(size_t n, const double *x, double *g, void *u) {
    (void)u;
    for (size_t q = 0; q < n; ++q) g[q] = x[q];
    return 0;
}
static int energy_ok(size_t n, const double *x, double *h, void *u) {
    (void)u;
    *h = 0;
    for (size_t q = 0; q < n; ++q) *h += 0.5 * x[q] * x[q];
    return 0;
}
static int grad_fail(size_t n, const double *x, double *g, void *u) {
    (void)n, (void)x, (void)g, (void)u;
    return 1;
}
static int energy_fail(size_t n, const double *x, double *h, void *u) {
    (void)n, (void)x, (void)h, (void)u;
    return 1;
}
static int casimir_fail(size_t d, const double *x, double *out, void *u) {
    (void)d, (void)x, (void)out, (void)u;
    return 1;
}
static int scalar_ok(double u, double *out, void *user) {
    (void)user;
    *out = u;
    return 0;
}

/* so(3): {x0,x1} = x2, {x1,x2} = x0, {x2,x0} = x1. */
static const int32_t kI[] = {0, 1, 2}, kJ[] = {1, 2, 0}, kK[] = {2, 0, 1};
static const double kC[] = {1, 1, 1};

static lpi_system *so3(void) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_generic_create(&sys, 3, 3, kI, kJ, kK, kC), LPI_OK);
    const double x[3] = {0.3, -0.2, 0.9};
    assert_int_equal(lpi_set_state(sys, x, 3), LPI_OK);
    return sys;
}

static void make_handles(void) {
    const double m[3] = {0.3, 1.1, -0.7};
    assert_int_equal(lpi_rigid_body_create(&handles[RB], 1.0, 2.0, 3.5), LPI_OK);
    assert_int_equal(lpi_set_state(handles[RB], m, 3), LPI_OK);
    assert_int_equal(lpi_step(handles[RB], 0.01, 100), LPI_OK);
    assert_int_equal(lpi_pendulum_create(&handles[PEND]), LPI_OK);
    assert_int_equal(lpi_set_state(handles[PEND], m, 3), LPI_OK);
    assert_int_equal(lpi_step(handles[PEND], 0.05, 100), LPI_OK);
    assert_int_equal(lpi_rigid_body_create(&handles[RB_RK4], 1.0, 2.0, 3.5), LPI_OK);
    assert_int_equal(lpi_set_state(handles[RB_RK4], m, 3), LPI_OK);
    assert_int_equal(lpi_set_method(handles[RB_RK4], "rk4"), LPI_OK);
    assert_int_equal(lpi_step(handles[RB_RK4], 0.01, 10), LPI_OK);
    assert_int_equal(lpi_rigid_body_create(&handles[RB_IMP], 1.0, 2.0, 3.5), LPI_OK);
    assert_int_equal(lpi_set_state(handles[RB_IMP], m, 3), LPI_OK);
    assert_int_equal(lpi_set_method(handles[RB_IMP], "implicit-midpoint"), LPI_OK);
    assert_int_equal(lpi_set_implicit_options(handles[RB_IMP], 1e-14, 1), LPI_OK);
    const int32_t sigma[] = {0};
    handles[GEN] = so3();
    assert_int_equal(lpi_add_piece(handles[GEN], 1, sigma, grad_ok, energy_ok, NULL), LPI_OK);
    assert_int_equal(lpi_step(handles[GEN], 0.1, 5), LPI_OK);
    handles[GEN_FAIL] = so3();
    assert_int_equal(lpi_add_piece(handles[GEN_FAIL], 1, sigma, grad_fail, energy_fail, NULL), LPI_OK);
    assert_int_equal(lpi_add_casimir(handles[GEN_FAIL], casimir_fail, NULL), LPI_OK);
    handles[GEN_EMPTY] = so3();
    assert_int_equal(lpi_moments_create(&handles[MOM]), LPI_OK);
    const double huge[3] = {1e200, -1e200, 1e200};
    assert_int_equal(lpi_rigid_body_create(&handles[RB_HUGE], 1.0, 2.0, 3.5), LPI_OK);
    assert_int_equal(lpi_set_state(handles[RB_HUGE], huge, 3), LPI_OK);
    const int status = lpi_sine_euler_create(&handles[SE], 9);
    have_fftw = status == LPI_OK;
    if (!have_fftw) {
        assert_int_equal(status, LPI_ERR_UNSUPPORTED);
        return;
    }
    double grid[81];
    for (int q = 0; q < 81; ++q) grid[q] = sin(0.7 * q) + 0.3 * cos(1.9 * q);
    assert_int_equal(lpi_sine_euler_set_grid(handles[SE], grid, 81), LPI_OK);
    assert_int_equal(lpi_step(handles[SE], 0.01, 3), LPI_OK);
    const char *methods[2] = {"rk4", "implicit-midpoint"};
    for (int t = SE_RK4; t <= SE_IMP; ++t) {
        assert_int_equal(lpi_sine_euler_create(&handles[t], 5), LPI_OK);
        assert_int_equal(lpi_sine_euler_set_grid(handles[t], grid, 25), LPI_OK);
        assert_int_equal(lpi_set_method(handles[t], methods[t - SE_RK4]), LPI_OK);
    }
    /* Public coordinates: Re w_(0,1) = Re w_(0,2) = 1e308 (and conjugates). */
    double x[25] = {0};
    x[1] = x[3] = 1e308;
    assert_int_equal(lpi_sine_euler_create(&handles[SE_HUGE], 5), LPI_OK);
    assert_int_equal(lpi_set_state(handles[SE_HUGE], x, 25), LPI_OK);
}

/* ---- arguments, invokers and the table ---------------------------------- */

/* One case's arguments; each invoker reads the fields its function takes.
 * nul: which pointer arguments are NULL, in the order of the signature
 * (P1 = the first pointer argument after the handle, or *out for creators). */
enum { P1 = 1, P2 = 2, P3 = 4, P4 = 8, P5 = 16 };
typedef struct {
    int target;
    unsigned nul;
    const char *s;
    double a, b, c;
    int64_t k;
    size_t n, m;
    const double *x;
    const int32_t *i, *j, *kk;
    const void *bytes;
} args;

typedef int (*invoker)(lpi_system *sys, const args *a, lpi_system **out);

enum { SENTINEL = 1000 }; /* expected value of cases checked by their sentinel */

typedef struct {
    const char *function;
    const char *input;
    int expected;
    invoker call;
    args a;
} bad_case;

static double out_buf[8192];
static size_t out_size;
static double out_d1, out_d2;
static char out_text[16];

#define PTR(flag, p) ((a->nul & (flag)) ? NULL : (p))

/* Sentinel invokers return 1 when the documented value came back. */
static int call_lpi_version_string(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)a, (void)o;
    return lpi_version_string() != NULL && strlen(lpi_version_string()) >= 5;
}
static int call_lpi_version_number(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)a, (void)o;
    return lpi_version_number() == LPI_VERSION_NUMBER;
}
static int call_lpi_status_name(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return strcmp(lpi_status_name((int)a->k), "LPI_UNKNOWN_STATUS") == 0;
}
static int call_lpi_status_message(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return strcmp(lpi_status_message((int)a->k), "unknown status code") == 0;
}
static int call_lpi_method_count(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)a, (void)o;
    return lpi_method_count() > 0;
}
static int call_lpi_method_name(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_method_name((int)a->k) == NULL;
}
static int call_lpi_method_order(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_method_order((int)a->k) == -1;
}
static int call_lpi_method_is_poisson(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_method_is_poisson((int)a->k) == -1;
}
static int call_lpi_method_stages(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_method_stages((int)a->k) == -1;
}
static int call_lpi_method_reference(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_method_reference((int)a->k) == NULL;
}
static int call_lpi_destroy(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)a, (void)o;
    return lpi_destroy(NULL) == LPI_OK;
}
static int call_lpi_dim(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return lpi_dim(s) == 0;
}
static int call_lpi_time(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return isnan(lpi_time(s));
}
static int call_lpi_kind(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return lpi_kind(s) == NULL;
}
static int call_lpi_get_method(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return lpi_get_method(s) == NULL;
}
static int call_lpi_get_split(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return lpi_get_split(s) == NULL;
}
static int call_lpi_casimir_count(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return lpi_casimir_count(s) == 0;
}
static int call_lpi_last_error(lpi_system *s, const args *a, lpi_system **o) {
    (void)a, (void)o;
    return lpi_last_error(s) != NULL;
}

/* Status invokers. */
static int call_lpi_rigid_body_create(lpi_system *s, const args *a, lpi_system **o) {
    (void)s;
    return lpi_rigid_body_create(PTR(P1, o), a->a, a->b, a->c);
}
static int call_lpi_rigid_body_exact(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_rigid_body_exact(s, a->a, PTR(P1, out_buf));
}
static int call_lpi_pendulum_create(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)a;
    return lpi_pendulum_create(PTR(P1, o));
}
static int call_lpi_set_method(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_method(s, a->s);
}
static int call_lpi_set_split(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_split(s, a->s);
}
static int call_lpi_set_state(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_state(s, a->x, a->n);
}
static int call_lpi_get_state(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_get_state(s, PTR(P1, out_buf), a->n);
}
static int observe_nothing(const lpi_system *s, int64_t step, double t, void *user) {
    (void)s, (void)step, (void)t, (void)user;
    return 0;
}
static int call_lpi_set_observer(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_observer(s, a->k, PTR(P1, observe_nothing), NULL);
}
static int call_lpi_step(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_step(s, a->a, a->k);
}
static int call_lpi_energy(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_energy(s, PTR(P1, out_buf));
}
static int call_lpi_casimirs(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_casimirs(s, PTR(P1, out_buf), a->n);
}
static int call_lpi_set_composition(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_composition(s, a->n, a->x);
}
static int call_lpi_flows_per_step(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_flows_per_step(s, PTR(P1, &out_size));
}
static int call_lpi_set_implicit_options(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_implicit_options(s, a->a, (int32_t)a->k);
}
static int call_lpi_generic_create(lpi_system *s, const args *a, lpi_system **o) {
    (void)s;
    return lpi_generic_create(PTR(P1, o), a->n, a->m, a->i, a->j, a->kk, a->x);
}
static int call_lpi_add_piece(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_add_piece(s, a->n, a->i, PTR(P2, grad_ok), PTR(P3, energy_ok), NULL);
}
static int call_lpi_add_casimir(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_add_casimir(s, PTR(P1, casimir_fail), NULL);
}
static int call_lpi_poisson_rank(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_poisson_rank(s, a->x, a->n, PTR(P2, &out_size));
}
static int call_lpi_moments_create(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)a;
    return lpi_moments_create(PTR(P1, o));
}
static int call_lpi_moments_add_product_piece(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_moments_add_product_piece(s, PTR(P1, scalar_ok), PTR(P2, scalar_ok), NULL);
}
static int call_lpi_sine_euler_create(lpi_system *s, const args *a, lpi_system **o) {
    (void)s;
    return lpi_sine_euler_create(PTR(P1, o), (int32_t)a->k);
}
static int call_lpi_sine_euler_size(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    int32_t N;
    return lpi_sine_euler_size(s, PTR(P1, &N));
}
static int call_lpi_sine_euler_set_modes(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_set_modes(s, a->x, a->n);
}
static int call_lpi_sine_euler_get_modes(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_get_modes(s, PTR(P1, out_buf), a->n);
}
static int call_lpi_sine_euler_set_grid(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_set_grid(s, a->x, a->n);
}
static int call_lpi_sine_euler_get_grid(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_get_grid(s, PTR(P1, out_buf), a->n);
}
static int call_lpi_sine_euler_enstrophy(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_enstrophy(s, PTR(P1, out_buf));
}
static int call_lpi_sine_euler_casimir_traces(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_casimir_traces(s, (int32_t)a->k, PTR(P1, out_buf));
}
static int call_lpi_sine_euler_fft_floor(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_fft_floor(s, a->k, PTR(P1, &out_d1), PTR(P2, &out_d2));
}
static int call_lpi_sine_euler_set_planning(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_set_planning(s, a->s);
}
static int call_lpi_sine_euler_get_planning(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    const char *rigor;
    return lpi_sine_euler_get_planning(s, PTR(P1, &rigor));
}
static int call_lpi_sine_euler_set_hamiltonian(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_set_hamiltonian(s, PTR(P1, a->x), a->n, PTR(P2, (const double *)a->bytes), a->m);
}
static int call_lpi_sine_euler_get_stream(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_get_stream(s, PTR(P1, out_buf), a->n);
}
static int call_lpi_sine_euler_spectrum(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_sine_euler_spectrum(s, PTR(P1, out_buf), PTR(P2, out_buf + 4096), a->n, PTR(P3, &out_size));
}
static int call_lpi_set_threads(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_set_threads(s, (int32_t)a->k);
}
static int call_lpi_fftw_wisdom_import_file(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_fftw_wisdom_import_file(a->s);
}
static int call_lpi_fftw_wisdom_export_file(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_fftw_wisdom_export_file(a->s);
}
static int call_lpi_fftw_wisdom_import_string(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_fftw_wisdom_import_string(a->s);
}
static int call_lpi_fftw_wisdom_export_string(lpi_system *s, const args *a, lpi_system **o) {
    (void)s, (void)o;
    return lpi_fftw_wisdom_export_string(PTR(P1, out_text), a->n, PTR(P2, &out_size));
}
static int call_lpi_save(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_save(s, a->s);
}
static int call_lpi_load(lpi_system *s, const args *a, lpi_system **o) {
    (void)s;
    return lpi_load(PTR(P1, o), a->s);
}
static int call_lpi_save_buffer(lpi_system *s, const args *a, lpi_system **o) {
    (void)o;
    return lpi_save_buffer(s, PTR(P1, out_buf), a->n, PTR(P2, &out_size));
}
static int call_lpi_load_buffer(lpi_system *s, const args *a, lpi_system **o) {
    (void)s;
    return lpi_load_buffer(PTR(P1, o), PTR(P2, a->bytes), a->n);
}

/* ---- inputs ---------------------------------------------------------------- */

static const double kState3[3] = {0.1, 0.2, 0.3};
static const double kNaN3[3] = {0.1, NAN, 0.3}, kInf3[3] = {INFINITY, 0.2, 0.3};
static const double kGammasNaN[3] = {0.5, NAN, 0.5};
static const double kGammasAsym[3] = {0.4, 0.1, 0.5};
static const double kGammasSum[3] = {0.5, 0.5, 0.5};
static const double kGammasInf[1] = {INFINITY};
static const double kGammasOverflow[3] = {1.5e308, -1.7e308, 1.5e308}; /* sum test overflows */
static const int32_t kOutOfRange[3] = {0, 1, 3}, kNegative[3] = {0, -1, 2};
static const int32_t kPair01[2] = {0, 1}, kDup[2] = {0, 0}, kSet3[1] = {3}, kSet0[1] = {0};
static const int32_t kSame[1] = {0}, kOne[1] = {1};
static const int32_t kContraI[2] = {0, 1}, kContraJ[2] = {1, 0}, kContraK[2] = {2, 2};
static const int32_t kJacI[2] = {0, 1}, kJacJ[2] = {1, 2}, kJacK[2] = {2, 1};
static const double kOnes2[2] = {1, 1}, kOne1[1] = {1}, kNaN1[1] = {NAN};
static const double kModesNaN[162] = {[5] = NAN};
static const double kModesNotHermitian[162] = {[2] = 1.0};  /* w_(0,1) without its conjugate */
static const double kModesImaginaryW0[162] = {[1] = 1.0};   /* Im w_0 != 0 */
static const double kGridNaN[81] = {[3] = NAN}, kGridInf[81] = {[80] = -INFINITY};
static const double kGrid[81] = {0};
/* N = 9 Hamiltonians: lambda = 0 and f = 0 are valid, the others are not. */
static const double kLambda[81] = {0}, kLambdaNaN[81] = {[7] = NAN};
static const double kLambdaAsymmetric[81] = {[1] = 2.0}; /* lambda_(0,1) != lambda_(0,-1) */
static const double kForce[162] = {0}, kForceInf[162] = {[9] = INFINITY};
static const double kForceNotHermitian[162] = {[3] = 1.0}; /* Im f_(0,1) without its conjugate */
static const unsigned char kNotCheckpoint[40] = "this is not a liepoisson checkpoint....";

#define C(fn, input, expected, tgt, ...) \
    {#fn, input, expected, call_##fn, {.target = tgt, __VA_ARGS__}}

static const bad_case kCases[] = {
    /* functions that need no handle: documented sentinels */
    C(lpi_version_string, "no arguments: never NULL", SENTINEL, NONE),
    C(lpi_version_number, "no arguments: the header's LPI_VERSION_NUMBER", SENTINEL, NONE),
    C(lpi_status_name, "unknown code 12345", SENTINEL, NONE, .k = 12345),
    C(lpi_status_name, "unknown code INT_MIN", SENTINEL, NONE, .k = INT_MIN),
    C(lpi_status_name, "unknown code 2", SENTINEL, NONE, .k = 2),
    C(lpi_status_message, "unknown code 12345", SENTINEL, NONE, .k = 12345),
    C(lpi_status_message, "unknown code -13000", SENTINEL, NONE, .k = -13000),
    C(lpi_method_count, "no arguments", SENTINEL, NONE),
    C(lpi_method_name, "i = -1", SENTINEL, NONE, .k = -1),
    C(lpi_method_name, "i = INT_MAX", SENTINEL, NONE, .k = INT_MAX),
    C(lpi_method_order, "i = -1", SENTINEL, NONE, .k = -1),
    C(lpi_method_order, "i = INT_MIN", SENTINEL, NONE, .k = INT_MIN),
    C(lpi_method_is_poisson, "i = -1", SENTINEL, NONE, .k = -1),
    C(lpi_method_is_poisson, "i = 100000", SENTINEL, NONE, .k = 100000),
    C(lpi_method_stages, "i = -1", SENTINEL, NONE, .k = -1),
    C(lpi_method_stages, "i = 100000", SENTINEL, NONE, .k = 100000),
    C(lpi_method_reference, "i = -1", SENTINEL, NONE, .k = -1),
    C(lpi_method_reference, "i = 100000", SENTINEL, NONE, .k = 100000),
    C(lpi_destroy, "NULL handle: no-op, LPI_OK", SENTINEL, NONE),
    C(lpi_dim, "NULL handle: 0", SENTINEL, NONE),
    C(lpi_time, "NULL handle: NaN", SENTINEL, NONE),
    C(lpi_casimir_count, "NULL handle: 0", SENTINEL, NONE),
    C(lpi_kind, "NULL handle: NULL", SENTINEL, NONE),
    C(lpi_get_method, "NULL handle: NULL", SENTINEL, NONE),
    C(lpi_get_split, "NULL handle: NULL", SENTINEL, NONE),
    C(lpi_last_error, "NULL handle: never NULL", SENTINEL, NONE),

    /* creators */
    C(lpi_rigid_body_create, "NULL out", LPI_ERR_NULL, NONE, .nul = P1, .a = 1, .b = 1, .c = 1),
    C(lpi_rigid_body_create, "NaN I1", LPI_ERR_NONFINITE, NONE, .a = NAN, .b = 1, .c = 1),
    C(lpi_rigid_body_create, "Inf I2", LPI_ERR_NONFINITE, NONE, .a = 1, .b = INFINITY, .c = 1),
    C(lpi_rigid_body_create, "-Inf I3", LPI_ERR_NONFINITE, NONE, .a = 1, .b = 1, .c = -INFINITY),
    C(lpi_rigid_body_create, "I1 = 0", LPI_ERR_INVALID, NONE, .a = 0, .b = 1, .c = 1),
    C(lpi_rigid_body_create, "I2 < 0", LPI_ERR_INVALID, NONE, .a = 1, .b = -2, .c = 1),
    C(lpi_rigid_body_create, "I3 = -0", LPI_ERR_INVALID, NONE, .a = 1, .b = 1, .c = -0.0),
    C(lpi_rigid_body_create, "I3 denormal (1/I overflows)", LPI_ERR_INVALID, NONE, .a = 1, .b = 1, .c = 1e-320),
    C(lpi_pendulum_create, "NULL out", LPI_ERR_NULL, NONE, .nul = P1),
    C(lpi_moments_create, "NULL out", LPI_ERR_NULL, NONE, .nul = P1),
    C(lpi_generic_create, "NULL out", LPI_ERR_NULL, NONE, .nul = P1, .n = 3, .m = 3, .i = kI, .j = kJ, .kk = kK, .x = kC),
    C(lpi_generic_create, "dim = 0", LPI_ERR_INVALID, NONE, .n = 0),
    C(lpi_generic_create, "dim = 2^31 + 1", LPI_ERR_INVALID, NONE, .n = 2147483649u),
    C(lpi_generic_create, "NULL i with nnz > 0", LPI_ERR_NULL, NONE, .n = 3, .m = 3, .j = kJ, .kk = kK, .x = kC),
    C(lpi_generic_create, "NULL j with nnz > 0", LPI_ERR_NULL, NONE, .n = 3, .m = 3, .i = kI, .kk = kK, .x = kC),
    C(lpi_generic_create, "NULL k with nnz > 0", LPI_ERR_NULL, NONE, .n = 3, .m = 3, .i = kI, .j = kJ, .x = kC),
    C(lpi_generic_create, "NULL c with nnz > 0", LPI_ERR_NULL, NONE, .n = 3, .m = 3, .i = kI, .j = kJ, .kk = kK),
    C(lpi_generic_create, "index = dim", LPI_ERR_INVALID, NONE, .n = 3, .m = 3, .i = kI, .j = kJ, .kk = kOutOfRange, .x = kC),
    C(lpi_generic_create, "negative index", LPI_ERR_INVALID, NONE, .n = 3, .m = 3, .i = kNegative, .j = kJ, .kk = kK, .x = kC),
    C(lpi_generic_create, "NaN coefficient", LPI_ERR_NONFINITE, NONE, .n = 3, .m = 1, .i = kI, .j = kJ, .kk = kK, .x = kNaN1),
    C(lpi_generic_create, "{x0, x0} != 0", LPI_ERR_INVALID, NONE, .n = 3, .m = 1, .i = kSame, .j = kSame, .kk = kOne, .x = kOne1),
    C(lpi_generic_create, "contradicting entries", LPI_ERR_INVALID, NONE, .n = 3, .m = 2, .i = kContraI, .j = kContraJ, .kk = kContraK, .x = kOnes2),
    C(lpi_generic_create, "Jacobi identity violated", LPI_ERR_INVALID, NONE, .n = 3, .m = 2, .i = kJacI, .j = kJacJ, .kk = kJacK, .x = kOnes2),
    C(lpi_sine_euler_create, "NULL out", LPI_ERR_NULL, NONE, .nul = P1, .k = 7),
    C(lpi_sine_euler_create, "N even", LPI_ERR_INVALID, NONE, .k = 8),
    C(lpi_sine_euler_create, "N = 1", LPI_ERR_INVALID, NONE, .k = 1),
    C(lpi_sine_euler_create, "N < 0", LPI_ERR_INVALID, NONE, .k = -3),
    C(lpi_sine_euler_create, "N = INT32_MAX", LPI_ERR_NO_MEMORY, NONE, .k = INT32_MAX),

    /* the handle itself */
    C(lpi_set_method, "NULL handle", LPI_ERR_NULL, NONE, .s = "leapfrog"),
    C(lpi_set_method, "NULL name", LPI_ERR_NULL, RB),
    C(lpi_set_method, "empty name", LPI_ERR_INVALID, RB, .s = ""),
    C(lpi_set_method, "unknown name", LPI_ERR_INVALID, PEND, .s = "no-such-method"),
    C(lpi_set_method, "odd recursive order", LPI_ERR_INVALID, RB, .s = "triple-jump-5"),
    C(lpi_set_method, "recursive order too high", LPI_ERR_INVALID, RB, .s = "suzuki-18"),
    C(lpi_set_method, "recursive order 0", LPI_ERR_INVALID, RB, .s = "triple-jump-0"),
    C(lpi_set_method, "unknown name (generic)", LPI_ERR_INVALID, GEN, .s = "LEAPFROG"),
    C(lpi_set_method, "unknown name (sine-Euler)", LPI_ERR_INVALID, SE, .s = "leapfrog "),
    C(lpi_set_split, "NULL handle", LPI_ERR_NULL, NONE, .s = "axes"),
    C(lpi_set_split, "NULL name", LPI_ERR_NULL, RB),
    C(lpi_set_split, "unknown split", LPI_ERR_INVALID, RB, .s = "diagonal"),
    C(lpi_set_split, "rigid-body split on a pendulum", LPI_ERR_INVALID, PEND, .s = "axes"),
    C(lpi_set_split, "unknown split (generic)", LPI_ERR_INVALID, GEN, .s = "axes"),
    C(lpi_set_split, "unknown split (sine-Euler)", LPI_ERR_INVALID, SE, .s = "axes"),
    C(lpi_set_state, "NULL handle", LPI_ERR_NULL, NONE, .x = kState3, .n = 3),
    C(lpi_set_state, "NULL state", LPI_ERR_NULL, RB, .n = 3),
    C(lpi_set_state, "n = 2", LPI_ERR_SIZE, RB, .x = kState3, .n = 2),
    C(lpi_set_state, "n = 0", LPI_ERR_SIZE, PEND, .x = kState3, .n = 0),
    C(lpi_set_state, "n = SIZE_MAX", LPI_ERR_SIZE, RB, .x = kState3, .n = SIZE_MAX),
    C(lpi_set_state, "NaN entry", LPI_ERR_NONFINITE, RB, .x = kNaN3, .n = 3),
    C(lpi_set_state, "Inf entry", LPI_ERR_NONFINITE, PEND, .x = kInf3, .n = 3),
    C(lpi_set_state, "NaN entry (generic)", LPI_ERR_NONFINITE, GEN, .x = kNaN3, .n = 3),
    C(lpi_set_state, "wrong n (sine-Euler)", LPI_ERR_SIZE, SE, .x = kGrid, .n = 80),
    C(lpi_set_state, "NaN entry (sine-Euler)", LPI_ERR_NONFINITE, SE, .x = kGridNaN, .n = 81),
    C(lpi_get_state, "NULL handle", LPI_ERR_NULL, NONE, .n = 3),
    C(lpi_get_state, "NULL buffer", LPI_ERR_NULL, RB, .nul = P1, .n = 3),
    C(lpi_get_state, "n = 4", LPI_ERR_SIZE, RB, .n = 4),
    C(lpi_get_state, "n = 2 (generic)", LPI_ERR_SIZE, GEN, .n = 2),
    C(lpi_get_state, "wrong n (sine-Euler)", LPI_ERR_SIZE, SE, .n = 162),
    C(lpi_step, "NULL handle", LPI_ERR_NULL, NONE, .a = 0.1, .k = 1),
    C(lpi_step, "NaN dt", LPI_ERR_NONFINITE, RB, .a = NAN, .k = 1),
    C(lpi_step, "Inf dt", LPI_ERR_NONFINITE, PEND, .a = INFINITY, .k = 1),
    C(lpi_step, "dt = 0", LPI_ERR_INVALID, RB, .a = 0.0, .k = 1),
    C(lpi_step, "nsteps < 0", LPI_ERR_INVALID, RB, .a = 0.1, .k = -1),
    C(lpi_step, "nsteps = INT64_MIN", LPI_ERR_INVALID, SE, .a = 0.1, .k = INT64_MIN),
    C(lpi_step, "dt * nsteps overflows the time", LPI_ERR_OVERFLOW, RB, .a = 1e300, .k = INT64_MAX),
    C(lpi_step, "rk4 beyond its stability limit: rolled back", LPI_ERR_NONFINITE, RB_RK4, .a = 1e3, .k = 1000),
    C(lpi_step, "implicit iteration not converging: rolled back", LPI_ERR_NO_CONVERGENCE, RB_IMP, .a = 0.5, .k = 3),
    C(lpi_step, "generic system with no pieces (call order)", LPI_ERR_INVALID, GEN_EMPTY, .a = 0.1, .k = 1),
    C(lpi_step, "moments with no pieces (call order)", LPI_ERR_INVALID, MOM, .a = 0.1, .k = 1),
    C(lpi_step, "failing gradient callback: rolled back", LPI_ERR_CALLBACK, GEN_FAIL, .a = 0.1, .k = 2),
    C(lpi_energy, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_energy, "NULL out", LPI_ERR_NULL, RB, .nul = P1),
    C(lpi_energy, "NULL out (sine-Euler)", LPI_ERR_NULL, SE, .nul = P1),
    C(lpi_energy, "failing energy callback", LPI_ERR_CALLBACK, GEN_FAIL),
    C(lpi_energy, "energy of |m| ~ 1e200 overflows", LPI_ERR_OVERFLOW, RB_HUGE),
    C(lpi_energy, "energy of modes ~ 1e308 overflows (sine-Euler)", LPI_ERR_OVERFLOW, SE_HUGE),
    C(lpi_set_observer, "NULL handle", LPI_ERR_NULL, NONE, .k = 1),
    C(lpi_set_observer, "every = 0", LPI_ERR_INVALID, RB, .k = 0),
    C(lpi_set_observer, "every < 0", LPI_ERR_INVALID, SE, .k = -3),
    C(lpi_set_observer, "every = INT64_MIN (generic)", LPI_ERR_INVALID, GEN, .k = INT64_MIN),
    C(lpi_casimirs, "NULL handle", LPI_ERR_NULL, NONE, .n = 1),
    C(lpi_casimirs, "NULL out", LPI_ERR_NULL, RB, .nul = P1, .n = 1),
    C(lpi_casimirs, "n = 2", LPI_ERR_SIZE, PEND, .n = 2),
    C(lpi_casimirs, "n = 0 (moments have 2)", LPI_ERR_SIZE, MOM, .n = 0),
    C(lpi_casimirs, "n = 1 (sine-Euler has 9)", LPI_ERR_SIZE, SE, .n = 1),
    C(lpi_casimirs, "failing Casimir callback", LPI_ERR_CALLBACK, GEN_FAIL, .n = 1),
    C(lpi_casimirs, "|m|^2 ~ 3e400 overflows", LPI_ERR_OVERFLOW, RB_HUGE, .n = 1),
    C(lpi_casimirs, "spectrum of modes ~ 1e308 overflows (sine-Euler)", LPI_ERR_OVERFLOW, SE_HUGE, .n = 5),
    C(lpi_rigid_body_exact, "NULL handle", LPI_ERR_NULL, NONE, .a = 1),
    C(lpi_rigid_body_exact, "NULL out", LPI_ERR_NULL, RB, .nul = P1, .a = 1),
    C(lpi_rigid_body_exact, "NaN t", LPI_ERR_NONFINITE, RB, .a = NAN),
    C(lpi_rigid_body_exact, "-Inf t", LPI_ERR_NONFINITE, RB, .a = -INFINITY),
    C(lpi_rigid_body_exact, "a pendulum (wrong kind)", LPI_ERR_UNSUPPORTED, PEND, .a = 1),
    C(lpi_rigid_body_exact, "a generic system (wrong kind)", LPI_ERR_UNSUPPORTED, GEN, .a = 1),
    C(lpi_rigid_body_exact, "sine-Euler (wrong kind)", LPI_ERR_UNSUPPORTED, SE, .a = 1),

    /* compositions and implicit settings */
    C(lpi_set_composition, "NULL handle", LPI_ERR_NULL, NONE, .n = 1, .x = kOne1),
    C(lpi_set_composition, "NULL gammas", LPI_ERR_NULL, RB, .n = 3),
    C(lpi_set_composition, "n = 0", LPI_ERR_INVALID, RB, .n = 0, .x = kOne1),
    C(lpi_set_composition, "NaN weight", LPI_ERR_NONFINITE, RB, .n = 3, .x = kGammasNaN),
    C(lpi_set_composition, "Inf weight", LPI_ERR_NONFINITE, PEND, .n = 1, .x = kGammasInf),
    C(lpi_set_composition, "not symmetric", LPI_ERR_INVALID, RB, .n = 3, .x = kGammasAsym),
    C(lpi_set_composition, "weights sum to 1.5", LPI_ERR_INVALID, SE, .n = 3, .x = kGammasSum),
    C(lpi_set_composition, "finite weights whose sum test overflows", LPI_ERR_OVERFLOW, RB, .n = 3, .x = kGammasOverflow),
    C(lpi_flows_per_step, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_flows_per_step, "NULL out", LPI_ERR_NULL, RB, .nul = P1),
    C(lpi_set_implicit_options, "NULL handle", LPI_ERR_NULL, NONE, .a = 1e-12, .k = 10),
    C(lpi_set_implicit_options, "NaN tolerance", LPI_ERR_NONFINITE, RB, .a = NAN, .k = 10),
    C(lpi_set_implicit_options, "Inf tolerance", LPI_ERR_INVALID, RB_IMP, .a = INFINITY, .k = 10),
    C(lpi_set_implicit_options, "tolerance = 0", LPI_ERR_INVALID, RB, .a = 0.0, .k = 10),
    C(lpi_set_implicit_options, "tolerance < 0", LPI_ERR_INVALID, SE, .a = -1e-12, .k = 10),
    C(lpi_set_implicit_options, "max_iterations = 0", LPI_ERR_INVALID, RB_IMP, .a = 1e-12, .k = 0),
    C(lpi_set_implicit_options, "max_iterations < 0", LPI_ERR_INVALID, GEN, .a = 1e-12, .k = -5),

    /* generic systems and moments */
    C(lpi_add_piece, "NULL handle", LPI_ERR_NULL, NONE, .n = 1, .i = kSet0),
    C(lpi_add_piece, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .n = 1, .i = kSet0),
    C(lpi_add_piece, "sine-Euler (wrong kind)", LPI_ERR_UNSUPPORTED, SE, .n = 1, .i = kSet0),
    C(lpi_add_piece, "NULL indices", LPI_ERR_NULL, GEN_EMPTY, .n = 1),
    C(lpi_add_piece, "NULL gradient", LPI_ERR_NULL, GEN_EMPTY, .nul = P2, .n = 1, .i = kSet0),
    C(lpi_add_piece, "NULL energy", LPI_ERR_NULL, GEN, .nul = P3, .n = 1, .i = kSet0),
    C(lpi_add_piece, "n = 0", LPI_ERR_INVALID, GEN_EMPTY, .n = 0, .i = kSet0),
    C(lpi_add_piece, "n > dim", LPI_ERR_INVALID, GEN, .n = 4, .i = kOutOfRange),
    C(lpi_add_piece, "index = dim", LPI_ERR_INVALID, GEN, .n = 1, .i = kSet3),
    C(lpi_add_piece, "negative index", LPI_ERR_INVALID, GEN_EMPTY, .n = 2, .i = kNegative),
    C(lpi_add_piece, "duplicate index", LPI_ERR_INVALID, GEN, .n = 2, .i = kDup),
    C(lpi_add_piece, "not abelian", LPI_ERR_NOT_ABELIAN, GEN_EMPTY, .n = 2, .i = kPair01),
    C(lpi_add_piece, "not abelian (moments {0, 1})", LPI_ERR_NOT_ABELIAN, MOM, .n = 2, .i = kPair01),
    C(lpi_add_casimir, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_add_casimir, "a pendulum (wrong kind)", LPI_ERR_UNSUPPORTED, PEND),
    C(lpi_add_casimir, "NULL callback", LPI_ERR_NULL, GEN, .nul = P1),
    C(lpi_poisson_rank, "NULL handle", LPI_ERR_NULL, NONE, .x = kState3, .n = 3),
    C(lpi_poisson_rank, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .x = kState3, .n = 3),
    C(lpi_poisson_rank, "NULL x", LPI_ERR_NULL, GEN, .n = 3),
    C(lpi_poisson_rank, "NULL rank", LPI_ERR_NULL, GEN, .nul = P2, .x = kState3, .n = 3),
    C(lpi_poisson_rank, "n = 2", LPI_ERR_SIZE, GEN, .x = kState3, .n = 2),
    C(lpi_poisson_rank, "NaN x", LPI_ERR_NONFINITE, GEN_EMPTY, .x = kNaN3, .n = 3),
    C(lpi_poisson_rank, "n = 3 on moments (dim 8)", LPI_ERR_SIZE, MOM, .x = kState3, .n = 3),
    C(lpi_moments_add_product_piece, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_moments_add_product_piece, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB),
    C(lpi_moments_add_product_piece, "a generic system (not moments)", LPI_ERR_UNSUPPORTED, GEN),
    C(lpi_moments_add_product_piece, "NULL H", LPI_ERR_NULL, MOM, .nul = P1),
    C(lpi_moments_add_product_piece, "NULL H'", LPI_ERR_NULL, MOM, .nul = P2),

    /* sine-Euler */
    C(lpi_sine_euler_size, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_sine_euler_size, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB),
    C(lpi_sine_euler_size, "NULL N", LPI_ERR_NULL, SE, .nul = P1),
    C(lpi_sine_euler_set_modes, "NULL handle", LPI_ERR_NULL, NONE, .x = kModesNaN, .n = 162),
    C(lpi_sine_euler_set_modes, "a pendulum (wrong kind)", LPI_ERR_UNSUPPORTED, PEND, .x = kModesNaN, .n = 162),
    C(lpi_sine_euler_set_modes, "NULL modes", LPI_ERR_NULL, SE, .n = 162),
    C(lpi_sine_euler_set_modes, "n = 81", LPI_ERR_SIZE, SE, .x = kModesNaN, .n = 81),
    C(lpi_sine_euler_set_modes, "NaN mode", LPI_ERR_NONFINITE, SE, .x = kModesNaN, .n = 162),
    C(lpi_sine_euler_set_modes, "not Hermitian", LPI_ERR_INVALID, SE, .x = kModesNotHermitian, .n = 162),
    C(lpi_sine_euler_set_modes, "imaginary w_0", LPI_ERR_INVALID, SE, .x = kModesImaginaryW0, .n = 162),
    C(lpi_sine_euler_get_modes, "NULL handle", LPI_ERR_NULL, NONE, .n = 162),
    C(lpi_sine_euler_get_modes, "a generic system (wrong kind)", LPI_ERR_UNSUPPORTED, GEN, .n = 162),
    C(lpi_sine_euler_get_modes, "NULL buffer", LPI_ERR_NULL, SE, .nul = P1, .n = 162),
    C(lpi_sine_euler_get_modes, "n = 161", LPI_ERR_SIZE, SE, .n = 161),
    C(lpi_sine_euler_set_grid, "NULL handle", LPI_ERR_NULL, NONE, .x = kGrid, .n = 81),
    C(lpi_sine_euler_set_grid, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .x = kGrid, .n = 81),
    C(lpi_sine_euler_set_grid, "NULL grid", LPI_ERR_NULL, SE, .n = 81),
    C(lpi_sine_euler_set_grid, "n = 162", LPI_ERR_SIZE, SE, .x = kGrid, .n = 162),
    C(lpi_sine_euler_set_grid, "NaN value", LPI_ERR_NONFINITE, SE, .x = kGridNaN, .n = 81),
    C(lpi_sine_euler_set_grid, "-Inf value", LPI_ERR_NONFINITE, SE, .x = kGridInf, .n = 81),
    C(lpi_sine_euler_get_grid, "NULL handle", LPI_ERR_NULL, NONE, .n = 81),
    C(lpi_sine_euler_get_grid, "moments (wrong kind)", LPI_ERR_UNSUPPORTED, MOM, .n = 81),
    C(lpi_sine_euler_get_grid, "NULL buffer", LPI_ERR_NULL, SE, .nul = P1, .n = 81),
    C(lpi_sine_euler_get_grid, "n = 0", LPI_ERR_SIZE, SE, .n = 0),
    C(lpi_sine_euler_get_grid, "grid of modes ~ 1e308 overflows", LPI_ERR_OVERFLOW, SE_HUGE, .n = 25),
    C(lpi_sine_euler_enstrophy, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_sine_euler_enstrophy, "a pendulum (wrong kind)", LPI_ERR_UNSUPPORTED, PEND),
    C(lpi_sine_euler_enstrophy, "NULL out", LPI_ERR_NULL, SE, .nul = P1),
    C(lpi_sine_euler_enstrophy, "enstrophy of modes ~ 1e308 overflows", LPI_ERR_OVERFLOW, SE_HUGE),
    C(lpi_sine_euler_casimir_traces, "NULL handle", LPI_ERR_NULL, NONE, .k = 3),
    C(lpi_sine_euler_casimir_traces, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .k = 3),
    C(lpi_sine_euler_casimir_traces, "NULL out", LPI_ERR_NULL, SE, .nul = P1, .k = 3),
    C(lpi_sine_euler_casimir_traces, "kmax = 0", LPI_ERR_INVALID, SE, .k = 0),
    C(lpi_sine_euler_casimir_traces, "kmax < 0", LPI_ERR_INVALID, SE, .k = -4),
    C(lpi_sine_euler_casimir_traces, "tr W^2 of modes ~ 1e308 overflows", LPI_ERR_OVERFLOW, SE_HUGE, .k = 3),
    C(lpi_sine_euler_fft_floor, "NULL handle", LPI_ERR_NULL, NONE, .k = 1),
    C(lpi_sine_euler_fft_floor, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .k = 1),
    C(lpi_sine_euler_fft_floor, "NULL seconds", LPI_ERR_NULL, SE, .nul = P1, .k = 1),
    C(lpi_sine_euler_fft_floor, "NULL transforms", LPI_ERR_NULL, SE, .nul = P2, .k = 1),
    C(lpi_sine_euler_fft_floor, "nsteps = 0", LPI_ERR_INVALID, SE, .k = 0),
    C(lpi_sine_euler_fft_floor, "nsteps < 0", LPI_ERR_INVALID, SE, .k = -1),
    C(lpi_sine_euler_fft_floor, "rk4 (not a splitting)", LPI_ERR_INVALID, SE_RK4, .k = 1),
    C(lpi_sine_euler_fft_floor, "implicit-midpoint (not a splitting)", LPI_ERR_INVALID, SE_IMP, .k = 1),
    C(lpi_sine_euler_fft_floor, "nsteps x flows per step overflows", LPI_ERR_OVERFLOW, SE, .k = INT64_MAX),
    C(lpi_sine_euler_set_planning, "NULL handle", LPI_ERR_NULL, NONE, .s = "measure"),
    C(lpi_sine_euler_set_planning, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .s = "measure"),
    C(lpi_sine_euler_set_planning, "NULL rigor", LPI_ERR_NULL, SE),
    C(lpi_sine_euler_set_planning, "unknown rigor", LPI_ERR_INVALID, SE, .s = "exhaustive"),
    C(lpi_sine_euler_set_planning, "empty rigor", LPI_ERR_INVALID, SE, .s = ""),
    C(lpi_sine_euler_get_planning, "NULL handle", LPI_ERR_NULL, NONE),
    C(lpi_sine_euler_get_planning, "a generic system (wrong kind)", LPI_ERR_UNSUPPORTED, GEN),
    C(lpi_sine_euler_get_planning, "NULL rigor", LPI_ERR_NULL, SE, .nul = P1),
    C(lpi_sine_euler_set_hamiltonian, "NULL handle", LPI_ERR_NULL, NONE, .x = kLambda, .n = 81, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .x = kLambda, .n = 81, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "NULL lambda", LPI_ERR_NULL, SE, .nul = P1, .n = 81, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "NULL f with n_f = 162", LPI_ERR_NULL, SE, .nul = P2, .x = kLambda, .n = 81, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "n_lambda = 80", LPI_ERR_SIZE, SE, .x = kLambda, .n = 80, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "n_lambda = SIZE_MAX", LPI_ERR_SIZE, SE, .x = kLambda, .n = SIZE_MAX, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "n_f = 81", LPI_ERR_SIZE, SE, .x = kLambda, .n = 81, .bytes = kForce, .m = 81),
    C(lpi_sine_euler_set_hamiltonian, "NaN lambda", LPI_ERR_NONFINITE, SE, .x = kLambdaNaN, .n = 81, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "infinite f", LPI_ERR_NONFINITE, SE, .x = kLambda, .n = 81, .bytes = kForceInf, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "lambda not symmetric", LPI_ERR_INVALID, SE, .x = kLambdaAsymmetric, .n = 81, .bytes = kForce, .m = 162),
    C(lpi_sine_euler_set_hamiltonian, "f not Hermitian", LPI_ERR_INVALID, SE, .x = kLambda, .n = 81, .bytes = kForceNotHermitian, .m = 162),
    C(lpi_sine_euler_get_stream, "NULL handle", LPI_ERR_NULL, NONE, .n = 81),
    C(lpi_sine_euler_get_stream, "a pendulum (wrong kind)", LPI_ERR_UNSUPPORTED, PEND, .n = 81),
    C(lpi_sine_euler_get_stream, "NULL buffer", LPI_ERR_NULL, SE, .nul = P1, .n = 81),
    C(lpi_sine_euler_get_stream, "n = 162", LPI_ERR_SIZE, SE, .n = 162),
    C(lpi_sine_euler_get_stream, "stream function of modes ~ 1e308 overflows", LPI_ERR_OVERFLOW, SE_HUGE, .n = 25),
    C(lpi_sine_euler_spectrum, "NULL handle", LPI_ERR_NULL, NONE, .n = 6),
    C(lpi_sine_euler_spectrum, "a rigid body (wrong kind)", LPI_ERR_UNSUPPORTED, RB, .n = 6),
    C(lpi_sine_euler_spectrum, "NULL energy", LPI_ERR_NULL, SE, .nul = P1, .n = 6),
    C(lpi_sine_euler_spectrum, "NULL enstrophy", LPI_ERR_NULL, SE, .nul = P2, .n = 6),
    C(lpi_sine_euler_spectrum, "NULL shells", LPI_ERR_NULL, SE, .nul = P3, .n = 6),
    C(lpi_sine_euler_spectrum, "n = 5 < 6 shells", LPI_ERR_SIZE, SE, .n = 5),
    C(lpi_sine_euler_spectrum, "spectrum of modes ~ 1e308 overflows", LPI_ERR_OVERFLOW, SE_HUGE, .n = 3),
    C(lpi_set_threads, "NULL handle", LPI_ERR_NULL, NONE, .k = 2),
    C(lpi_set_threads, "n = 0", LPI_ERR_INVALID, SE, .k = 0),
    C(lpi_set_threads, "n < 0", LPI_ERR_INVALID, SE, .k = -2),
    C(lpi_set_threads, "n = 0 (rigid body)", LPI_ERR_INVALID, RB, .k = 0),
    C(lpi_set_threads, "n = 2 on a one-thread model", LPI_ERR_UNSUPPORTED, RB, .k = 2),
    C(lpi_set_threads, "n = 2 on a generic system", LPI_ERR_UNSUPPORTED, GEN, .k = 2),
    C(lpi_set_threads, "n = INT32_MAX (above 4 x processors)", LPI_ERR_INVALID, SE, .k = INT32_MAX),
    C(lpi_set_threads, "n = 100000 (above 4 x processors)", LPI_ERR_INVALID, SE, .k = 100000),
    C(lpi_set_threads, "n = INT32_MAX on a one-thread model: bounded first", LPI_ERR_INVALID, RB, .k = INT32_MAX),
    C(lpi_fftw_wisdom_import_file, "NULL path", LPI_ERR_NULL, NONE),
    C(lpi_fftw_wisdom_import_file, "empty path", LPI_ERR_INVALID, NONE, .s = ""),
    C(lpi_fftw_wisdom_import_file, "missing file", LPI_ERR_IO, NONE, .s = "no-such-dir/wisdom"),
    C(lpi_fftw_wisdom_export_file, "NULL path", LPI_ERR_NULL, NONE),
    C(lpi_fftw_wisdom_export_file, "empty path", LPI_ERR_INVALID, NONE, .s = ""),
    C(lpi_fftw_wisdom_export_file, "unwritable path", LPI_ERR_IO, NONE, .s = "no-such-dir/wisdom"),
    C(lpi_fftw_wisdom_import_string, "NULL string", LPI_ERR_NULL, NONE),
    C(lpi_fftw_wisdom_import_string, "not wisdom", LPI_ERR_INVALID, NONE, .s = "(not wisdom"),
    C(lpi_fftw_wisdom_export_string, "NULL length", LPI_ERR_NULL, NONE, .nul = P2, .n = 16),
    C(lpi_fftw_wisdom_export_string, "NULL buffer with size > 0", LPI_ERR_NULL, NONE, .nul = P1, .n = 16),
    C(lpi_fftw_wisdom_export_string, "buffer too small", LPI_ERR_SIZE, NONE, .n = 2),

    /* checkpoints */
    C(lpi_save, "NULL handle", LPI_ERR_NULL, NONE, .s = "never.lpi"),
    C(lpi_save, "NULL path", LPI_ERR_NULL, RB),
    C(lpi_save, "empty path", LPI_ERR_INVALID, PEND, .s = ""),
    C(lpi_save, "directory does not exist", LPI_ERR_IO, SE, .s = "no-such-dir/run.lpi"),
    C(lpi_save, "path is a directory", LPI_ERR_IO, RB, .s = "."),
    C(lpi_save, "generic system (user callbacks)", LPI_ERR_UNSUPPORTED, GEN, .s = "never.lpi"),
    C(lpi_save, "moments (user callbacks)", LPI_ERR_UNSUPPORTED, MOM, .s = "never.lpi"),
    C(lpi_load, "NULL out", LPI_ERR_NULL, NONE, .nul = P1, .s = "never.lpi"),
    C(lpi_load, "NULL path", LPI_ERR_NULL, NONE),
    C(lpi_load, "empty path", LPI_ERR_INVALID, NONE, .s = ""),
    C(lpi_load, "missing file", LPI_ERR_IO, NONE, .s = "no-such-dir/run.lpi"),
    C(lpi_load, "a directory", LPI_ERR_IO, NONE, .s = "."),
    C(lpi_save_buffer, "NULL handle", LPI_ERR_NULL, NONE, .n = 8192),
    C(lpi_save_buffer, "NULL size", LPI_ERR_NULL, RB, .nul = P2, .n = 8192),
    C(lpi_save_buffer, "NULL buffer with capacity > 0", LPI_ERR_NULL, PEND, .nul = P1, .n = 64),
    C(lpi_save_buffer, "capacity too small", LPI_ERR_SIZE, RB, .n = 16),
    C(lpi_save_buffer, "capacity too small (sine-Euler)", LPI_ERR_SIZE, SE, .n = 1000),
    C(lpi_save_buffer, "generic system (user callbacks)", LPI_ERR_UNSUPPORTED, GEN_EMPTY, .n = 8192),
    C(lpi_load_buffer, "NULL out", LPI_ERR_NULL, NONE, .nul = P1, .bytes = kNotCheckpoint, .n = 40),
    C(lpi_load_buffer, "NULL buffer", LPI_ERR_NULL, NONE, .nul = P2, .n = 40),
    C(lpi_load_buffer, "size 0", LPI_ERR_FORMAT, NONE, .bytes = kNotCheckpoint, .n = 0),
    C(lpi_load_buffer, "not a checkpoint", LPI_ERR_FORMAT, NONE, .bytes = kNotCheckpoint, .n = 40),
};

/* Cases that need FFTW: a sine-Euler handle or the wisdom functions. */
static int needs_fftw(const bad_case *c) {
    const int sine_euler = (c->a.target >= SE && c->a.target <= SE_IMP) || c->a.target == SE_HUGE;
    return sine_euler || strstr(c->function, "wisdom") ||
           (strcmp(c->function, "lpi_sine_euler_create") == 0 && c->a.nul == 0);
}

/* A checkpoint of the handle (or its public state where it has none). */
static unsigned char *fingerprint(const lpi_system *sys, size_t *size) {
    if (lpi_save_buffer(sys, NULL, 0, size) != LPI_OK) {
        *size = 0;
        return NULL;
    }
    unsigned char *buf = malloc(*size);
    assert_non_null(buf);
    assert_int_equal(lpi_save_buffer(sys, buf, *size, size), LPI_OK);
    return buf;
}

static int run_case(const bad_case *c) {
    lpi_system *sys = handles[c->a.target];
    lpi_system *out = (lpi_system *)0x1; /* creators must reset it to NULL */
    if (c->expected == SENTINEL) {
        if (c->call(sys, &c->a, &out) != 1)
            fail_msg("%s (%s): documented sentinel not returned", c->function, c->input);
        return 1;
    }
    /* A stale message from another function must not satisfy the check. */
    if (strcmp(c->function, "lpi_energy") != 0)
        (void)lpi_energy(sys, NULL);
    else
        (void)lpi_flows_per_step(sys, NULL);
    size_t before_size = 0, after_size = 0, flows_before = 0, flows_after = 0;
    unsigned char *before = sys ? fingerprint(sys, &before_size) : NULL;
    const size_t casimirs_before = lpi_casimir_count(sys);
    if (sys) assert_int_equal(lpi_flows_per_step(sys, &flows_before), LPI_OK);

    /* A failed call leaves its outputs untouched, but for the size it
     * reports with LPI_ERR_SIZE (a buffer too small says what it needs). */
    memset(out_buf, 0xA5, sizeof out_buf);
    memset(&out_size, 0xA5, sizeof out_size);
    size_t untouched_size;
    memset(&untouched_size, 0xA5, sizeof untouched_size);

    LPI_ASSERT_FAILS(sys, c->call(sys, &c->a, &out), c->expected, c->function);

    for (size_t i = 0; i < sizeof out_buf; ++i)
        if (((const unsigned char *)out_buf)[i] != 0xA5)
            fail_msg("%s (%s): the output buffer was written (byte %zu) by a failed call", c->function,
                     c->input, i);
    if (c->expected != LPI_ERR_SIZE && out_size != untouched_size)
        fail_msg("%s (%s): the output size was written by a failed call", c->function, c->input);

    const char *message = lpi_last_error(sys);
    if (strlen(message) < strlen(c->function) + 8)
        fail_msg("%s (%s): message '%s' is not specific", c->function, c->input, message);
    if (out != (lpi_system *)0x1 && out != NULL)
        fail_msg("%s (%s): *out not NULL after failure", c->function, c->input);
    if (sys) {
        unsigned char *after = fingerprint(sys, &after_size);
        assert_int_equal(after_size, before_size);
        if (before_size && memcmp(before, after, before_size) != 0)
            fail_msg("%s (%s) on %s: the checkpoint changed", c->function, c->input,
                     kTargetName[c->a.target]);
        assert_int_equal(lpi_flows_per_step(sys, &flows_after), LPI_OK);
        assert_int_equal(flows_after, flows_before);
        assert_int_equal(lpi_casimir_count(sys), casimirs_before);
        free(after);
    }
    free(before);
    return 1;
}

/* ---- coverage of the header ---------------------------------------------- */

static const char *header_path;

static void test_every_function_in_table(void **state) {
    (void)state;
    FILE *f = fopen(header_path, "r");
    if (!f) fail_msg("cannot open the header '%s'", header_path ? header_path : "(none)");
    char line[1024];
    int declared = 0, missing = 0;
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "LPI_API ", 8) != 0) continue;
        char *paren = strchr(line, '(');
        if (!paren) continue;
        char *end = paren, *begin = paren;
        while (begin > line && (isalnum((unsigned char)begin[-1]) || begin[-1] == '_')) --begin;
        *end = '\0';
        ++declared;
        int found = 0;
        for (size_t i = 0; i < sizeof kCases / sizeof kCases[0]; ++i)
            if (strcmp(kCases[i].function, begin) == 0) found = 1;
        if (!found) {
            printf("no bad-input case for %s\n", begin);
            ++missing;
        }
    }
    fclose(f);
    assert_true(declared >= 50);
    assert_int_equal(missing, 0);
    printf("header: %d functions declared, every one in the table\n", declared);
}

static void test_bad_input_table(void **state) {
    (void)state;
    make_handles();
    int run = 0, skipped = 0, sentinels = 0;
    const size_t count = sizeof kCases / sizeof kCases[0];
    for (size_t i = 0; i < count; ++i) {
        const bad_case *c = &kCases[i];
        if (!have_fftw && needs_fftw(c)) {
            ++skipped;
            continue;
        }
        run += run_case(c);
        sentinels += c->expected == SENTINEL;
    }
    /* Still usable after all of it. */
    assert_int_equal(lpi_step(handles[RB], 0.01, 10), LPI_OK);
    assert_int_equal(lpi_step(handles[GEN], 0.01, 10), LPI_OK);
    remove("never.lpi");
    for (int t = 0; t < TARGETS; ++t) lpi_destroy(handles[t]);
    printf("bad input: %d cases run (%d status cases, %d sentinel cases), %d skipped "
           "(they need FFTW)\n", run, run - sentinels, sentinels, skipped);
}

int main(int argc, char **argv) {
    header_path = argc > 1 ? argv[1] : NULL;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_function_in_table),
        cmocka_unit_test(test_bad_input_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
