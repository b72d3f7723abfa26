#include "generic.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "../core/error.hpp"
#include "../core/system.hpp"
#include "../core/text.hpp"

namespace lpi {

namespace {

std::string x_name(std::uint32_t i) { return "x_" + std::to_string(i); }

std::string bracket_text(std::uint32_t i, std::uint32_t j,
                         const std::vector<StructureConstants::Output> &terms) {
    std::string s = "{" + x_name(i) + ", " + x_name(j) + "} = ";
    for (std::size_t t = 0; t < terms.size(); ++t)
        s += (t ? " + " : "") + number_text(terms[t].c) + " " + x_name(terms[t].l);
    return s;
}

// Relative size below which a Jacobiator component counts as round-off.
constexpr double kJacobiTolerance = 1e-10;

// A sum of products c c' and the sum of their sizes, both held as a double
// times 2^exponent, so that neither overflows nor underflows however large or
// small the constants (products beyond 1e308 made the Jacobi test compare inf
// with inf, and pass). Their ratio, which the test reads, does not depend on
// the scale; each product is rounded once, as c c' would be.
struct ScaledProductSum {
    double value = 0.0, size = 0.0;
    int exponent = 0;
    bool empty = true;

    void add(double a, double b) {
        int ea = 0, eb = 0;
        const double product = std::frexp(a, &ea) * std::frexp(b, &eb);
        const int e = ea + eb;
        if (empty || e > exponent) {
            if (!empty) {
                value = std::ldexp(value, exponent - e);
                size = std::ldexp(size, exponent - e);
            }
            exponent = e;
            empty = false;
        }
        const double term = std::ldexp(product, e - exponent);
        value += term;
        size += std::fabs(term);
    }
    bool exceeds(double tolerance) const { return std::fabs(value) > tolerance * size; }
    std::string text() const {
        const double sum = std::ldexp(value, exponent);
        if (std::isfinite(sum) && (sum != 0.0 || value == 0.0)) return number_text(sum, 3);
        return number_text(value, 3) + " * 2^" + std::to_string(exponent);
    }
};

}  // namespace

// ---- structure constants ------------------------------------------------------

StructureConstants::StructureConstants(std::size_t dim, std::size_t nnz, const std::int32_t *i,
                                       const std::int32_t *j, const std::int32_t *k,
                                       const double *c)
    : dim_(dim) {
    if (dim == 0) fail(LPI_ERR_INVALID, "dim must be >= 1");
    if (dim > static_cast<std::size_t>(INT32_MAX) + 1)
        fail(LPI_ERR_INVALID, "dim = " + std::to_string(dim) +
                                  " exceeds 2^31 (indices are int32_t)");
    if (nnz > 0 && (!i || !j || !k || !c))
        fail(LPI_ERR_NULL, "an index or coefficient array is NULL while nnz = " +
                               std::to_string(nnz));

    // Canonical entries (a < b, l) -> (coefficient, entry that set it).
    std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>, std::pair<double, std::size_t>>
        canonical;
    const std::string range = " is outside 0.." + std::to_string(dim - 1);
    for (std::size_t e = 0; e < nnz; ++e) {
        const std::string entry = "entry " + std::to_string(e) + ": ";
        const std::int32_t idx[3] = {i[e], j[e], k[e]};
        const char *names[3] = {"i", "j", "k"};
        for (int q = 0; q < 3; ++q)
            if (idx[q] < 0 || static_cast<std::size_t>(idx[q]) >= dim)
                fail(LPI_ERR_INVALID, entry + names[q] + " = " + std::to_string(idx[q]) + range);
        if (!std::isfinite(c[e]))
            fail(LPI_ERR_NONFINITE, entry + "c = " + number_text(c[e]) + " is not finite");
        const auto a = static_cast<std::uint32_t>(idx[0]), b = static_cast<std::uint32_t>(idx[1]),
                   l = static_cast<std::uint32_t>(idx[2]);
        if (a == b) {
            if (c[e] != 0.0)
                fail(LPI_ERR_INVALID, entry + "{" + x_name(a) + ", " + x_name(a) + "} must be 0 "
                                      "(antisymmetry), got coefficient " + number_text(c[e]) +
                                      " on " + x_name(l));
            continue;
        }
        const auto key = std::make_tuple(std::min(a, b), std::max(a, b), l);
        const double value = a < b ? c[e] : -c[e];
        auto [it, inserted] = canonical.emplace(key, std::make_pair(value, e));
        if (!inserted && it->second.first != value) {
            const double implied = a < b ? it->second.first : -it->second.first;
            fail(LPI_ERR_INVALID,
                 entry + "gives {" + x_name(a) + ", " + x_name(b) + "} the coefficient " +
                     number_text(c[e]) + " on " + x_name(l) + ", but entry " +
                     std::to_string(it->second.second) + " implies " + number_text(implied) +
                     " (entries must agree, with {x_j, x_i} = -{x_i, x_j})");
        }
    }

    columns_.resize(dim);
    for (const auto &[key, entry] : canonical) {
        const auto [a, b, l] = key;
        const double value = entry.first;
        if (value == 0.0) continue;
        brackets_[static_cast<std::uint64_t>(a) * dim + b].push_back({l, value});
        brackets_[static_cast<std::uint64_t>(b) * dim + a].push_back({l, -value});
        columns_[b].push_back({a, l, value});   // c_ab^l, second index b
        columns_[a].push_back({b, l, -value});  // c_ba^l = -c_ab^l
    }
    check_jacobi();
}

const std::vector<StructureConstants::Output> &StructureConstants::bracket(std::uint32_t i,
                                                                           std::uint32_t j) const {
    auto it = brackets_.find(static_cast<std::uint64_t>(i) * dim_ + j);
    return it == brackets_.end() ? none_ : it->second;
}

void StructureConstants::check_jacobi() const {
    // Jac(p,q,r) = {{x_p,x_q},x_r} + {{x_q,x_r},x_p} + {{x_r,x_p},x_q}, linear
    // in x: component m is sum_l c_pq^l c_lr^m + c_qr^l c_lp^m + c_rp^l c_lq^m.
    // It vanishes unless one of its terms does not, and {{x_a,x_b},x_c} is
    // nonzero only along a path: a term c_ab^l x_l of a bracket with x_l and
    // x_c not commuting. So the triples are found from those paths (each
    // bracket's outputs' partners) and each is checked once: work that
    // follows the paths, where taking every partner of x_a and x_b took
    // R x| R^n (n brackets) through n^2 triples (37 s at n = 20000).
    std::vector<ScaledProductSum> sums(dim_);
    std::vector<std::uint32_t> touched;
    auto accumulate = [&](std::uint32_t a, std::uint32_t b, std::uint32_t d) {
        for (const Output &first : bracket(a, b))
            for (const Output &second : bracket(first.l, d)) {
                if (sums[second.l].empty) touched.push_back(second.l);
                sums[second.l].add(first.c, second.c);
            }
    };
    std::set<std::array<std::uint32_t, 3>> checked;
    for (const auto &[key, outputs] : brackets_) {
        const auto i = static_cast<std::uint32_t>(key / dim_), j = static_cast<std::uint32_t>(key % dim_);
        if (i > j) continue;
        for (const Output &o : outputs)
            for (const Term &partner : columns_[o.l]) {
                const std::uint32_t r = partner.i;
                if (r == i || r == j) continue;
                std::array<std::uint32_t, 3> t = {i, j, r};
                std::sort(t.begin(), t.end());
                if (!checked.insert(t).second) continue;
                accumulate(t[0], t[1], t[2]);
                accumulate(t[1], t[2], t[0]);
                accumulate(t[2], t[0], t[1]);
                for (std::uint32_t m : touched) {
                    if (sums[m].exceeds(kJacobiTolerance))
                        fail(LPI_ERR_INVALID,
                             "the structure constants violate the Jacobi identity at (i, j, k) = (" +
                                 std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " +
                                 std::to_string(t[2]) + "): {{x_i, x_j}, x_k} + {{x_j, x_k}, x_i} + "
                                 "{{x_k, x_i}, x_j} has coefficient " + sums[m].text() +
                                 " on " + x_name(m) + " (must be 0)");
                }
                for (std::uint32_t m : touched) sums[m] = ScaledProductSum{};
                touched.clear();
            }
    }
}

void StructureConstants::poisson_matrix(const double *x, double *J) const {
    std::fill(J, J + square_entries(dim_, "Poisson matrix"), 0.0);
    for (const auto &[key, outputs] : brackets_) {
        double s = 0.0;
        for (const Output &o : outputs) s += o.c * x[o.l];
        J[key] = s;  // key = i * dim + j is the row-major position
    }
}

void add_poisson_times(const StructureConstants &c, const std::uint32_t *sigma, std::size_t n,
                       const double *g, const double *x, double *rate) {
    for (std::size_t p = 0; p < n; ++p)
        for (const StructureConstants::Term &t : c.column(sigma[p]))
            rate[t.i] += t.c * g[p] * x[t.l];
}

// ---- abelian pieces -----------------------------------------------------------

namespace {

class AbelianPiece final : public Piece {
public:
    // `compiled`: the compiled flow of this index set, or nullptr for the
    // general plan.
    AbelianPiece(std::string label, const StructureConstants &constants,
                 std::vector<std::uint32_t> sigma, lpi_gradient_fn grad, lpi_energy_fn energy,
                 void *user, CompiledFlow compiled)
        : Piece(std::move(label)), constants_(constants), sigma_(std::move(sigma)), grad_(grad),
          energy_(energy), user_(user), x_sigma_(sigma_.size()), g_(sigma_.size()),
          compiled_(compiled), sorted_g_(sigma_.size()) {
        consecutive_ = true;
        for (std::size_t p = 1; p < sigma_.size(); ++p)
            consecutive_ = consecutive_ && sigma_[p] == sigma_[p - 1] + 1;
        if (!compiled_) {
            plan_blocks(flow_terms(constants_, sigma_));
            return;
        }
        // A compiled flow takes g in the order of the sorted index set.
        if (std::is_sorted(sigma_.begin(), sigma_.end())) return;
        for (std::uint32_t index : sigma_)
            rank_.push_back(static_cast<std::uint32_t>(std::count_if(
                sigma_.begin(), sigma_.end(), [&](std::uint32_t j) { return j < index; })));
    }

