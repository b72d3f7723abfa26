#include "system.hpp"

#include <cmath>
#include <cstdio>

#include "error.hpp"

namespace lpi {

void require_length(const char *what, std::size_t given, std::size_t expected) {
    if (given != expected)
        fail(LPI_ERR_SIZE, std::string(what) + " has length " + std::to_string(given) +
                               ", expected " + std::to_string(expected));
}

System::System(std::unique_ptr<Model> model)
    : model_(std::move(model)), method_(find_method("leapfrog")),
      state_(model_->state_size(), 0.0), saved_(model_->state_size(), 0.0) {
    rebuild_integrator();
}

void System::rebuild_integrator() { integrator_ = make_integrator(method_, *model_, implicit_); }

void System::set_method(const std::string &name) {
    Method method = find_method(name);
    auto integrator = make_integrator(method, *model_, implicit_);
    method_ = std::move(method);
    integrator_ = std::move(integrator);
}

void System::set_composition(const double *gammas, std::size_t n) {
    Method method = custom_composition(gammas, n);
    auto integrator = make_integrator(method, *model_, implicit_);
    method_ = std::move(method);
    integrator_ = std::move(integrator);
}

void System::set_split(const std::string &name) {
    const std::string previous = model_->split();
    model_->set_split(name);  // throws, unchanged, if unknown
    try {
        rebuild_integrator();
    } catch (...) {
        model_->set_split(previous);
        throw;
    }
}

void System::set_implicit_settings(const ImplicitSettings &settings) {
    if (!(settings.tolerance > 0.0) || !std::isfinite(settings.tolerance))
        fail(LPI_ERR_INVALID, "tolerance must be finite and > 0");
    if (settings.max_iterations < 1)
        fail(LPI_ERR_INVALID, "max_iterations must be >= 1, got " +
                                  std::to_string(settings.max_iterations));
    auto integrator = make_integrator(method_, *model_, settings);
    implicit_ = settings;
    integrator_ = std::move(integrator);
}

void System::set_state(const double *x, std::size_t n) {
    require_length("state", n, model_->dim());
    std::vector<double> next(model_->state_size());
    model_->from_public(x, next.data());
    state_.swap(next);
    time_ = 0.0;
}

void System::get_state(double *x, std::size_t n) const {
    require_length("state buffer", n, model_->dim());
    model_->to_public(state_.data(), x);
}

void System::restore_working_state(std::vector<double> state, double time) {
    require_length("working state", state.size(), model_->state_size());
    for (std::size_t i = 0; i < state.size(); ++i)
        if (!std::isfinite(state[i]))
            fail(LPI_ERR_NONFINITE, "working state entry " + std::to_string(i) + " is not finite");
    if (!std::isfinite(time)) fail(LPI_ERR_NONFINITE, "time is not finite");
    state_.swap(state);
    time_ = time;
}

void System::step(double dt, std::int64_t nsteps) {
    if (!std::isfinite(dt)) fail(LPI_ERR_NONFINITE, "dt is not finite");
    if (dt == 0.0) fail(LPI_ERR_INVALID, "dt must be nonzero");
    if (nsteps < 0) fail(LPI_ERR_INVALID, "nsteps must be >= 0, got " + std::to_string(nsteps));
    if (nsteps == 0) return;
    // A model whose pieces are added by the user (generic, moments) may have
    // none yet: there is no Hamiltonian to integrate.
    if (model_->piece_count() == 0)
        fail(LPI_ERR_INVALID, std::string("the ") + model_->kind() +
                                  " system has no Hamiltonian pieces yet (add them with "
                                  "lpi_add_piece)");
    const double end_time = time_ + dt * static_cast<double>(nsteps);
    if (!std::isfinite(end_time))
        fail(LPI_ERR_INVALID, "dt * nsteps overflows the time variable");

    saved_ = state_;
    bool finite = false;
    try {
        finite = integrator_->advance(*model_, state_.data(), dt, nsteps);
    } catch (...) {
        state_.swap(saved_);
        throw;
    }
    if (!finite) {
        state_.swap(saved_);
        char step[32];
        std::snprintf(step, sizeof step, "%.6g", dt);
        fail(LPI_ERR_NONFINITE, "method '" + method_.name + "' produced a non-finite state "
                                "with dt = " + step + "; state rolled back");
    }
    time_ = end_time;
}

double System::energy() const { return model_->energy(state_.data()); }

void System::casimirs(double *out, std::size_t n) const {
    require_length("Casimir buffer", n, model_->casimir_count());
    model_->casimirs(state_.data(), out);
}

}  // namespace lpi
