// Generic Lie-Poisson systems (paper section 1): user structure constants and
// a Hamiltonian split into pieces H_k(x_sigma) on abelian index sets sigma.
// Along such a piece x_sigma is constant, so its flow is x' = A x with
// A_il = sum_{j in sigma} c_ij^l g_j, g = grad H_k: solved exactly (expm.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "../core/model.hpp"
#include "compiled_flows.hpp"
#include "expm.hpp"
#include "liepoisson.h"

namespace lpi {

class System;

// {x_i, x_j} = sum_l c_ij^l x_l, stored sparsely in both orders. Construction
// validates ranges, antisymmetry and the Jacobi identity (throws lpi::Error).
class StructureConstants {
public:
    struct Output {  // one term c * x_l of a bracket
        std::uint32_t l;
        double c;
    };
    struct Term {  // c_ij^l for a fixed second index j
        std::uint32_t i;
        std::uint32_t l;
        double c;
    };

    StructureConstants(std::size_t dim, std::size_t nnz, const std::int32_t *i,
                       const std::int32_t *j, const std::int32_t *k, const double *c);

    std::size_t dim() const { return dim_; }
    // The nonzero terms of {x_i, x_j}; empty when the bracket vanishes.
    const std::vector<Output> &bracket(std::uint32_t i, std::uint32_t j) const;
    // Every nonzero c_ij^l with second index j.
    const std::vector<Term> &column(std::uint32_t j) const { return columns_[j]; }
    // Dense J(x), dim x dim row-major.
    void poisson_matrix(const double *x, double *J) const;

private:
    void check_jacobi() const;

    std::size_t dim_;
    std::unordered_map<std::uint64_t, std::vector<Output>> brackets_;  // key i * dim + j
    std::vector<std::vector<Term>> columns_;
    std::vector<Output> none_;
};

// One piece of the Hamiltonian. `label` names it in error messages.
class Piece {
public:
    explicit Piece(std::string label) : label_(std::move(label)) {}
    virtual ~Piece() = default;
    const std::string &label() const { return label_; }
    virtual void flow(double t, double *x) = 0;  // exact, in place
    virtual double energy(const double *x) const = 0;
    virtual void add_vector_field(const double *x, double *rate) const = 0;  // rate += J grad H_k

private:
    std::string label_;
};

// A user-declared Casimir.
struct CasimirCallback {
    lpi_casimir_fn fn;
    void *user;
    std::string builtin;  // name of a built-in Casimir ("" for a user callback)
};

class GenericModel : public Model {
public:
    explicit GenericModel(std::unique_ptr<StructureConstants> constants,
                          const char *kind = "generic");

    const char *kind() const override { return kind_; }
    std::size_t dim() const override { return constants_->dim(); }

    std::vector<std::string> split_names() const override { return split_.names(); }
    void set_split(const std::string &name) override { split_.select(name, kind_); }
    std::string split() const override { return split_.current(); }
    // A system without pieces reports one, whose flow refuses to run: every
    // method then fails with a clear message instead of doing nothing.
    std::size_t piece_count() const override { return pieces_.size(); }

    void flow(std::size_t piece, double t, double *state) override;
    double energy(const double *state) const override;
    std::size_t casimir_count() const override { return casimirs_.size(); }
    void casimirs(const double *state, double *out) const override;
    void vector_field(const double *state, double *rate) const override;
    // Refuses (LPI_ERR_UNSUPPORTED): the pieces and Casimirs are user callbacks.
    std::vector<double> checkpoint_parameters() const override;

    const StructureConstants &constants() const { return *constants_; }
    std::size_t pieces() const { return pieces_.size(); }

    // Validates (range, duplicates, abelian, callbacks) and appends.
    void add_piece(std::size_t n, const std::int32_t *indices, lpi_gradient_fn grad,
                   lpi_energy_fn energy, void *user);
    void add_piece(std::unique_ptr<Piece> piece) { pieces_.push_back(std::move(piece)); }
    void remove_last_piece() { pieces_.pop_back(); }
    void add_casimir(lpi_casimir_fn fn, void *user);
    // A Casimir of the library's own: a non-finite value is an overflow of
    // the state's scale (LPI_ERR_NONFINITE), not a failed callback.
    void add_builtin_casimir(lpi_casimir_fn fn, const std::string &name);

    // Compiled flows for this model's structure constants (a built-in
    // algebra's, compiled_flows.hpp): pieces added from now on whose index
    // set has one use it instead of the general plan, with the same bits.
    void set_compiled_flows(CompiledFlow (*lookup)(unsigned mask)) { compiled_flows_ = lookup; }

    // "piece 3" for the next piece to be added.
    std::string next_piece_name() const { return "piece " + std::to_string(pieces_.size()); }

    // Numerical rank of J(x): one-sided Jacobi SVD (Hestenes 1958), singular
    // values above dim * eps * sigma_max.
    std::size_t poisson_rank(const double *x) const;

private:
    const char *kind_;
    std::unique_ptr<StructureConstants> constants_;
    std::vector<std::unique_ptr<Piece>> pieces_;
    std::vector<CasimirCallback> casimirs_;
    CompiledFlow (*compiled_flows_)(unsigned mask) = nullptr;
    SplitChoice split_{{"pieces"}};
};

// Singular values of the n x n row-major matrix M (destroyed), unordered.
std::vector<double> singular_values(std::size_t n, std::vector<double> M);

// rate_i += sum_{p} J_{i, sigma_p}(x) g_p: the vector field of a piece whose
// gradient g lives on the index set sigma.
void add_poisson_times(const StructureConstants &c, const std::uint32_t *sigma, std::size_t n,
                       const double *g, const double *x, double *rate);

// The generic model of a system; LPI_ERR_UNSUPPORTED naming the system's
// kind for every other kind.
GenericModel &generic_model_of(System &system);
const GenericModel &generic_model_of(const System &system);

// Appends a piece to the system's generic model (validated as in
// GenericModel::add_piece) and rebuilds the system's integrator for it. When
// either fails, the system is left as it was.
void add_piece(System &system, std::size_t n, const std::int32_t *indices, lpi_gradient_fn grad,
               lpi_energy_fn energy, void *user);
// Rebuilds the system's integrator after model (its own) gained a piece; on
// failure the piece is removed again and the failure rethrown.
void commit_new_piece(System &system, GenericModel &model);

std::unique_ptr<GenericModel> make_generic(std::size_t dim, std::size_t nnz, const std::int32_t *i,
                                           const std::int32_t *j, const std::int32_t *k,
                                           const double *c);

// The moment algebra of the paper (kind "moments"), Casimirs I and K declared.
std::unique_ptr<GenericModel> make_moments();
// Appends the product piece H(x1 x3) as add_piece does; LPI_ERR_UNSUPPORTED
// unless the system is a moments system.
void add_moments_product_piece(System &system, lpi_scalar_fn h, lpi_scalar_fn dh, void *user);

}  // namespace lpi