    void flow(double t, double *x) override {
        gradient(x);
        try {
            if (compiled_) {
                const double *g = g_.data();
                if (!rank_.empty()) {
                    for (std::size_t p = 0; p < rank_.size(); ++p) sorted_g_[rank_[p]] = g_[p];
                    g = sorted_g_.data();
                }
                const long failed = compiled_(g, t, x);
                if (failed >= 0) fail_flow_overflow(static_cast<std::size_t>(failed));
            } else if (exponentials_.size() == 1) {
                exponentials_.front().apply(g_.data(), t, x);
            } else if (factors_cancel(t)) {
                whole_->apply(g_.data(), t, x);
            } else {
                // x as it was when a block fails after others wrote theirs.
                std::copy(x, x + backup_.size(), backup_.begin());
                try {
                    for (SparseExponential &block : exponentials_) block.apply(g_.data(), t, x);
                } catch (...) {
                    std::copy(backup_.begin(), backup_.end(), x);
                    throw;
                }
            }
        } catch (const Error &e) {
            fail(e.status(), label() + ": " + e.what());
        }
    }

    double energy(const double *x) const override {
        double h = 0.0;
        const int rc = call_user([&] { return energy_(sigma_.size(), gather(x), &h, user_); },
                                 [&] { return "the energy callback of " + label(); });
        if (rc != 0)
            fail(LPI_ERR_CALLBACK, "the energy callback of " + label() + " returned " +
                                       std::to_string(rc));
        if (!std::isfinite(h))
            fail(LPI_ERR_CALLBACK, "the energy callback of " + label() + " gave a non-finite value");
        return h;
    }

