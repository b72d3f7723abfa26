// How a System advances its state: an Integrator is built from a Method for a
// Model by the method's own factory. Splitting methods compose the model's
// exact piece flows; the baselines (src/baselines) integrate otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>

#include "methods.hpp"
#include "model.hpp"

namespace lpi {

// Watches a run of steps: observe(k) is called after every `every`-th step
// (k = steps completed in the run), with the state holding exactly what a run
// of k steps leaves; true from it stops the run there.
struct StepObserver {
    std::int64_t every = 0;  // 0: nobody watches
    std::function<bool(std::int64_t)> observe;
};

// How a run ended and the steps whose result the state holds (NonFinite: the
// step after which the state was found non-finite; the caller restores it).
struct RunOutcome {
    enum End { Done, Stopped, NonFinite } end = Done;
    std::int64_t steps = 0;
};

// The steps being computed, first..last (1-based in the run): what a failure
// thrown from inside a step is reported against.
struct StepsInProgress {
    std::int64_t first = 0, last = 0;
};

class Integrator {
public:
    virtual ~Integrator() = default;
    // Advances n >= 1 steps of size dt in place: steps progress.first ..
    // progress.first + n - 1 of the call, progress narrowed to the step being
    // computed (what a failure thrown from it names). Returns 0 when the
    // state stayed finite (checked every few steps and at the end), else as
    // soon as it is found non-finite, the steps of these n done then; the
    // caller restores its copy.
    virtual std::int64_t advance(Model &model, double *state, double dt, std::int64_t n,
                                 StepsInProgress &progress) = 0;
    // Advances n >= 1 steps with an optional observer. The default runs
    // advance() in chunks of observer.every steps, which is exact for methods
    // whose steps share nothing; the splitting integrator overrides it to
    // keep merging flows across the observed steps, and the sine-Euler
    // matrix methods to keep their matrix form.
    virtual RunOutcome run(Model &model, double *state, double dt, std::int64_t n,
                           const StepObserver &observer, StepsInProgress &progress);
    // Allocates what run() will, before it runs: on a model spread over
    // processes, nothing may fail on one process alone between two flows
    // (the others would wait in the next one's exchange).
    virtual void prepare_run(const Model &model, const StepObserver &observer) {
        (void)model, (void)observer;
    }
    // Piece flows (or vector-field evaluations) per step in a long run.
    virtual std::size_t evaluations_per_step() const = 0;
    // The largest |multiple of dt| that one flow or stage of a step takes.
    virtual double largest_step_fraction() const { return 1.0; }
    // What a run measures besides the state: the average iterations behind
    // evaluations_per_step of the implicit methods. System puts it back when
    // a call fails, so that a failed call leaves the handle as it was.
    virtual double average_iterations() const { return 0.0; }
    virtual void restore_average_iterations(double) {}

protected:
    // advance() for an integrator that overrides run(): its steps counted
    // from progress.first.
    std::int64_t advance_through_run(Model &model, double *state, double dt, std::int64_t n,
                                     StepsInProgress &progress);
};

// How implicit methods solve their equations (fixed-point iteration).
struct ImplicitSettings {
    double tolerance = 1e-13;  // on max|increment| relative to max|x|
    int max_iterations = 100;
};

// The method's integrator for model (its row's factory).
std::unique_ptr<Integrator> make_integrator(const Method &method, const Model &model,
                                            const ImplicitSettings &implicit = {});

// The factory of every splitting row: composes the model's piece flows in
// the method's flow program (FlowProgram).
std::unique_ptr<Integrator> make_splitting_integrator(const Method &method, const Model &model,
                                                      const ImplicitSettings &implicit);

bool all_finite(const double *x, std::size_t n);

// How often long runs look for a non-finite state, in steps.
constexpr std::int64_t kFiniteCheckInterval = 256;

// Runs step(s) for s = 0 .. n-1, steps progress.first + s of the call,
// progress naming the one being computed, and asks finite() every
// kFiniteCheckInterval steps and at the end: advance()'s result, 0 or the
// steps done when it first answered false (the loop of every baseline's
// advance()).
template <class Step, class Finite>
std::int64_t run_checked_steps(std::int64_t n, StepsInProgress &progress, Step &&step,
                               Finite &&finite) {
    const std::int64_t first = progress.first;
    for (std::int64_t s = 0; s < n; ++s) {
        progress = {first + s, first + s};
        step(s);
        if ((s + 1) % kFiniteCheckInterval == 0 && !finite()) return s + 1;
    }
    return finite() ? 0 : n;
}

}  // namespace lpi
