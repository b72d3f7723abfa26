#include "integrator.hpp"

#include <cmath>
#include <vector>

#include "../reference/implicit_midpoint.hpp"
#include "../reference/runge_kutta4.hpp"
#include "../reference/sine_euler_matrix_methods.hpp"
#include "error.hpp"

namespace lpi {

bool all_finite(const double *x, std::size_t n) {
    // Summing 0*x keeps the loop branch-free: any NaN or Inf makes it NaN.
    double probe = 0.0;
    for (std::size_t i = 0; i < n; ++i) probe += 0.0 * x[i];
    return probe == 0.0;
}

namespace {

// Composes exact piece flows. When a step begins and ends with the same piece
// (every symmetric composition does), the last flow of one step and the first
// of the next are merged into one: n steps then cost n*(L-1)+1 flows.
class SplittingIntegrator final : public Integrator {
public:
    explicit SplittingIntegrator(std::vector<Flow> program) : program_(std::move(program)) {
        merge_seam_ = program_.size() > 1 && program_.front().piece == program_.back().piece;
    }

    bool advance(Model &model, double *state, double dt, std::int64_t n) override {
        const std::size_t size = model.state_size();
        const std::size_t last = program_.size() - 1;
        if (!merge_seam_) {
            for (std::int64_t step = 0; step < n; ++step) {
                for (const Flow &f : program_) model.flow(f.piece, f.weight * dt, state);
                if ((step + 1) % kFiniteCheckInterval == 0 && !all_finite(state, size))
                    return false;
            }
            return all_finite(state, size);
        }
        model.flow(program_[0].piece, program_[0].weight * dt, state);
        for (std::int64_t step = 0; step < n; ++step) {
            for (std::size_t i = 1; i < last; ++i)
                model.flow(program_[i].piece, program_[i].weight * dt, state);
            const double w = program_[last].weight + (step + 1 < n ? program_[0].weight : 0.0);
            model.flow(program_[last].piece, w * dt, state);
            if ((step + 1) % kFiniteCheckInterval == 0 && !all_finite(state, size)) return false;
        }
        return all_finite(state, size);
    }

    std::size_t evaluations_per_step() const override {
        return merge_seam_ ? program_.size() - 1 : program_.size();
    }

private:
    std::vector<Flow> program_;
    bool merge_seam_ = false;
};

}  // namespace

std::unique_ptr<Integrator> make_integrator(const Method &method, const Model &model,
                                            const ImplicitSettings &implicit) {
    switch (method.kind) {
    case MethodKind::Sequence:
    case MethodKind::SequenceAdjoint:
    case MethodKind::SymmetricComposition:
        return std::make_unique<SplittingIntegrator>(
            build_flow_program(method, model.piece_count()));
    case MethodKind::RungeKutta4:
        return std::make_unique<RungeKutta4>(model.state_size());
    case MethodKind::ImplicitMidpoint:
        return std::make_unique<ImplicitMidpoint>(model.state_size(), implicit);
    case MethodKind::IsospectralMidpoint:
    case MethodKind::RungeKutta4Matrix:
    case MethodKind::DirectEq5:
        return make_sine_euler_matrix_integrator(method, model, implicit);
    }
    fail(LPI_ERR_INTERNAL, "unhandled method kind for '" + method.name + "'");
}

}  // namespace lpi