    void add_vector_field(const double *x, double *rate) const override {
        gradient(x);
        add_poisson_times(constants_, sigma_.data(), sigma_.size(), g_.data(), x, rate);
    }

private:
    // A_il = sum_p c_{i sigma_p}^l g_p: its terms depend only on the
    // constants and sigma, so the exponential is planned once, at add_piece.
    static std::vector<SparseTerm> flow_terms(const StructureConstants &constants,
                                              const std::vector<std::uint32_t> &sigma) {
        std::vector<SparseTerm> terms;
        for (std::size_t p = 0; p < sigma.size(); ++p)
            for (const StructureConstants::Term &t : constants.column(sigma[p]))
                terms.push_back({t.i, t.l, static_cast<std::uint32_t>(p), t.c});
        return terms;
    }

    // The general plan. Where A, whole, would take the Pade path, its
    // exp(tA), rounded once a flow, is a constant of the flow wherever g is,
    // and the Casimirs drifted with one sign: e(3) with H = J1 + 0.7 P1 moved
    // |P|^2 by 187 standard errors over 1e5 random states at t = 0.7. So it
    // is applied as factors that commute, exp(s_0 C_0) exp(s_1 C_1) ... (the
    // C_p of an abelian set commute), each split into its blocks that share
    // no index (H = J1 rotates (J2, J3) and (P2, P3)): planes by shears,
    // nilpotent ones by their series, and Pade only for a block of three or
    // more that one parameter couples. The blocks share their cut of s_p, so
    // that all run for the very same times.
    //
    // The factors are exact only in exact arithmetic: where terms of several
    // parameters meet at one position and cancel (C_1 = -C_0, H = a (x0 +
    // x1): A = 0), each factor may grow what the next shrinks, and the
    // product lost everything (x scaled by 1e25 where the flow is the
    // identity). Such a flow is taken whole (factors_cancel).
    void plan_blocks(const std::vector<SparseTerm> &terms) {
        exponentials_.emplace_back(constants_.dim(), terms);
        if (exponentials_.front().path() != ExpmPath::Pade &&
            exponentials_.front().path() != ExpmPath::EllipticSeries)
            return;
        std::vector<std::vector<SparseTerm>> factors(sigma_.size()), blocks;
        for (const SparseTerm &term : terms) factors[term.parameter].push_back(term);
        for (const std::vector<SparseTerm> &factor : factors)
            for (std::vector<SparseTerm> &block : disjoint_blocks(factor)) blocks.push_back(std::move(block));
        if (blocks.size() < 2) return;
        whole_ = std::make_unique<SparseExponential>(std::move(exponentials_.front()));
        shared_positions_ = shared_positions(terms);
        exponentials_.clear();
        std::vector<int> shortening;
        for (std::vector<SparseTerm> &block : blocks) {
            exponentials_.emplace_back(constants_.dim(), std::move(block));
            const std::vector<int> &bits = exponentials_.back().shortening();
            if (shortening.size() < bits.size()) shortening.resize(bits.size(), 0);
            for (std::size_t p = 0; p < bits.size(); ++p) shortening[p] = std::max(shortening[p], bits[p]);
        }
        for (SparseExponential &block : exponentials_) block.widen_shortening(shortening);
        backup_.resize(constants_.dim());
    }

