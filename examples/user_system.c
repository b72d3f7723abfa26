/* A user-defined Lie-Poisson system: the heavy top on e(3)* = (so(3) x R^3)*.
 *
 *   x = (M1, M2, M3, G1, G2, G3)   angular momentum M, direction of gravity G
 *   {M_i, M_j} = -eps_ijk M_k,  {M_i, G_j} = -eps_ijk G_k,  {G_i, G_j} = 0
 *   H = M1^2/(2 I1) + M2^2/(2 I2) + M3^2/(2 I3) + mgl G3
 *
 * Each term depends on an abelian set ({0}, {1}, {2}, {3,4,5}), so the library
 * integrates each exactly and composes them; the Casimirs |G|^2 and M.G are
 * declared so that lpi_casimirs reports them. Build:
 *   cc user_system.c -lliepoisson -lm
 * Exits 0 when the Casimirs were kept to round-off. */
#include <liepoisson.h>
#include <math.h>
#include <stdio.h>

typedef struct {
    double inertia;
} axis_data;

static int axis_grad(size_t n, const double *x, double *g, void *user) {
    (void)n;
    g[0] = x[0] / ((const axis_data *)user)->inertia;
    return 0;
}

static int axis_energy(size_t n, const double *x, double *h, void *user) {
    (void)n;
    *h = 0.5 * x[0] * x[0] / ((const axis_data *)user)->inertia;
    return 0;
}

static const double kMgl = 0.8;

static int gravity_grad(size_t n, const double *x, double *g, void *user) {
    (void)n; (void)x; (void)user;
    g[0] = 0.0;
    g[1] = 0.0;
    g[2] = kMgl;
    return 0;
}

static int gravity_energy(size_t n, const double *x, double *h, void *user) {
    (void)n; (void)user;
    *h = kMgl * x[2];
    return 0;
}

static int gamma_squared(size_t dim, const double *x, double *out, void *user) {
    (void)dim; (void)user;
    *out = x[3] * x[3] + x[4] * x[4] + x[5] * x[5];
    return 0;
}

static int m_dot_gamma(size_t dim, const double *x, double *out, void *user) {
    (void)dim; (void)user;
    *out = x[0] * x[3] + x[1] * x[4] + x[2] * x[5];
    return 0;
}

#define CHECK(call)                                                                        \
    do {                                                                                   \
        int status_ = (call);                                                              \
        if (status_ != LPI_OK) {                                                           \
            fprintf(stderr, "%s: %s\n", lpi_status_name(status_), lpi_last_error(sys));   \
            lpi_destroy(sys);                                                              \
            return 1;                                                                      \
        }                                                                                  \
    } while (0)

int main(void) {
    /* {x_i, x_j} = c x_k, one entry per pair i < j (the other order is implied). */
    const int32_t i[] = {0, 0, 1, 0, 0, 1, 1, 2, 2};
    const int32_t j[] = {1, 2, 2, 4, 5, 3, 5, 3, 4};
    const int32_t k[] = {2, 1, 0, 5, 4, 5, 3, 4, 3};
    const double c[] = {-1, 1, -1, -1, 1, 1, -1, -1, 1};
    lpi_system *sys = NULL;
    CHECK(lpi_generic_create(&sys, 6, 9, i, j, k, c));

    static axis_data axes[3] = {{1.0}, {1.5}, {3.0}};
    for (int32_t a = 0; a < 3; ++a) CHECK(lpi_add_piece(sys, 1, &a, axis_grad, axis_energy, &axes[a]));
    const int32_t gravity[] = {3, 4, 5};
    CHECK(lpi_add_piece(sys, 3, gravity, gravity_grad, gravity_energy, NULL));
    CHECK(lpi_add_casimir(sys, gamma_squared, NULL));
    CHECK(lpi_add_casimir(sys, m_dot_gamma, NULL));

    const double x0[6] = {0.4, -0.2, 2.0, 0.0, 0.6, 0.8};
    size_t rank = 0;
    CHECK(lpi_poisson_rank(sys, x0, 6, &rank));
    printf("heavy top: dim 6, Poisson rank %zu, so %zu Casimirs expected, %zu declared\n", rank,
           6 - rank, lpi_casimir_count(sys));

    CHECK(lpi_set_method(sys, "triple-jump-4"));
    CHECK(lpi_set_state(sys, x0, 6));
    double h0, c0[2], h, cas[2];
    CHECK(lpi_energy(sys, &h0));
    CHECK(lpi_casimirs(sys, c0, 2));
    CHECK(lpi_step(sys, 0.01, 100000));
    CHECK(lpi_energy(sys, &h));
    CHECK(lpi_casimirs(sys, cas, 2));
    const double drift0 = fabs(cas[0] - c0[0]) / fabs(c0[0]);
    const double drift1 = fabs(cas[1] - c0[1]) / fabs(c0[1]);
    printf("after 1e5 steps of triple-jump-4 (t = %g): energy error %.2e, "
           "|G|^2 drift %.2e, M.G drift %.2e\n",
           lpi_time(sys), fabs(h - h0) / fabs(h0), drift0, drift1);
    lpi_destroy(sys);
    return rank == 4 && drift0 < 1e-12 && drift1 < 1e-12 ? 0 : 1;
}
