// The method registry: every integration method the library offers, chosen by
// name. Each row carries the factory of its integrator. The splitting methods
// are rows of this file, described as data (a sequence of piece flows or a
// symmetric composition of leapfrog): adding a composition is adding a row.
// The baselines (src/baselines) bring their own rows and factories, listed
// once in src/registry.cpp.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace lpi {

class Integrator;
class Model;
struct ImplicitSettings;
struct Method;

// Builds the integrator of `method` for `model`. A method defined for some
// kinds of system only refuses the others with LPI_ERR_UNSUPPORTED, thrown
// as MethodNotApplicable (refuse_system).
using IntegratorFactory = std::unique_ptr<Integrator> (*)(const Method &method,
                                                          const Model &model,
                                                          const ImplicitSettings &implicit);

enum class MethodKind {
    Sequence,             // each piece once per step, in order (Lie-Trotter)
    SequenceAdjoint,      // each piece once per step, in reverse order
    SymmetricComposition, // leapfrog stages with weights gammas (sum 1, symmetric)
    Baseline,             // no piece flows: its factory integrates otherwise
};

struct Method {
    std::string name;
    int order = 0;
    int stages = 0;  // leapfrog stages per step (1 for sequences and baselines)
    std::string source;  // the publication the method comes from
    bool poisson = true;  // preserves the Poisson structure and every Casimir
    MethodKind kind = MethodKind::Sequence;
    std::vector<double> gammas;  // SymmetricComposition only
    IntegratorFactory make_integrator = nullptr;
};

// Refuses a system the method can never apply to: LPI_ERR_UNSUPPORTED,
// thrown as MethodNotApplicable (error.hpp).
[[noreturn]] void refuse_system(const std::string &message);

// True for the methods that compose exact piece flows.
bool is_splitting(const Method &method);

// A row of a method that is not a Poisson map and takes one stage per step.
Method baseline_method(std::string name, int order, std::string source, IntegratorFactory make);

// The registered methods, in the order lpi_method_name(i) lists them: the
// splittings of this file, then the rows of add_registered_methods.
const std::vector<Method> &method_table();

// Appends the rows registered from outside the core (defined in
// src/registry.cpp). Called once, when the table is first built.
void add_registered_methods(std::vector<Method> &table);

// Looks a method up by name or alias; also builds the recursive compositions
// "triple-jump-<p>" and "suzuki-<p>" for even p in 2..kMaxRecursiveOrder.
// Throws lpi::Error(LPI_ERR_INVALID) naming the known methods when there is none.
Method find_method(const std::string &name);

// Highest order p accepted in "triple-jump-<p>" / "suzuki-<p>" (suzuki-16
// already has 5^7 = 78125 stages).
constexpr int kMaxRecursiveOrder = 16;

// Weights of the recursive compositions of leapfrog for even order >= 2:
// Yoshida's triple jump (3^(p/2-1) stages) and Suzuki's fractal
// (5^(p/2-1) stages). Order 2 is leapfrog itself.
std::vector<double> triple_jump_gammas(int order);
std::vector<double> suzuki_gammas(int order);

// A user-supplied symmetric composition of leapfrog, named "custom" (order
// reported as 2, the least it has). Requires n >= 1 finite weights summing to
// 1 and symmetric, both to a relative 1e-14; mirrored pairs are replaced by
// their mean so the stored composition is exactly symmetric. Throws
// lpi::Error naming the offending weight otherwise.
Method custom_composition(const double *gammas, std::size_t n);
// LPI_ERR_INVALID for a weight count custom_composition refuses before
// reading the weights (0, or more than an int counts).
void require_composition_count(std::size_t n);

// One exact piece flow of a splitting step: piece `piece` for weight * dt.
struct Flow {
    std::size_t piece;
    double weight;
};

// The flows of one step for `pieces` pieces, with adjacent flows of the same
// piece merged (first-same-as-last at the seams between leapfrog stages).
// Held as its parts, not written out: suzuki-16 has 78125 stages, so a
// splitting of 102 pieces (sine-Euler at N = 101) makes 15.8 million flows
// a step, 250 MB written out; the parts take the stages and the pieces.
class FlowProgram {
public:
    FlowProgram(const Method &method, std::size_t pieces);

    std::size_t size() const { return gammas_.size() * stage_.size() + seams_.size(); }
    // Whether the step begins and ends with a flow of the same piece (every
    // symmetric composition of two or more pieces): the first and the last.
    bool has_seams() const { return !seams_.empty(); }
    Flow first() const { return {0, seams_.front()}; }
    Flow last() const { return {0, seams_.back()}; }

    // visit(flow) for the flows of a step in order, but the first and the
    // last where has_seams(): a run merges those across steps.
    template <class Visit>
    void for_each_between_seams(Visit &&visit) const {
        for (std::size_t i = 0; i < gammas_.size(); ++i) {
            if (i > 0 && has_seams()) visit(Flow{0, seams_[i]});
            for (const Flow &f : stage_) visit(Flow{f.piece, f.weight * gammas_[i]});
        }
    }
    // Every flow of a step, in order.
    std::vector<Flow> written_out() const;
    // The largest |weight| of a flow, a merged seam included.
    double largest_weight() const;

private:
    std::vector<Flow> stage_;     // a stage's flows between its seams, weights per unit of its gamma
    std::vector<double> gammas_;  // each stage's weight
    std::vector<double> seams_;   // piece 0's flows before, between and after the stages, or none
};

}  // namespace lpi
