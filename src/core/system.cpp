#include "system.hpp"

#include <algorithm>
#include <cmath>

#include "error.hpp"
#include "exact_sums.hpp"
#include "text.hpp"
#include "threads.hpp"

namespace lpi {

namespace {

// "in step 7 of this call (t = 0.6 .. 0.7)" or "in steps 1 .. 256 ..."
std::string steps_text(const StepsInProgress &p, double start, double dt) {
    const double from = start + dt * static_cast<double>(p.first - 1);
    const double to = start + dt * static_cast<double>(p.last);
    const std::string steps = p.first == p.last
                                  ? "step " + std::to_string(p.first)
                                  : "steps " + std::to_string(p.first) + " .. " +
                                        std::to_string(p.last);
    return "in " + steps + " of this call (t = " + number_text(from, 6) + " .. " +
           number_text(to, 6) + ")";
}

}  // namespace

void require_no_overflow(const double *values, std::size_t n,
                         const std::function<std::string(std::size_t)> &what) {
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(values[i]))
            fail(LPI_ERR_OVERFLOW, what(i) + " overflows a double");
}

void require_length(const char *what, std::size_t given, std::size_t expected) {
    if (given != expected)
        fail(LPI_ERR_SIZE, std::string(what) + " has length " + std::to_string(given) +
                               ", expected " + std::to_string(expected));
}

System::System(std::unique_ptr<Model> model)
    : model_(std::move(model)), method_(find_method("leapfrog")),
      state_(model_->state_size(), 0.0), saved_(model_->state_size(), 0.0),
      split_(model_->split()) {
    rebuild_integrator();
}

void System::rebuild_integrator() { integrator_ = make_integrator(method_, *model_, implicit_); }

// The setters below make what they change (a method, an integrator) inside
// agree_on_every_process and only then put it in place: an allocation that
// fails on one process of a spread model fails the call on every process,
// and no process is left with another method than the rest.

void System::set_method(const std::string &name) {
    Method method;
    std::unique_ptr<Integrator> integrator;
    model_->agree_on_every_process([&] {
        method = find_method(name);
        integrator = make_integrator(method, *model_, implicit_);
    });
    method_ = std::move(method);
    integrator_ = std::move(integrator);
}

void System::set_composition(const double *gammas, std::size_t n) {
    require_composition_count(n);
    model_->require_same_on_every_process(gammas, n * sizeof(double), "composition weights");
    Method method;
    std::unique_ptr<Integrator> integrator;
    model_->agree_on_every_process([&] {
        method = custom_composition(gammas, n);
        integrator = make_integrator(method, *model_, implicit_);
    });
    method_ = std::move(method);
    integrator_ = std::move(integrator);
}

void System::set_split(const std::string &name) {
    std::string previous, current;
    std::unique_ptr<Integrator> integrator;
    try {
        model_->agree_on_every_process([&] {
            previous = model_->split();
            model_->set_split(name);  // throws, unchanged, if unknown
            current = model_->split();
            integrator = make_integrator(method_, *model_, implicit_);
        });
    } catch (...) {
        if (!previous.empty()) model_->set_split(previous);  // empty: never changed
        throw;
    }
    integrator_ = std::move(integrator);
    split_.swap(current);
}

void System::set_implicit_settings(const ImplicitSettings &settings) {
    if (!(settings.tolerance > 0.0) || !std::isfinite(settings.tolerance))
        fail(LPI_ERR_INVALID, "tolerance must be finite and > 0, got " + number_text(settings.tolerance));
    if (settings.max_iterations < 1)
        fail(LPI_ERR_INVALID, "max_iterations must be >= 1, got " +
                                  std::to_string(settings.max_iterations));
    std::unique_ptr<Integrator> integrator;
    model_->agree_on_every_process([&] { integrator = make_integrator(method_, *model_, settings); });
    implicit_ = settings;
    integrator_ = std::move(integrator);
}

void System::set_state(const double *x, std::size_t n) {
    require_length("state", n, model_->dim());
    // Allocated on every process before the conversion's collectives.
    std::vector<double> next;
    model_->agree_on_every_process([&] { next.resize(model_->state_size()); });
    model_->from_public(x, next.data());
    state_.swap(next);
    time_ = Time{};
}

void System::get_state(double *x, std::size_t n) const {
    require_length("state buffer", n, model_->dim());
    model_->to_public(state_.data(), x);
}

void System::restore_working_state(const std::vector<double> &state, double time, double time_carry) {
    // Checked and copied with one outcome on every process of a spread
    // model: each holds its own part of the state.
    std::vector<double> restored;
    model_->agree_on_every_process([&] {
        require_length("working state", state.size(), model_->state_size());
        for (std::size_t i = 0; i < state.size(); ++i)
            if (!std::isfinite(state[i]))
                fail(LPI_ERR_NONFINITE, "working state entry " + std::to_string(i) + " is not finite");
        if (!std::isfinite(time)) fail(LPI_ERR_NONFINITE, "time is not finite");
        if (!std::isfinite(time_carry) || time + time_carry != time)
            fail(LPI_ERR_INVALID, "the time's carry " + number_text(time_carry) +
                                      " is not below half a unit in the last place of the time " +
                                      number_text(time));
        restored = state;
    });
    state_.swap(restored);
    time_ = Time{time, time_carry};
}