    // The terms of the positions that several parameters' terms share, each
    // position's run ended by a term with parameter kEndOfPosition.
    static constexpr std::uint32_t kEndOfPosition = UINT32_MAX;
    static std::vector<SparseTerm> shared_positions(std::vector<SparseTerm> terms) {
        std::sort(terms.begin(), terms.end(), [](const SparseTerm &a, const SparseTerm &b) {
            return std::tie(a.row, a.col, a.parameter) < std::tie(b.row, b.col, b.parameter);
        });
        std::vector<SparseTerm> shared;
        for (std::size_t first = 0, end; first < terms.size(); first = end) {
            end = first + 1;
            bool several = false;
            while (end < terms.size() && terms[end].row == terms[first].row && terms[end].col == terms[first].col)
                several = several || terms[end].parameter != terms[first].parameter, ++end;
            if (!several) continue;
            shared.insert(shared.end(), terms.begin() + first, terms.begin() + end);
            shared.push_back({0, 0, kEndOfPosition, 0.0});
        }
        return shared;
    }

    // Whether the factors' terms cancel at their shared positions by more
    // than ln 2 in all (sum of |c t g_p| less |sum of c t g_p|): then a factor
    // may grow by up to that much more than the flow does, and the product
    // lose as many digits.
    bool factors_cancel(double t) const {
        double cancelled = 0.0, sum = 0.0, magnitude = 0.0;
        for (const SparseTerm &term : shared_positions_) {
            if (term.parameter == kEndOfPosition) {
                cancelled += magnitude - std::fabs(sum);
                sum = magnitude = 0.0;
                continue;
            }
            const double entry = term.coefficient * (t * g_[term.parameter]);
            sum += entry;
            magnitude += std::fabs(entry);
        }
        return !(cancelled <= kLn2);
    }
    static constexpr double kLn2 = 0.6931471805599453;

