/* The exact free rigid body against references computed here by other means,
 * over 12 000 random cases in the families where an elliptic-function
 * solution is delicate: symmetric and nearly symmetric bodies, steady
 * rotations, on and beside the separatrix, at and near each axis, every
 * ordering of the inertias, t of either sign, long times. Each family prints
 * its worst error. The references:
 *  - a Taylor-series integrator in long double (the equation is quadratic, so
 *    the series coefficients are Cauchy products), for moderate t;
 *  - the closed form of the symmetric top in long double, for long times;
 *  - the input itself, bit for bit, for steady rotations.
 * Valgrind runs long double arithmetic in 64 bits; there the references are
 * too coarse, and only the properties that need none (t = 0, steady states)
 * are checked. */
#include <float.h>

#include "lpi_test.h"

typedef long double real;

/* ---- references ------------------------------------------------------------ */

/* max |1/I_i - 1/I_j|: |m| times it bounds every rate of the motion. */
static double inertia_spread(const double I[3]) {
    double spread = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) spread = fmax(spread, fabs(1 / I[i] - 1 / I[j]));
    return spread;
}

/* dm/dt = m x (m / I) by Taylor series in long double. With rate = |m| max|w_i
 * - w_j|, the Jacobi functions of the solution have their nearest poles
 * K' >= pi/2 over the rate (at most) from the real t axis, so steps of 0.2 /
 * rate shrink the terms like 0.13^n: 24 terms reach long double round-off. */
enum { kTaylorTerms = 24 };
static void taylor_reference(const double I[3], const double m0[3], double t, real out[3]) {
    const real w[3] = {1.0L / I[0], 1.0L / I[1], 1.0L / I[2]};
    real m[3] = {m0[0], m0[1], m0[2]};
    const real rate = sqrtl(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) * inertia_spread(I);
    const long steps = (long)ceill(fabsl(t) * rate / 0.2L);
    for (long s = 0; s < steps; ++s) {
        const real h = (real)t / steps;
        real c[kTaylorTerms + 1][3], wc[kTaylorTerms + 1][3]; /* h^k m^(k) / k!, w times it */
        for (int i = 0; i < 3; ++i) c[0][i] = m[i], wc[0][i] = w[i] * m[i];
        for (int k = 0; k < kTaylorTerms; ++k) {
            real sum[3] = {0, 0, 0};
            for (int j = 0; j <= k; ++j) {
                const real *x = c[j], *y = wc[k - j];
                sum[0] += x[1] * y[2] - x[2] * y[1];
                sum[1] += x[2] * y[0] - x[0] * y[2];
                sum[2] += x[0] * y[1] - x[1] * y[0];
            }
            for (int i = 0; i < 3; ++i) c[k + 1][i] = sum[i] * h / (k + 1), wc[k + 1][i] = w[i] * c[k + 1][i];
        }
        for (int i = 0; i < 3; ++i) {
            real v = 0;
            for (int k = kTaylorTerms; k >= 0; --k) v += c[k][i];
            m[i] = v;
        }
    }
    for (int i = 0; i < 3; ++i) out[i] = m[i];
}

/* I_p = I_q, (p, q, r) cyclic: m_r is constant and (m_p, m_q) turns at the
 * rate m_r (1/I_r - 1/I_p), in long double. */
static void symmetric_reference(const double I[3], const double m0[3], double t, real out[3]) {
    const int r = I[0] == I[1] ? 2 : I[1] == I[2] ? 0 : 1, p = (r + 1) % 3, q = (r + 2) % 3;
    const real angle = m0[r] * (1.0L / I[r] - 1.0L / I[p]) * t;
    out[p] = m0[p] * cosl(angle) + m0[q] * sinl(angle);
    out[q] = m0[q] * cosl(angle) - m0[p] * sinl(angle);
    out[r] = m0[r];
}

/* Valgrind performs x87 arithmetic in 64 bits. */
static int long_double_is_extended(void) {
    volatile real one = 1.0L, epsilon = LDBL_EPSILON;
    return LDBL_MANT_DIG > DBL_MANT_DIG && (one + epsilon) - one == epsilon;
}

/* ---- random cases ---------------------------------------------------------- */

