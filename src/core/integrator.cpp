#include "integrator.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "error.hpp"

namespace lpi {

bool all_finite(const double *x, std::size_t n) {
    // Summing 0*x keeps the loop branch-free: any NaN or Inf makes it NaN.
    double probe = 0.0;
    for (std::size_t i = 0; i < n; ++i) probe += 0.0 * x[i];
    return probe == 0.0;
}

RunOutcome Integrator::run(Model &model, double *state, double dt, std::int64_t n,
                           const StepObserver &observer, StepsInProgress &progress) {
    const std::int64_t chunk = observer.every > 0 ? observer.every : n;
    std::int64_t done = 0;
    while (done < n) {
        const std::int64_t count = chunk < n - done ? chunk : n - done;
        progress = {done + 1, done + count};
        if (const std::int64_t found = advance(model, state, dt, count, progress))
            return {RunOutcome::NonFinite, done + found};
        done += count;
        if (observer.every > 0 && done % observer.every == 0 && observer.observe(done))
            return {RunOutcome::Stopped, done};
    }
    return {RunOutcome::Done, n};
}

std::int64_t Integrator::advance_through_run(Model &model, double *state, double dt, std::int64_t n,
                                             StepsInProgress &progress) {
    const std::int64_t first = progress.first;
    const RunOutcome outcome = run(model, state, dt, n, StepObserver{}, progress);
    progress = {first - 1 + progress.first, first - 1 + progress.last};
    return outcome.end == RunOutcome::NonFinite ? outcome.steps : 0;
}

namespace {

// Composes exact piece flows. When a step begins and ends with the same piece
// (every symmetric composition does), the last flow of one step and the first
// of the next are merged into one: n steps then cost n*(L-1)+1 flows.
class SplittingIntegrator final : public Integrator {
public:
    explicit SplittingIntegrator(FlowProgram program)
        : program_(std::move(program)), merge_seam_(program_.has_seams()),
          largest_(program_.largest_weight()) {}

    std::int64_t advance(Model &model, double *state, double dt, std::int64_t n,
                         StepsInProgress &progress) override {
        return advance_through_run(model, state, dt, n, progress);
    }

    // An observed step ends with its own last flow, on a copy kept aside: the
    // observer sees exactly the state of a run of that many steps, and the
    // run then goes on from the copy with the merged flow, so observing
    // changes no bit of the trajectory.
    RunOutcome run(Model &model, double *state, double dt, std::int64_t n,
                   const StepObserver &observer, StepsInProgress &progress) override {
        const std::size_t size = model.state_size();
        const Flow first = merge_seam_ ? program_.first() : Flow{};
        const Flow last = merge_seam_ ? program_.last() : Flow{};
        const double merged = last.weight + first.weight;
        const auto flow = [&](const Flow &f) { model.flow(f.piece, f.weight * dt, state); };
        // The next observed step, counted rather than found by a division
        // per step (one division costs as much as a small model's flow).
        std::int64_t next_observed = observer.every > 0 ? observer.every : INT64_MAX;
        progress = {1, 1};  // the leading flow is step 1's: a failure there names it
        if (merge_seam_) flow(first);
        for (std::int64_t step = 1; step <= n; ++step) {
            progress = {step, step};
            program_.for_each_between_seams(flow);
            const bool observed = step == next_observed;
            if (observed)
                next_observed = observer.every <= INT64_MAX - step ? step + observer.every : INT64_MAX;
            const bool final = step == n;
            if (merge_seam_) {
                if (observed && !final) {
                    model.settle(state);  // the copy must hold what the flows may keep elsewhere
                    pending_.assign(state, state + size);
                }
                if (observed || final)
                    flow(last);
                else
                    flow({last.piece, merged});
            }
            const bool checked = observed || final || step % kFiniteCheckInterval == 0;
            if (checked) model.settle(state);
            if (checked && !model.finite(state)) return {RunOutcome::NonFinite, step};
            if (observed && observer.observe(step)) return {RunOutcome::Stopped, step};
            if (merge_seam_ && observed && !final) {
                std::copy(pending_.begin(), pending_.end(), state);
                flow({last.piece, merged});
            }
        }
        return {RunOutcome::Done, n};
    }

    // The copy an observed step keeps of the state before its last flow.
    void prepare_run(const Model &model, const StepObserver &observer) override {
        if (merge_seam_ && observer.every > 0) pending_.reserve(model.state_size());
    }

    std::size_t evaluations_per_step() const override {
        return merge_seam_ ? program_.size() - 1 : program_.size();
    }
    double largest_step_fraction() const override { return largest_; }

private:
    FlowProgram program_;
    bool merge_seam_;
    double largest_;
    std::vector<double> pending_;  // an observed step's state before its last flow
};

}  // namespace

std::unique_ptr<Integrator> make_splitting_integrator(const Method &method, const Model &model,
                                                      const ImplicitSettings &) {
    return std::make_unique<SplittingIntegrator>(FlowProgram(method, model.piece_count()));
}

std::unique_ptr<Integrator> make_integrator(const Method &method, const Model &model,
                                            const ImplicitSettings &implicit) {
    if (!method.make_integrator)
        fail(LPI_ERR_INTERNAL, "method '" + method.name + "' has no integrator factory");
    // A baseline works on the whole state; a distributed model holds a part.
    if (model.distributed() && method.kind == MethodKind::Baseline)
        fail(LPI_ERR_UNSUPPORTED, "method '" + method.name + "' is a baseline, which needs the whole " +
                                      "state on one process; a " + model.kind() +
                                      " system spread over processes steps by splitting methods");
    return method.make_integrator(method, model, implicit);
}

}  // namespace lpi
