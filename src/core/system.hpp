// A System owns a Model (algebra + split), a Method and its Integrator, the
// state and the time. Every mutating operation either succeeds or throws
// lpi::Error with the state exactly as it was.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "integrator.hpp"
#include "methods.hpp"
#include "model.hpp"

namespace lpi {

class System {
public:
    explicit System(std::unique_ptr<Model> model);

    Model &model() { return *model_; }
    const Model &model() const { return *model_; }
    const Method &method() const { return method_; }

    void set_method(const std::string &name);
    // A user-supplied symmetric composition of leapfrog (see custom_composition).
    void set_composition(const double *gammas, std::size_t n);
    void set_implicit_settings(const ImplicitSettings &settings);
    const ImplicitSettings &implicit_settings() const { return implicit_; }
    // Piece flows (RK4: vector-field evaluations) per step in a long run.
    std::size_t flows_per_step() const { return integrator_->evaluations_per_step(); }
    void set_split(const std::string &name);
    // The split in use, stored here so that its name outlives the call.
    const std::string &split() const { return split_; }
    // Bounded by max_threads(); the model may refuse n > 1, and a count whose
    // threads the system refuses to start fails with LPI_ERR_NO_MEMORY.
    void set_threads(int n);
    int threads() const { return threads_; }
    // Readies the calling thread for the model's parallel regions (threads.hpp):
    // every entry that runs them calls it first.
    void prepare_threads() const;

    std::size_t dim() const { return model_->dim(); }
    void set_state(const double *x, std::size_t n);  // also resets time to 0
    void get_state(double *x, std::size_t n) const;
    const std::vector<double> &working_state() const { return state_; }
    // Restores a working state and time exactly (checkpoints): the length
    // must be the model's state_size() and every value finite.
    void restore_working_state(const std::vector<double> &state, double time, double time_carry = 0.0);

    // Called by step() after every `every`-th step with the steps completed
    // in the call and the time; true stops the call there.
    using Observer = std::function<bool(std::int64_t step, double time)>;
    void set_observer(std::int64_t every, Observer observer);  // empty observer: none

    // Advances nsteps steps; false when the observer stopped it early (the
    // state and time are then those of that many steps).
    bool step(double dt, std::int64_t nsteps);
    double time() const { return time_.value; }
    double time_carry() const { return time_.carry; }  // time() + it: the time, exactly

    // Outputs computed from the (finite) state: a value that is not finite
    // overflowed, and throws LPI_ERR_OVERFLOW naming it.
    double energy() const;
    std::size_t casimir_count() const { return model_->casimir_count(); }
    void casimirs(double *out, std::size_t n) const;

    // Rebuilds the integrator after the model's pieces changed (generic
    // systems gain pieces after creation); throws, unchanged, on failure.
    void rebuild_integrator();

private:
    std::unique_ptr<Model> model_;
    Method method_;
    std::unique_ptr<Integrator> integrator_;
    std::vector<double> state_;
    std::vector<double> saved_;  // the state before the step in progress
    // The time as a double-double, value + carry, each call adding dt times
    // its steps exactly but for u^2 t: time reported after many short calls
    // (a program stepping one step at a time) is then the sum of their
    // spans rounded once, not a rounding a call (0.1 a call: 1.3e-11
    // relative after 10^6 calls).
    struct Time {
        double value = 0.0, carry = 0.0;
        Time advanced(double dt, std::int64_t steps) const;
    };
    Time time_;
    ImplicitSettings implicit_;
    std::string split_;  // the model's split(), as of the last change
    int threads_ = 1;
    std::int64_t observe_every_ = 0;
    Observer observer_;
};

// Throws LPI_ERR_SIZE unless given == expected, naming what was expected.
void require_length(const char *what, std::size_t given, std::size_t expected);

// Throws LPI_ERR_OVERFLOW unless every value is finite: outputs computed from
// a finite state that are not finite have overflowed. `what(i)` names value i.
void require_no_overflow(const double *values, std::size_t n,
                         const std::function<std::string(std::size_t)> &what);

}  // namespace lpi