typedef struct {
    uint64_t state;
} rng;
static double uniform(rng *r, double lo, double hi) {
    r->state = r->state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * ((double)(r->state >> 11) / 9007199254740992.0);
}
static double log_uniform(rng *r, double lo, double hi) { return exp(uniform(r, log(lo), log(hi))); }
static double random_sign(rng *r) { return uniform(r, 0, 1) < 0.5 ? -1.0 : 1.0; }
static int random_index(rng *r, int n) { return (int)uniform(r, 0, n) % n; }

static double norm3(const double m[3]) { return sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]); }

/* A uniformly random direction scaled to `length`. */
static void random_vector(rng *r, double length, double m[3]) {
    double n;
    do {
        for (int i = 0; i < 3; ++i) m[i] = uniform(r, -1, 1);
        n = norm3(m);
    } while (n > 1 || n < 1e-3);
    for (int i = 0; i < 3; ++i) m[i] *= length / n;
}

/* Moves the labelled axes (lo, mid, hi) = slots 0, 1, 2 to a random order. */
static void permute_axes(rng *r, double I[3], double m[3]) {
    static const int orders[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    const int *o = orders[random_index(r, 6)];
    const double I0[3] = {I[0], I[1], I[2]}, m0[3] = {m[0], m[1], m[2]};
    for (int i = 0; i < 3; ++i) I[o[i]] = I0[i], m[o[i]] = m0[i];
}

/* Three distinct moments in increasing order. */
static void random_triaxial(rng *r, double I[3]) {
    do {
        for (int i = 0; i < 3; ++i) I[i] = log_uniform(r, 0.1, 10);
    } while (I[0] == I[1] || I[1] == I[2] || I[0] == I[2]);
    for (int i = 0; i < 3; ++i) /* sort */
        for (int j = i + 1; j < 3; ++j)
            if (I[j] < I[i]) {
                const double x = I[i];
                I[i] = I[j], I[j] = x;
            }
}

/* Rate of escape from the middle axis (sorted I): |m| sqrt((w_lo - w_mid)(w_mid - w_hi)). */
static double saddle_rate(const double I[3], double norm) {
    return norm * sqrt((1 / I[0] - 1 / I[1]) * (1 / I[1] - 1 / I[2]));
}

/* A point of the separatrix of sorted I: m_hi^2 (w_mid - w_hi) = m_lo^2
 * (w_lo - w_mid), at hyperbolic phase u (|u| small: far from the middle
 * axis, which the orbit reaches as |u| -> infinity). exact != 0 makes the
 * relation hold exactly in real arithmetic: I = ((k^2 - 2j) 8, (k^2 - 2j)(8 +
 * j), k^2 (8 + j)) times a power of two and m_hi = (k / 4) m_lo with short
 * mantissas. Otherwise I is random and m_hi rounded (about u from it). */
static void separatrix_point(rng *r, int exact, double u, double I[3], double m[3]) {
    if (exact) {
        const int j = 1 + random_index(r, 20);
        int k = 1 + random_index(r, 40);
        while (k * k <= 2 * j) ++k;
        const double scale = ldexp(1.0, random_index(r, 9) - 4);
        I[0] = 8.0 * (k * k - 2 * j) * scale;
        I[1] = (double)(k * k - 2 * j) * (8 + j) * scale;
        I[2] = (double)k * k * (8 + j) * scale;
        m[0] = (1 + random_index(r, 1023)) / 1024.0;
        m[2] = m[0] * k / 4;
    } else {
        random_triaxial(r, I);
        m[0] = uniform(r, 0.1, 1);
        m[2] = m[0] * sqrt((1 / I[0] - 1 / I[1]) / (1 / I[1] - 1 / I[2]));
    }
    /* On the separatrix sinh u = sqrt(d) m_mid / |m_lo|, d = (w_mid - w_hi) / (w_lo - w_hi). */
    const double d = (1 / I[1] - 1 / I[2]) / (1 / I[0] - 1 / I[2]);
    m[1] = m[0] * sinh(u) / sqrt(d);
    m[0] *= random_sign(r);
    m[2] *= random_sign(r);
}

typedef struct {
    double I[3], m[3], t;
} rigid_case;

/* Any three moments, any state. */
static void draw_generic(rng *r, rigid_case *c) {
    random_triaxial(r, c->I);
    random_vector(r, log_uniform(r, 1e-3, 1e3), c->m);
    c->t = uniform(r, -10, 10) / (norm3(c->m) * inertia_spread(c->I));
    permute_axes(r, c->I, c->m);
}

/* Long times: 100 to 300 over the rate. */
static void draw_generic_long(rng *r, rigid_case *c) {
    draw_generic(r, c);
    c->t = random_sign(r) * uniform(r, 100, 300) / (norm3(c->m) * inertia_spread(c->I));
}

/* Two equal moments, any state. */
static void draw_symmetric(rng *r, rigid_case *c) {
    do {
        c->I[0] = c->I[1] = log_uniform(r, 0.1, 10);
        c->I[2] = log_uniform(r, 0.1, 10);
    } while (c->I[0] == c->I[2]);
    random_vector(r, log_uniform(r, 1e-3, 1e3), c->m);
    c->t = uniform(r, -10, 10) / (norm3(c->m) * inertia_spread(c->I));
    permute_axes(r, c->I, c->m);
}

/* Two equal moments over 100 to 1000 turns of the rate. */
static void draw_symmetric_long(rng *r, rigid_case *c) {
    draw_symmetric(r, c);
    c->t *= uniform(r, 10, 100);
}

/* Two moments equal to a relative 1e-16 .. 1e-4; a third of the states in
 * the plane of those two (steady if they were equal). */
static void draw_nearly_symmetric(rng *r, rigid_case *c) {
    c->I[0] = log_uniform(r, 0.1, 10);
    c->I[1] = c->I[0] * (1 + random_sign(r) * log_uniform(r, 1e-16, 1e-4));
    c->I[2] = log_uniform(r, 0.1, 10);
    random_vector(r, log_uniform(r, 1e-3, 1e3), c->m);
    if (random_index(r, 3) == 0) c->m[2] = 0;
    c->t = uniform(r, -10, 10) / (norm3(c->m) * inertia_spread(c->I));
    permute_axes(r, c->I, c->m);
}

/* Steady rotations, whatever t: on an axis, in the plane of two equal axes,
 * any state of a sphere; in the last two, one component in two cases is
 * 1e-290 .. 1e-318 of the others (subnormal once the state is scaled to
 * magnitudes near 1, which rounded it). */
static void draw_steady(rng *r, rigid_case *c) {
    const int kind = random_index(r, 3);
    const double length = log_uniform(r, 1e-3, 1e3);
    if (kind == 0) {
        random_triaxial(r, c->I);
        c->m[0] = c->m[1] = c->m[2] = 0;
        c->m[random_index(r, 3)] = random_sign(r) * length;
    } else if (kind == 1) {
        c->I[0] = c->I[1] = log_uniform(r, 0.1, 10);
        c->I[2] = log_uniform(r, 0.1, 10);
        random_vector(r, length, c->m);
        c->m[2] = 0;
    } else {
        c->I[0] = c->I[1] = c->I[2] = log_uniform(r, 0.1, 10);
        random_vector(r, length, c->m);
    }
    if (kind > 0 && random_index(r, 2)) c->m[random_index(r, 2)] *= log_uniform(r, 1e-318, 1e-290);
    c->t = random_sign(r) * log_uniform(r, 1e-3, 1e6) / (length * (inertia_spread(c->I) + 1));
    permute_axes(r, c->I, c->m);
}

/* Separatrix families: from |u| <= 2, up to 6 over the escape rate either
 * way, so the orbit stays at least sech(8) |m| from the middle axis. Closer
 * passes are left to the near-axis family: the long double reference itself
 * carries about 1e-18 / (distance of the pass)^2 there. */
static void separatrix_case(rng *r, int exact, double relative_offset, rigid_case *c) {
    separatrix_point(r, exact, uniform(r, -2, 2), c->I, c->m);
    c->m[2] *= 1 + relative_offset;
    c->t = uniform(r, -6, 6) / saddle_rate(c->I, norm3(c->m));
    permute_axes(r, c->I, c->m);
}
static void draw_on_separatrix(rng *r, rigid_case *c) { separatrix_case(r, 1, 0, c); }
static void draw_rounded_separatrix(rng *r, rigid_case *c) { separatrix_case(r, 0, 0, c); }
static void draw_beside_separatrix(rng *r, rigid_case *c) {
    separatrix_case(r, 1, random_sign(r) * log_uniform(r, 1e-16, 1e-4), c);
}

/* Within 1e-16 .. 1e-4 (relative) of axis `axis` of sorted I. */
static void near_axis(rng *r, int axis, rigid_case *c) {
    random_triaxial(r, c->I);
    const double length = log_uniform(r, 1e-3, 1e3), distance = log_uniform(r, 1e-16, 1e-4);
    random_vector(r, length * distance, c->m);
    c->m[axis] = random_sign(r) * length;
}

/* Near the largest or the smallest moment's axis (stable). */
static void draw_near_stable_axis(rng *r, rigid_case *c) {
    near_axis(r, random_index(r, 2) * 2, c);
    c->t = uniform(r, -10, 10) / (norm3(c->m) * inertia_spread(c->I));
    permute_axes(r, c->I, c->m);
}

/* Near the middle axis, until (about) 3 over the escape rate after leaving. */
static void draw_near_middle_axis(rng *r, rigid_case *c) {
    near_axis(r, 1, c);
    const double distance = hypot(c->m[0], c->m[2]) / norm3(c->m);
    c->t = uniform(r, -1, 1) * (log(1 / distance) + 3) / saddle_rate(c->I, norm3(c->m));
    permute_axes(r, c->I, c->m);
}

/* ---- the check ---------------------------------------------------------------- */

typedef enum { REF_TAYLOR, REF_SYMMETRIC, REF_INPUT } reference_kind;

typedef struct {
    const char *name;
    int count;
    void (*draw)(rng *, rigid_case *);
    reference_kind reference;
} family;

static void exact_at(const rigid_case *c, double t, double out[3]) {
    lpi_system *sys = NULL;
    assert_int_equal(lpi_rigid_body_create(&sys, c->I[0], c->I[1], c->I[2]), LPI_OK);
    assert_int_equal(lpi_set_state(sys, c->m, 3), LPI_OK);
    const int status = lpi_rigid_body_exact(sys, t, out);
    if (status != LPI_OK)
        fail_msg("I = (%.17g, %.17g, %.17g), m0 = (%.17g, %.17g, %.17g), t = %.17g: %s (%s)", c->I[0],
                 c->I[1], c->I[2], c->m[0], c->m[1], c->m[2], t, lpi_status_name(status),
                 lpi_last_error(sys));
    lpi_destroy(sys);
}

static double relative_distance(const double x[3], const real y[3], const double m0[3]) {
    real d = 0;
    for (int i = 0; i < 3; ++i) d += (x[i] - y[i]) * (x[i] - y[i]);
    return (double)(sqrtl(d) / norm3(m0));
}

/* Runs one family; fails past `tolerance` (relative to |m|) at t, or past a
 * few ulps at t = 0, naming the worst case. */
static void check_family(const family *f, uint64_t seed, int with_references) {
    const double tolerance = 1e-12, at_zero_tolerance = 16 * DBL_EPSILON;
    rng r = {seed};
    double worst = 0, worst_at_zero = 0;
    rigid_case worst_case = {{0}, {0}, 0};
    for (int n = 0; n < f->count; ++n) {
        rigid_case c;
        f->draw(&r, &c);
        double out[3];
        real reference[3];
        exact_at(&c, 0.0, out);
        const real input[3] = {c.m[0], c.m[1], c.m[2]};
        worst_at_zero = fmax(worst_at_zero, relative_distance(out, input, c.m));
        if (f->reference == REF_INPUT) {
            exact_at(&c, c.t, out);
            if (memcmp(out, c.m, sizeof out) != 0)
                fail_msg("%s: I = (%.17g, %.17g, %.17g), m0 = (%.17g, %.17g, %.17g), t = %.17g "
                         "moved to (%.17g, %.17g, %.17g)", f->name, c.I[0], c.I[1], c.I[2], c.m[0],
                         c.m[1], c.m[2], c.t, out[0], out[1], out[2]);
            continue;
        }
        if (!with_references) continue;
        exact_at(&c, c.t, out);
        if (f->reference == REF_TAYLOR)
            taylor_reference(c.I, c.m, c.t, reference);
        else
            symmetric_reference(c.I, c.m, c.t, reference);
        double e = relative_distance(out, reference, c.m);
        if (isnan(e)) e = INFINITY;
        if (e > worst) worst = e, worst_case = c;
    }
    if (f->reference == REF_INPUT)
        print_message("%-26s %5d cases: unchanged bit for bit; at t = 0: %.1e\n", f->name, f->count,
                      worst_at_zero);
    else if (with_references)
        print_message("%-26s %5d cases: worst |exact - reference| / |m| = %.1e; at t = 0: %.1e\n",
                      f->name, f->count, worst, worst_at_zero);
    else
        print_message("%-26s %5d cases: at t = 0: %.1e\n", f->name, f->count, worst_at_zero);
    if (worst > tolerance)
        fail_msg("%s: I = (%.17g, %.17g, %.17g), m0 = (%.17g, %.17g, %.17g), t = %.17g: "
                 "|exact - reference| / |m| = %.3e",
                 f->name, worst_case.I[0], worst_case.I[1], worst_case.I[2], worst_case.m[0],
                 worst_case.m[1], worst_case.m[2], worst_case.t, worst);
    if (!(worst_at_zero <= at_zero_tolerance)) /* NaN fails too */
        fail_msg("%s: at t = 0 the result is %.3e |m| from the input", f->name, worst_at_zero);
}

static const family families[] = {
    {"generic", 2500, draw_generic, REF_TAYLOR},
    {"generic, long times", 100, draw_generic_long, REF_TAYLOR},
    {"two equal moments", 1500, draw_symmetric, REF_TAYLOR},
    {"two equal, long times", 500, draw_symmetric_long, REF_SYMMETRIC},
    {"nearly symmetric", 1000, draw_nearly_symmetric, REF_TAYLOR},
    {"steady rotations", 1000, draw_steady, REF_INPUT},
    {"on the separatrix", 1000, draw_on_separatrix, REF_TAYLOR},
    {"separatrix, rounded", 1000, draw_rounded_separatrix, REF_TAYLOR},
    {"beside the separatrix", 1500, draw_beside_separatrix, REF_TAYLOR},
    {"near a stable axis", 1000, draw_near_stable_axis, REF_TAYLOR},
    {"near the middle axis", 1000, draw_near_middle_axis, REF_TAYLOR},
};

static void test_every_family_matches_its_reference(void **state) {
    (void)state;
    const int with_references = long_double_is_extended();
    if (!with_references)
        print_message("long double arithmetic is not extended here (valgrind?): "
                      "checking t = 0 and steady rotations only\n");
    for (size_t i = 0; i < sizeof families / sizeof families[0]; ++i)
        check_family(&families[i], 0x5eed0000u + i, with_references);
}

/* The Taylor reference itself against the closed form of a symmetric top, so
 * that its accuracy is measured rather than assumed. */
static void test_taylor_reference_is_tight(void **state) {
    (void)state;
    if (!long_double_is_extended()) skip();
    const double I[3] = {2, 2, 0.5}, m0[3] = {0.3, -0.7, 1.1};
    real taylor[3], closed[3];
    taylor_reference(I, m0, 37.0, taylor);
    symmetric_reference(I, m0, 37.0, closed);
    double difference = 0;
    for (int i = 0; i < 3; ++i) difference = fmax(difference, (double)fabsl(taylor[i] - closed[i]));
    print_message("Taylor reference against the symmetric closed form: %.1e\n", difference);
    assert_true(difference < 1e-16);
}

static void test_bad_input(void **state) {
    (void)state;
    lpi_system *body = NULL, *pendulum = NULL;
    double out[3];
    assert_int_equal(lpi_rigid_body_create(&body, 1, 2, 3), LPI_OK);
    assert_int_equal(lpi_pendulum_create(&pendulum), LPI_OK);
    LPI_ASSERT_FAILS(NULL, lpi_rigid_body_exact(NULL, 1.0, out), LPI_ERR_NULL, "lpi_rigid_body_exact");
    LPI_ASSERT_FAILS(body, lpi_rigid_body_exact(body, 1.0, NULL), LPI_ERR_NULL, "lpi_rigid_body_exact");
    LPI_ASSERT_FAILS(body, lpi_rigid_body_exact(body, NAN, out), LPI_ERR_NONFINITE, "lpi_rigid_body_exact");
    LPI_ASSERT_FAILS(pendulum, lpi_rigid_body_exact(pendulum, 1.0, out), LPI_ERR_UNSUPPORTED,
                     "lpi_rigid_body_exact");
    /* t times the rate scale |m| / I past DBL_MAX: the phase is not
     * representable (the state is ordinary: it was named an overflow). */
    lpi_system *fast = NULL;
    const double m[3] = {1.0, 0.5, 1.0};
    assert_int_equal(lpi_rigid_body_create(&fast, 1e-10, 2e-10, 3e-10), LPI_OK);
    assert_int_equal(lpi_set_state(fast, m, 3), LPI_OK);
    LPI_ASSERT_FAILS(fast, lpi_rigid_body_exact(fast, 1e300, out), LPI_ERR_NONFINITE, "lpi_rigid_body_exact");
    assert_non_null(strstr(lpi_last_error(fast), "phase of the solution"));
    assert_int_equal(lpi_rigid_body_exact(fast, 1e290, out), LPI_OK);
    lpi_destroy(fast);
    /* The rates go with |m| over the smallest inertia, not the largest. */
    const double spread_inertia[3][3] = {{1e-10, 2e-10, 1.0}, {1.0, 1.0, 1e-300}};
    const double spread_t[2] = {1e300, 1e10};
    for (int c = 0; c < 2; ++c) {
        assert_int_equal(lpi_rigid_body_create(&fast, spread_inertia[c][0], spread_inertia[c][1],
                                               spread_inertia[c][2]), LPI_OK);
        assert_int_equal(lpi_set_state(fast, m, 3), LPI_OK);
        LPI_ASSERT_FAILS(fast, lpi_rigid_body_exact(fast, spread_t[c], out), LPI_ERR_NONFINITE,
                         "lpi_rigid_body_exact");
        assert_non_null(strstr(lpi_last_error(fast), "phase of the solution"));
        lpi_destroy(fast);
    }
    /* A steady rotation comes back unchanged at any t. */
    const double steady[3] = {1e300, 1e-300, 0.0};
    assert_int_equal(lpi_rigid_body_create(&fast, 1, 2, 3), LPI_OK);
    assert_int_equal(lpi_set_state(fast, steady, 3), LPI_OK);
    assert_int_equal(lpi_rigid_body_exact(fast, 1e20, out), LPI_OK);
    assert_memory_equal(out, steady, sizeof steady);
    lpi_destroy(fast);
    /* So does one in the plane of two equal moments whose inertias are more
     * than 2^1022 apart (refused as an overflow of their ratio before). */
    const double planar[3] = {1.0, -2.0, 0.0};
    assert_int_equal(lpi_rigid_body_create(&fast, 1e-300, 1e-300, 1e300), LPI_OK);
    assert_int_equal(lpi_set_state(fast, planar, 3), LPI_OK);
    assert_int_equal(lpi_rigid_body_exact(fast, 10.0, out), LPI_OK);
    assert_memory_equal(out, planar, sizeof planar);
    lpi_destroy(fast);
    /* Inertias 2^1100 apart: their ratio is no double (a NaN was named an
     * overflow of the solution's component 0). */
    lpi_system *spread = NULL;
    assert_int_equal(lpi_rigid_body_create(&spread, 1e-165, 1.0, 1e165), LPI_OK);
    assert_int_equal(lpi_set_state(spread, m, 3), LPI_OK);
    LPI_ASSERT_FAILS(spread, lpi_rigid_body_exact(spread, 1.0, out), LPI_ERR_OVERFLOW, "lpi_rigid_body_exact");
    /* The message names the two inertias, not an internal scaling. */
    assert_non_null(strstr(lpi_last_error(spread), "ratio of the inertias 9.999999999999999e+164 and 1e-165"));
    lpi_destroy(spread);
    lpi_destroy(body);
    lpi_destroy(pendulum);
}

/* Components more than 2^1074 times smaller than the largest vanish when the
 * state is scaled to magnitudes near 1: the state is then a steady rotation
 * to far below round-off and comes back unchanged (it reached a negated
 * ilogb(0) in the triaxial amplitudes, found by fuzz_api). */
static void test_components_below_the_scale(void **state) {
    (void)state;
    const double cases[][3] = {{1e-320, 1e300, -1e-320}, {1e-320, 1e300, 0.0}, {4e-324, -1e10, 4e-324}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        lpi_system *body = NULL;
        double out[3];
        assert_int_equal(lpi_rigid_body_create(&body, 1, 2, 3), LPI_OK);
        assert_int_equal(lpi_set_state(body, cases[i], 3), LPI_OK);
        assert_int_equal(lpi_rigid_body_exact(body, 5.0, out), LPI_OK);
        assert_memory_equal(out, cases[i], sizeof out);
        lpi_destroy(body);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_taylor_reference_is_tight),
        cmocka_unit_test(test_every_family_matches_its_reference),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_components_below_the_scale),
    };
    return lpi_run_tests(tests);
}