void System::set_threads(int n) {
    // Each process bounds n by its own processors and limits: every process
    // takes the outcome of all, and one refused anywhere is refused, and
    // undone, everywhere.
    try {
        model_->agree_on_every_process([&] {
            check_thread_count(n);
            model_->set_threads(n);  // throws, unchanged, if the model refuses n
            prepare_thread_team(n);
        });
    } catch (...) {
        model_->set_threads(threads_);  // accepted before: cannot throw
        throw;
    }
    threads_ = n;
}

void System::prepare_threads() const { prepare_thread_team(threads_); }

void System::set_observer(std::int64_t every, Observer observer) {
    if (observer && every < 1)
        fail(LPI_ERR_INVALID, "every must be >= 1, got " + std::to_string(every));
    observe_every_ = observer ? every : 0;
    observer_ = std::move(observer);
}

bool System::step(double dt, std::int64_t nsteps) {
    if (!std::isfinite(dt)) fail(LPI_ERR_NONFINITE, "dt = " + number_text(dt) + " is not finite");
    if (dt == 0.0) fail(LPI_ERR_INVALID, "dt must be nonzero");
    if (nsteps < 0) fail(LPI_ERR_INVALID, "nsteps must be >= 0, got " + std::to_string(nsteps));
    if (nsteps == 0) return true;
    // A model whose pieces are added by the user (generic, moments) may have
    // none yet: there is no Hamiltonian to integrate.
    if (model_->piece_count() == 0)
        fail(LPI_ERR_INVALID, std::string("the ") + model_->kind() +
                                  " system has no Hamiltonian pieces yet (add them with "
                                  "lpi_add_piece)");
    const Time begun = time_;
    const double start = begun.value;
    if (!std::isfinite(start + dt * static_cast<double>(nsteps)))
        fail(LPI_ERR_OVERFLOW, "the end time t + dt * nsteps = " + number_text(start, 6) + " + " +
                                   number_text(dt, 6) + " * " + std::to_string(nsteps) +
                                   " overflows a double");
    const double fraction = integrator_->largest_step_fraction();
    if (!std::isfinite(dt * fraction))
        fail(LPI_ERR_OVERFLOW, "dt = " + number_text(dt, 6) + " times the largest flow weight " +
                                   number_text(fraction, 6) + " of method '" + method_.name +
                                   "' overflows a double");
    // Everything the step sets up or allocates, before its first flow: on a
    // model spread over processes, a failure on one of them (its thread
    // limit, memory for the plans or the watch) then fails the call on every
    // process, and none is left waiting in a flow's exchange.
    StepObserver watch;
    model_->agree_on_every_process([&] {
        prepare_threads();
        model_->prepare_step();
        saved_ = state_;
        if (observer_) {
            watch.every = observe_every_;
            watch.observe = [&](std::int64_t done) {
                time_ = begun.advanced(dt, done);
                // An observer that fails (throws) on one process fails the
                // call on every one: none is left waiting in the next
                // collective.
                bool stop = false;
                model_->agree_on_every_process([&] { stop = observer_(done, time_.value); });
                return model_->on_any_process(stop);
            };
        }
        integrator_->prepare_run(*model_, watch);
    });
    const double average_iterations = integrator_->average_iterations();
    const auto roll_back = [&] {
        state_.swap(saved_);
        time_ = begun;
        integrator_->restore_average_iterations(average_iterations);
    };
    StepsInProgress progress;
    RunOutcome outcome;
    try {
        outcome = integrator_->run(*model_, state_.data(), dt, nsteps, watch, progress);
    } catch (const Error &e) {
        roll_back();
        fail(e.status(), std::string(e.what()) + ", " + steps_text(progress, start, dt) +
                             "; state rolled back");
    } catch (...) {
        roll_back();
        throw;
    }
    if (outcome.end == RunOutcome::NonFinite) {
        roll_back();
        fail(LPI_ERR_NONFINITE,
             "method '" + method_.name + "' produced a non-finite state with dt = " +
                 number_text(dt, 6) + ", found after step " + std::to_string(outcome.steps) +
                 " of this call (t = " +
                 number_text(start + dt * static_cast<double>(outcome.steps), 6) +
                 "; the state is checked every " + std::to_string(kFiniteCheckInterval) +
                 " steps, at each observation and at the end); state rolled back");
    }
    time_ = begun.advanced(dt, outcome.steps);
    return outcome.end != RunOutcome::Stopped;
}

System::Time System::Time::advanced(double dt, std::int64_t steps) const {
    // steps < 2^63 is a double exactly up to 2^53, past which a call's span
    // rounds once more (a run of 10^16 steps).
    double span, span_error, sum, sum_error;
    two_product(dt, static_cast<double>(steps), span, span_error);
    two_sum(value, span, sum, sum_error);
    Time next;
    two_sum(sum, sum_error + (span_error + carry), next.value, next.carry);
    return next;
}

double System::energy() const {
    const double h = model_->energy(state_.data());
    require_no_overflow(&h, 1, [](std::size_t) { return std::string("the energy of this state"); });
    return h;
}

void System::casimirs(double *out, std::size_t n) const {
    require_length("Casimir buffer", n, model_->casimir_count());
    std::vector<double> values;
    model_->agree_on_every_process([&] { values.resize(n); });  // before the model's collectives
    model_->casimirs(state_.data(), values.data());
    require_no_overflow(values.data(), n,
                        [](std::size_t i) { return "Casimir " + std::to_string(i) + " of this state"; });
    std::copy(values.begin(), values.end(), out);
}

}  // namespace lpi
