// The C ABI of generic Lie-Poisson systems and the moment algebra.
#include <cmath>
#include <string>

#include "../models/generic.hpp"
#include "handle.hpp"

using lpi::capi::create;
using lpi::capi::guarded;
using lpi::capi::require;

namespace {

// The generic model behind sys, or LPI_ERR_UNSUPPORTED naming what it is.
lpi::GenericModel &generic_model(const lpi_system *sys) {
    auto *model = dynamic_cast<lpi::GenericModel *>(const_cast<lpi::Model *>(&sys->system.model()));
    if (!model)
        lpi::fail(LPI_ERR_UNSUPPORTED, std::string("a ") + sys->system.model().kind() +
                                           " system has no user pieces or structure constants "
                                           "(create it with lpi_generic_create or "
                                           "lpi_moments_create)");
    return *model;
}

// Rebuilds the integrator for the new piece count; on failure the piece goes.
void commit_piece(lpi_system *sys, lpi::GenericModel &model) {
    try {
        sys->system.rebuild_integrator();
    } catch (...) {
        model.remove_last_piece();
        throw;
    }
}

}  // namespace

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
    return guarded(sys, "lpi_add_piece", [&] {
        require(sys, "system");
        lpi::GenericModel &model = generic_model(sys);
        require(indices, "indices");
        model.add_piece(n, indices, grad, energy, user);
        commit_piece(sys, model);
    });
}

LPI_API int lpi_add_casimir(lpi_system *sys, lpi_casimir_fn fn, void *user) {
    return guarded(sys, "lpi_add_casimir", [&] {
        require(sys, "system");
        generic_model(sys).add_casimir(fn, user);
    });
}

LPI_API int lpi_poisson_rank(const lpi_system *sys, const double *x, size_t n, size_t *rank) {
    return guarded(sys, "lpi_poisson_rank", [&] {
        require(sys, "system");
        const lpi::GenericModel &model = generic_model(sys);
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
    return guarded(sys, "lpi_moments_add_product_piece", [&] {
        require(sys, "system");
        lpi::GenericModel &model = generic_model(sys);
        lpi::add_moments_product_piece(model, h, dh, user);
        commit_piece(sys, model);
    });
}

}  // extern "C"