    // x_sigma: where the index set is a run of consecutive indices (a single
    // one included), in place; else gathered into x_sigma_.
    const double *gather(const double *x) const {
        if (consecutive_) return x + sigma_[0];
        for (std::size_t p = 0; p < sigma_.size(); ++p) x_sigma_[p] = x[sigma_[p]];
        return x_sigma_.data();
    }

    void gradient(const double *x) const {
        // Zeros on entry, on every call (the energy's and the Casimirs'
        // outputs are zeroed too): a callback that writes only its nonzero
        // components, or adds into them, otherwise read the last call's.
        // Stored one by one through a volatile pointer: as a loop or
        // std::fill the compiler calls memset, which cost a flow 5 ns.
        volatile double *zeroed = g_.data();
        for (std::size_t p = 0; p < g_.size(); ++p) zeroed[p] = 0.0;
        const int rc = call_user([&] { return grad_(sigma_.size(), gather(x), g_.data(), user_); },
                                 [&] { return "the gradient callback of " + label(); });
        bool finite = true;
        for (std::size_t p = 0; p < g_.size(); ++p) finite &= std::isfinite(g_[p]);
        if (rc != 0 || !finite) fail_gradient(rc);
    }

    // Out of line, so that the messages cost the flows nothing.
    [[noreturn, gnu::noinline, gnu::cold]] void fail_gradient(int rc) const {
        if (rc != 0)
            fail(LPI_ERR_CALLBACK, "the gradient callback of " + label() + " returned " +
                                       std::to_string(rc));
        std::size_t p = 0;
        while (std::isfinite(g_[p])) ++p;
        fail(LPI_ERR_CALLBACK, "the gradient callback of " + label() +
                                   " gave a non-finite component " + std::to_string(p));
    }

