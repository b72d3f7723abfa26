// The planar pendulum on e(2)* (paper section 2): H = x3^2/2 + x2 with
// J = [[0,0,-x2],[0,0,x1],[x2,-x1,0]]. Piece 0, H = x2, kicks x3 <- x3 - t x1;
// piece 1, H = x3^2/2, rotates (x1, x2) by x3 t. Together: the standard map.
#include "models.hpp"

namespace lpi {

namespace {

class Pendulum final : public CompensatedModel {
public:
    const char *kind() const override { return "pendulum"; }
    std::size_t dim() const override { return 3; }

    std::vector<std::string> split_names() const override { return split_.names(); }
    void set_split(const std::string &name) override { split_.select(name, kind()); }
    std::string split() const override { return split_.current(); }
    std::size_t piece_count() const override { return 2; }
    std::vector<double> checkpoint_parameters() const override { return {}; }

    void flow(std::size_t piece, double t, double *state) override {
        double *carry = state + 3;
        if (piece == 0)
            // The increment of the double-double x1 + carry formed by parts,
            // as rotate_pair's are.
            compensated_add(state[2], carry[2], -t * state[0] + -t * carry[0]);
        else  // dx1 = -x3 x2, dx2 = x3 x1
            rotate_pair(state, carry, 0, 1, -(state[2] + carry[2]) * t);
    }

    double energy(const double *state) const override {
        double x[3];
        value(state, x);
        return 0.5 * x[2] * x[2] + x[1];
    }
    std::size_t casimir_count() const override { return 1; }
    void casimirs(const double *state, double *out) const override {
        double x[3];
        value(state, x);
        out[0] = x[0] * x[0] + x[1] * x[1];
    }

    void public_vector_field(const double *x, double *rate) const override {
        rate[0] = -x[1] * x[2];
        rate[1] = x[0] * x[2];
        rate[2] = -x[0];
    }

private:
    SplitChoice split_{{"standard-map"}};
};

}  // namespace

std::unique_ptr<Model> make_pendulum() { return std::make_unique<Pendulum>(); }

CheckpointKind pendulum_checkpoint_kind() {
    return {"pendulum", 0, [](const std::vector<double> &) -> std::uint64_t { return 6; },
            [](const std::vector<double> &) { return make_pendulum(); }, check_compensated_state};
}

}  // namespace lpi
