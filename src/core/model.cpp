#include "model.hpp"

#include <algorithm>
#include <cmath>

#include "error.hpp"
#include "integrator.hpp"
#include "text.hpp"

namespace lpi {

void Model::to_public(const double *state, double *x) const {
    std::copy(state, state + dim(), x);
}

void Model::from_public(const double *x, double *state) const {
    for (std::size_t i = 0; i < dim(); ++i) {
        if (!std::isfinite(x[i]))
            fail(LPI_ERR_NONFINITE, "state entry " + std::to_string(i) + " is not finite");
    }
    std::copy(x, x + dim(), state);
}

void Model::set_threads(int n) {
    if (n < 1) fail(LPI_ERR_INVALID, "thread count must be >= 1, got " + std::to_string(n));
    if (n > 1)
        fail(LPI_ERR_UNSUPPORTED, std::string(kind()) + " integrates on one thread only");
}

bool Model::finite(const double *state) const { return all_finite(state, state_size()); }

std::vector<double> Model::whole_state(const double *state) const {
    return std::vector<double>(state, state + state_size());
}

std::vector<double> Model::checkpoint_parameters() const {
    fail(LPI_ERR_UNSUPPORTED, std::string("a ") + kind() + " system cannot be checkpointed");
}

}  // namespace lpi

namespace lpi {

void SplitChoice::select(const std::string &name, const char *model_kind) {
    for (std::size_t i = 0; i < names_.size(); ++i) {
        if (names_[i] == name) {
            index_ = i;
            return;
        }
    }
    std::string known;
    for (const std::string &n : names_) known += (known.empty() ? "" : ", ") + n;
    fail(LPI_ERR_INVALID, "unknown split " + quoted(name) + " for " + model_kind + " (known: " + known + ")");
}

}  // namespace lpi