    const StructureConstants &constants_;
    std::vector<std::uint32_t> sigma_;
    lpi_gradient_fn grad_;
    lpi_energy_fn energy_;
    void *user_;
    bool consecutive_ = false;  // sigma_ = {s, s + 1, ...}: x_sigma is read in place
    mutable std::vector<double> x_sigma_, g_;
    CompiledFlow compiled_;
    std::vector<std::uint32_t> rank_;  // compiled, sigma_ not sorted: sigma_[p]'s place in order
    std::vector<double> sorted_g_;
    std::vector<SparseExponential> exponentials_;  // the general plan, without one: its blocks
    std::unique_ptr<SparseExponential> whole_;      // with blocks: A whole, where they cancel
    std::vector<SparseTerm> shared_positions_;      // with blocks: see shared_positions
    std::vector<double> backup_;                   // x before the blocks, where there are several
};

}  // namespace

// ---- the model ------------------------------------------------------------------

GenericModel::GenericModel(std::unique_ptr<StructureConstants> constants, const char *kind)
    : kind_(kind), constants_(std::move(constants)) {}

std::vector<double> GenericModel::checkpoint_parameters() const {
    // Callbacks are code plus a user pointer: nothing in a file can bring
    // them back, and a system restored without them would not be the same.
    fail(LPI_ERR_UNSUPPORTED, std::string("a ") + kind_ + " system cannot be checkpointed: "
                              "its Hamiltonian pieces and Casimirs are user callbacks, which "
                              "cannot be saved (save lpi_get_state and lpi_time instead, and "
                              "rebuild the system)");
}

void GenericModel::flow(std::size_t piece, double t, double *state) {
    pieces_[piece]->flow(t, state);
}

double GenericModel::energy(const double *state) const {
    double h = 0.0;
    for (const auto &p : pieces_) h += p->energy(state);
    return h;
}

void GenericModel::casimirs(const double *state, double *out) const {
    for (std::size_t q = 0; q < casimirs_.size(); ++q) {
        double value = 0.0;
        const int rc = call_user([&] { return casimirs_[q].fn(dim(), state, &value, casimirs_[q].user); },
                                 [&] { return "the callback of Casimir " + std::to_string(q); });
        if (rc != 0)
            fail(LPI_ERR_CALLBACK, "the callback of Casimir " + std::to_string(q) + " returned " +
                                       std::to_string(rc));
        if (!std::isfinite(value) && !casimirs_[q].builtin.empty())
            fail(LPI_ERR_OVERFLOW, "Casimir " + std::to_string(q) + " (" + casimirs_[q].builtin +
                                       ") is not representable at this state: it overflows a "
                                       "double");
        if (!std::isfinite(value))
            fail(LPI_ERR_CALLBACK, "the callback of Casimir " + std::to_string(q) +
                                       " gave a non-finite value");
        out[q] = value;
    }
}

void GenericModel::vector_field(const double *state, double *rate) const {
    std::fill(rate, rate + dim(), 0.0);
    for (const auto &p : pieces_) p->add_vector_field(state, rate);
}

void GenericModel::add_piece(std::size_t n, const std::int32_t *indices, lpi_gradient_fn grad,
                             lpi_energy_fn energy, void *user) {
    if (!grad) fail(LPI_ERR_NULL, "the gradient callback is NULL");
    if (!energy) fail(LPI_ERR_NULL, "the energy callback is NULL");
    if (n == 0) fail(LPI_ERR_INVALID, "a piece needs at least one index (n = 0)");
    if (!indices) fail(LPI_ERR_NULL, "indices is NULL");
    const std::size_t d = dim();
    if (n > d)
        fail(LPI_ERR_INVALID, "n = " + std::to_string(n) + " indices exceed dim = " +
                                  std::to_string(d) + " (indices must be distinct)");
    std::vector<std::uint32_t> sigma(n);
    std::unordered_map<std::uint32_t, std::size_t> seen;
    for (std::size_t p = 0; p < n; ++p) {
        if (indices[p] < 0 || static_cast<std::size_t>(indices[p]) >= d)
            fail(LPI_ERR_INVALID, "indices[" + std::to_string(p) + "] = " +
                                      std::to_string(indices[p]) + " is outside 0.." +
                                      std::to_string(d - 1));
        sigma[p] = static_cast<std::uint32_t>(indices[p]);
        auto [it, inserted] = seen.emplace(sigma[p], p);
        if (!inserted)
            fail(LPI_ERR_INVALID, "indices[" + std::to_string(it->second) + "] and indices[" +
                                      std::to_string(p) + "] are both " +
                                      std::to_string(sigma[p]) + " (indices must be distinct)");
    }
    // The first pair (p, q), p < q, that does not commute, found through
    // each index's partners (the brackets it has) rather than all n^2 pairs
    // (25 s for 160000 indices of an abelian algebra).
    for (std::size_t p = 0; p < n; ++p) {
        std::size_t first = n;
        for (const StructureConstants::Term &t : constants_->column(sigma[p])) {
            const auto it = seen.find(t.i);
            if (it != seen.end() && it->second > p) first = std::min(first, it->second);
        }
        if (first == n) continue;
        const std::uint32_t a = sigma[p], b = sigma[first];
        fail(LPI_ERR_NOT_ABELIAN, "the index set is not abelian: indices " + std::to_string(a) + " and " +
                                      std::to_string(b) + " do not commute, " +
                                      bracket_text(a, b, constants_->bracket(a, b)));
    }
    std::string label = next_piece_name() + " (indices {";
    for (std::size_t p = 0; p < n; ++p) label += (p ? ", " : "") + std::to_string(sigma[p]);
    label += "})";
    CompiledFlow compiled = nullptr;
    if (compiled_flows_ && d <= 8 * sizeof(unsigned)) {
        unsigned mask = 0;
        for (std::uint32_t j : sigma) mask |= 1u << j;
        compiled = compiled_flows_(mask);
    }
    pieces_.push_back(std::make_unique<AbelianPiece>(std::move(label), *constants_,
                                                     std::move(sigma), grad, energy, user, compiled));
}

void GenericModel::add_casimir(lpi_casimir_fn fn, void *user) {
    if (!fn) fail(LPI_ERR_NULL, "the Casimir callback is NULL");
    casimirs_.push_back({fn, user, std::string()});
}

void GenericModel::add_builtin_casimir(lpi_casimir_fn fn, const std::string &name) {
    casimirs_.push_back({fn, nullptr, name});
}

std::vector<double> singular_values(std::size_t n, std::vector<double> M) {
    // One-sided Jacobi (Hestenes 1958): rotate pairs of columns until they are
    // mutually orthogonal; the column norms are then the singular values.
    std::vector<double> col(square_entries(n, "matrix"));  // column-major copy
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t c = 0; c < n; ++c) col[c * n + r] = M[r * n + c];
    for (int sweep = 0; sweep < 100; ++sweep) {
        bool rotated = false;
        for (std::size_t p = 0; p + 1 < n; ++p)
            for (std::size_t q = p + 1; q < n; ++q) {
                double *a = &col[p * n], *b = &col[q * n];
                double alpha = 0.0, beta = 0.0, gamma = 0.0;
                for (std::size_t r = 0; r < n; ++r) {
                    alpha += a[r] * a[r];
                    beta += b[r] * b[r];
                    gamma += a[r] * b[r];
                }
                if (gamma == 0.0 || std::fabs(gamma) <= DBL_EPSILON * std::sqrt(alpha * beta))
                    continue;
                rotated = true;
                const double zeta = (beta - alpha) / (2.0 * gamma);
                const double t = std::copysign(1.0, zeta) / (std::fabs(zeta) + std::hypot(1.0, zeta));
                const double cs = 1.0 / std::hypot(1.0, t), sn = cs * t;
                for (std::size_t r = 0; r < n; ++r) {
                    const double u = a[r], v = b[r];
                    a[r] = cs * u - sn * v;
                    b[r] = sn * u + cs * v;
                }
            }
        if (!rotated) break;
    }
    std::vector<double> sigma(n);
    for (std::size_t c = 0; c < n; ++c) {
        double s = 0.0;
        for (std::size_t r = 0; r < n; ++r) s += col[c * n + r] * col[c * n + r];
        sigma[c] = std::sqrt(s);
    }
    return sigma;
}

