// The free rigid body on so(3)* (paper section 2). J(m) v = m x v, so the
// flow of a piece H_k = a_k m_k^2 / 2 is a rotation about axis k by -a_k m_k t.
#include <cmath>
#include <string>

#include "../core/error.hpp"
#include "../core/text.hpp"
#include "models.hpp"

namespace lpi {

namespace {

class RigidBody final : public CompensatedModel {
public:
    RigidBody(double I1, double I2, double I3)
        : inertia_{I1, I2, I3}, inverse_{1.0 / I1, 1.0 / I2, 1.0 / I3} {}

    const char *kind() const override { return "rigid-body"; }
    std::size_t dim() const override { return 3; }

    std::vector<std::string> split_names() const override { return split_.names(); }
    void set_split(const std::string &name) override { split_.select(name, kind()); }
    std::string split() const override { return split_.current(); }
    double inertia(int axis) const { return inertia_[axis]; }
    std::vector<double> checkpoint_parameters() const override {
        return {inertia_[0], inertia_[1], inertia_[2]};
    }
    std::size_t piece_count() const override { return split_.index() == kCasimirShift ? 2 : 3; }

    void flow(std::size_t piece, double t, double *state) override {
        // casimir-shift: H - |m|^2 / (2 I1) leaves pieces on axes 2 and 3 with
        // coefficients 1/I_k - 1/I1 (paper); axes: pieces on axes 1, 2, 3.
        const int axis = split_.index() == kCasimirShift ? static_cast<int>(piece) + 1
                                                         : static_cast<int>(piece);
        const double a = split_.index() == kCasimirShift ? inverse_[axis] - inverse_[0]
                                                         : inverse_[axis];
        // Axis k rotates the pair (k+1, k+2) mod 3: dm_i = w m_j, dm_j = -w m_i.
        const double m_axis = state[axis] + state[3 + axis];
        rotate_pair(state, state + 3, (axis + 1) % 3, (axis + 2) % 3, a * m_axis * t);
    }

    double energy(const double *state) const override {
        double m[3];
        value(state, m);
        // Halved term by term (the same bits): a sum beyond DBL_MAX whose
        // half is not is no overflow of the energy.
        return 0.5 * inverse_[0] * m[0] * m[0] + 0.5 * inverse_[1] * m[1] * m[1] +
               0.5 * inverse_[2] * m[2] * m[2];
    }
    std::size_t casimir_count() const override { return 1; }
    void casimirs(const double *state, double *out) const override {
        double m[3];
        value(state, m);
        out[0] = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    }

    void public_vector_field(const double *m, double *rate) const override {
        const double w[3] = {inverse_[0] * m[0], inverse_[1] * m[1], inverse_[2] * m[2]};
        rate[0] = m[1] * w[2] - m[2] * w[1];
        rate[1] = m[2] * w[0] - m[0] * w[2];
        rate[2] = m[0] * w[1] - m[1] * w[0];
    }

private:
    static constexpr std::size_t kCasimirShift = 0;
    double inertia_[3];
    double inverse_[3];
    SplitChoice split_{{"casimir-shift", "axes"}};
};

void check_inertia(const char *name, double I) {
    if (!std::isfinite(I)) fail(LPI_ERR_NONFINITE, std::string("inertia ") + name + " is not finite");
    if (!(I > 0.0))
        fail(LPI_ERR_INVALID, std::string("inertia ") + name + " must be > 0, got " + number_text(I));
    if (!std::isfinite(1.0 / I))
        fail(LPI_ERR_INVALID, std::string("inertia ") + name + " is too small: 1/" + name + " overflows");
}

}  // namespace

bool rigid_body_inertia(const Model &model, double inertia[3]) {
    const auto *body = dynamic_cast<const RigidBody *>(&model);
    if (!body) return false;
    for (int k = 0; k < 3; ++k) inertia[k] = body->inertia(k);
    return true;
}

std::unique_ptr<Model> make_rigid_body(double I1, double I2, double I3) {
    check_inertia("I1", I1);
    check_inertia("I2", I2);
    check_inertia("I3", I3);
    return std::make_unique<RigidBody>(I1, I2, I3);
}

CheckpointKind rigid_body_checkpoint_kind() {
    return {"rigid-body", 3, [](const std::vector<double> &) -> std::uint64_t { return 6; },
            [](const std::vector<double> &p) { return make_rigid_body(p[0], p[1], p[2]); },
            check_compensated_state};
}

}  // namespace lpi
