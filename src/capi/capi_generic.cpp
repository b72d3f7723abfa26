// The C ABI of generic Lie-Poisson systems and the moment algebra.
#include <cmath>

#include "../models/generic.hpp"
#include "handle.hpp"

using lpi::capi::create;
using lpi::capi::Arguments;
using lpi::capi::guarded;
using lpi::capi::guarded_local_read;
using lpi::capi::require;

extern "C" {

LPI_API int lpi_generic_create(lpi_system **out, size_t dim, size_t nnz, const int32_t *i,
                               const int32_t *j, const int32_t *k, const double *c) {
    return create(out, "lpi_generic_create", [&] {
        if (nnz > 0) {
            require(i, "i");
            require(j, "j");
            require(k, "k");
            require(c, "c");
        }
        return lpi::make_generic(dim, nnz, i, j, k, c);
    });
}

LPI_API int lpi_add_piece(lpi_system *sys, size_t n, const int32_t *indices,
                          lpi_gradient_fn grad, lpi_energy_fn energy, void *user) {
    return guarded(sys, "lpi_add_piece", Arguments(n, indices, grad, energy), [&] {
        require(sys, "system");
        lpi::generic_model_of(sys->system);  // the kind first: a rigid body has no pieces to add
        require(indices, "indices");
        lpi::add_piece(sys->system, n, indices, grad, energy, user);
    });
}

LPI_API int lpi_add_casimir(lpi_system *sys, lpi_casimir_fn fn, void *user) {
    return guarded(sys, "lpi_add_casimir", Arguments(fn), [&] {
        require(sys, "system");
        lpi::generic_model_of(sys->system).add_casimir(fn, user);
    });
}

LPI_API int lpi_poisson_rank(const lpi_system *sys, const double *x, size_t n, size_t *rank) {
    return guarded_local_read(sys, "lpi_poisson_rank", [&] {
        require(sys, "system");
        const lpi::GenericModel &model = lpi::generic_model_of(sys->system);
        require(x, "x");
        require(rank, "rank");
        lpi::require_length("x", n, model.dim());
        for (size_t q = 0; q < n; ++q)
            if (!std::isfinite(x[q]))
                lpi::fail(LPI_ERR_NONFINITE, "x[" + std::to_string(q) + "] is not finite");
        *rank = model.poisson_rank(x);
    });
}

LPI_API int lpi_moments_create(lpi_system **out) {
    return create(out, "lpi_moments_create", [] { return lpi::make_moments(); });
}

LPI_API int lpi_moments_add_product_piece(lpi_system *sys, lpi_scalar_fn h, lpi_scalar_fn dh,
                                          void *user) {
    return guarded(sys, "lpi_moments_add_product_piece", Arguments(h, dh), [&] {
        require(sys, "system");
        lpi::add_moments_product_piece(sys->system, h, dh, user);
    });
}

}  // extern "C"