std::size_t GenericModel::poisson_rank(const double *x) const {
    // J is linear in x and the rank test is relative, so both are scaled to
    // a largest entry of 1: no product or sum of squares below overflows.
    const std::size_t n = dim();
    double x_max = 0.0;
    for (std::size_t i = 0; i < n; ++i) x_max = std::max(x_max, std::fabs(x[i]));
    if (x_max == 0.0) return 0;
    std::vector<double> scaled(x, x + n);
    for (double &v : scaled) v /= x_max;
    std::vector<double> J(square_entries(n, "Poisson matrix J(x)"));
    constants_->poisson_matrix(scaled.data(), J.data());
    double J_max = 0.0;
    for (std::size_t e = 0; e < J.size(); ++e) {
        if (!std::isfinite(J[e]))
            fail(LPI_ERR_OVERFLOW, "J(x) entry (" + std::to_string(e / n) + ", " +
                                       std::to_string(e % n) + ") overflows a double even for "
                                       "x scaled to max |x_i| = 1 (the structure constants are "
                                       "too large)");
        J_max = std::max(J_max, std::fabs(J[e]));
    }
    if (J_max == 0.0) return 0;
    for (double &v : J) v /= J_max;
    const std::vector<double> sigma = singular_values(n, std::move(J));
    const double largest = sigma.empty() ? 0.0 : *std::max_element(sigma.begin(), sigma.end());
    const double tolerance = static_cast<double>(n) * DBL_EPSILON * largest;
    std::size_t rank = 0;
    for (double s : sigma)
        if (s > tolerance) ++rank;
    return rank;
}

GenericModel &generic_model_of(System &system) {
    return const_cast<GenericModel &>(generic_model_of(static_cast<const System &>(system)));
}

const GenericModel &generic_model_of(const System &system) {
    const auto *model = dynamic_cast<const GenericModel *>(&system.model());
    if (!model)
        fail(LPI_ERR_UNSUPPORTED, std::string("a ") + system.model().kind() +
                                      " system has no user pieces or structure constants "
                                      "(create it with lpi_generic_create or "
                                      "lpi_moments_create)");
    return *model;
}

void commit_new_piece(System &system, GenericModel &model) {
    try {
        system.rebuild_integrator();
    } catch (...) {
        model.remove_last_piece();
        throw;
    }
}

void add_piece(System &system, std::size_t n, const std::int32_t *indices, lpi_gradient_fn grad,
               lpi_energy_fn energy, void *user) {
    GenericModel &model = generic_model_of(system);
    model.add_piece(n, indices, grad, energy, user);
    commit_new_piece(system, model);
}

std::unique_ptr<GenericModel> make_generic(std::size_t dim, std::size_t nnz, const std::int32_t *i,
                                           const std::int32_t *j, const std::int32_t *k,
                                           const double *c) {
    return std::make_unique<GenericModel>(std::make_unique<StructureConstants>(dim, nnz, i, j, k, c));
}

}  // namespace lpi
