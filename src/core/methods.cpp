#include "methods.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.hpp"
#include "integrator.hpp"
#include "text.hpp"

namespace lpi {

namespace {

Method sequence(const char *name, MethodKind kind, const char *source) {
    Method m;
    m.name = name;
    m.order = 1;
    m.stages = 1;
    m.source = source;
    m.kind = kind;
    m.make_integrator = make_splitting_integrator;
    return m;
}

Method composition(std::string name, int order, std::vector<double> gammas, std::string source) {
    Method m;
    m.name = std::move(name);
    m.order = order;
    m.stages = static_cast<int>(gammas.size());
    m.source = std::move(source);
    m.kind = MethodKind::SymmetricComposition;
    m.gammas = std::move(gammas);
    m.make_integrator = make_splitting_integrator;
    return m;
}

// The full weights of a symmetric composition from its independent half,
// listed from the outermost stage to the centre stage (included, last):
// {g1, ..., gm, c} -> {g1, ..., gm, c, gm, ..., g1}.
std::vector<double> palindrome(std::initializer_list<double> half) {
    std::vector<double> full(half);
    for (std::size_t i = half.size() - 1; i-- > 0;) full.push_back(full[i]);
    return full;
}

// Every table below is verified in tests/test_composition_tables.cpp: weights
// summing to 1, exact symmetry, and every order condition of a symmetric
// composition of a symmetric second-order method, up to its order (checked as
// the word coefficients of the composed series in the free algebra of the
// method's error terms). Measured orders are in tests/test_compositions.c.
std::vector<Method> make_table() {
    std::vector<Method> table;
    table.push_back(sequence("lie-trotter", MethodKind::Sequence,
                             "H. F. Trotter, Proc. AMS 10 (1959) 545; McLachlan 1993 eq. (1)"));
    table.push_back(sequence("lie-trotter-adjoint", MethodKind::SequenceAdjoint,
                             "adjoint of lie-trotter (pieces in reverse order)"));
    table.push_back(composition("leapfrog", 2, {1.0},
                                "G. Strang, SIAM J. Numer. Anal. 5 (1968) 506; McLachlan 1993"));

    // Triple jump: g1 = 1/(2 - 2^(1/3)), centre 1 - 2 g1.
    table.push_back(composition(
        "triple-jump-4", 4,
        palindrome({1.351207191959657634047688, -1.702414383919315268095376}),
        "H. Yoshida, Phys. Lett. A 150 (1990) 262 (triple jump); M. Creutz and A. Gocksch, "
        "Phys. Rev. Lett. 63 (1989) 9"));

    // Suzuki's fractal: g1 = g2 = 1/(4 - 4^(1/3)), centre 1 - 4 g1.
    table.push_back(composition(
        "suzuki-4", 4,
        palindrome({0.4144907717943757371423541, 0.4144907717943757371423541,
                    -0.6579630871775029485694163}),
        "M. Suzuki, Phys. Lett. A 146 (1990) 319 (fractal decomposition, p = 1/(4 - 4^(1/3)))"));

    // McLachlan's symmetric 5-stage order-4 method (g1 = 0.28; g2 the root of
    // 2 g1^3 + 2 g2^3 + (1 - 2 g1 - 2 g2)^3 = 0 near 0.625). Outermost stage
    // first: composing in another order is a different method.
    table.push_back(composition(
        "mclachlan-4", 4,
        palindrome({0.28, 0.6254664284676700450123389, -0.8109328569353400900246778}),
        "R. I. McLachlan, SIAM J. Sci. Comput. 16 (1995) 151, order 4, m = 5; "
        "B. Leimkuhler and S. Reich, Simulating Hamiltonian Dynamics (2004) Table 6.2"));

    // Yoshida's solution A, order 6 (w3, w2, w1, w0). Yoshida gives 15 digits;
    // these are the exact solution of the order conditions nearest to them
    // (Newton iteration in 60-digit arithmetic; the published digits agree).
    table.push_back(composition(
        "yoshida-6", 6,
        palindrome({0.7845136104775572638194976, 0.2355732133593581336847932,
                    -1.177679984178871006946416, 1.315186320683911218884250}),
        "H. Yoshida, Phys. Lett. A 150 (1990) 262, Table 1, solution A"));

    // Kahan & Li s9odr6a, as tabulated in Hairer, Lubich & Wanner, Geometric
    // Numerical Integration, 2nd ed. (2006), sect. V.3.2.
    table.push_back(composition(
        "kahan-li-6", 6,
        palindrome({0.39216144400731413927925056, 0.33259913678935943859974864,
                    -0.70624617255763935980996482, 0.08221359629355080023149045,
                    0.79854399093482996339895035}),
        "W. Kahan and R.-C. Li, Math. Comp. 66 (1997) 1089, s9odr6a; Hairer, Lubich & "
        "Wanner, Geometric Numerical Integration (2006) sect. V.3.2"));

    // Yoshida's solution D, order 8 (w7, ..., w1, w0): the one in common use.
    // The 15 published digits satisfy the order conditions only to ~3e-12 and
    // differ from the exact solution by up to 2.4e-13 (w3); these are the exact
    // solution nearest to them (Newton iteration in 60-digit arithmetic).
    table.push_back(composition(
        "yoshida-8", 8,
        palindrome({0.9148442462297915667487935, 0.2536933365662113541461460,
                    -1.444852236860605157694731, -0.1582406353680501752040668,
                    1.938139137622525986579186, -1.960610232975310807607633,
                    0.1027998493917964406981151, 1.708453070787281584668379}),
        "H. Yoshida, Phys. Lett. A 150 (1990) 262, Table 2, solution D (refined to the "
        "exact root of the order conditions)"));

    // McLachlan's 15-stage order-8 method, as tabulated in Hairer, Lubich &
    // Wanner (2006) sect. V.3.2 ("p8 s15").
    table.push_back(composition(
        "mclachlan-8", 8,
        palindrome({0.74167036435061295344822780, -0.40910082580003159399730010,
                    0.19075471029623837995387626, -0.57386247111608226665638773,
                    0.29906418130365592384446354, 0.33462491824529818378495798,
                    0.31529309239676659663205666, -0.79688793935291635401978884}),
        "R. I. McLachlan, SIAM J. Sci. Comput. 16 (1995) 151, order 8, m = 15; Hairer, "
        "Lubich & Wanner (2006) sect. V.3.2"));

    // Kahan & Li s17odr8a, as tabulated in Hairer, Lubich & Wanner (2006)
    // sect. V.3.2 ("p8 s17").
    table.push_back(composition(
        "kahan-li-8", 8,
        palindrome({0.13020248308889008087881763, 0.56116298177510838456196441,
                    -0.38947496264484728640807860, 0.15884190655515560089621075,
                    -0.39590389413323757733623154, 0.18453964097831570709183254,
                    0.25837438768632204729397911, 0.29501172360931029887096624,
                    -0.60550853383003451169892108}),
        "W. Kahan and R.-C. Li, Math. Comp. 66 (1997) 1089, s17odr8a; Hairer, Lubich & "
        "Wanner (2006) sect. V.3.2"));

    // Sofroniou & Spaletta's 35-stage order-10 method, as tabulated in Hairer,
    // Lubich & Wanner (2006) sect. V.3.2 ("p10 s35").
    table.push_back(composition(
        "sofroniou-spaletta-10", 10,
        palindrome({0.07879572252168641926390768, 0.31309610341510852776481247,
                    0.02791838323507806610952027, -0.22959284159390709415121340,
                    0.13096206107716486317465686, -0.26973340565451071434460973,
                    0.07497334315589143566613711, 0.11199342399981020488957508,
                    0.36613344954622675119314812, -0.39910563013603589787862981,
                    0.10308739852747107731580277, 0.41143087395589023782070412,
                    -0.00486636058313526176219566, -0.39203335370863990644808194,
                    0.05194250296244964703718290, 0.05066509075992449633587434,
                    0.04967437063972987905456880, 0.04931773575959453791768001}),
        "M. Sofroniou and G. Spaletta, Optim. Methods Softw. 20 (2005) 597; Hairer, "
        "Lubich & Wanner (2006) sect. V.3.2"));

    add_registered_methods(table);
    return table;
}

struct Alias {
    const char *alias;
    const char *name;
};
const Alias kAliases[] = {{"strang", "leapfrog"}};

// Builds the recursive composition of order p: each level composes the
// previous one as (w1, w0, w1) or (w1, w1, w0, w1, w1).
std::vector<double> recursive_gammas(int order, int copies) {
    std::vector<double> gammas{1.0};
    for (int q = 2; q < order; q += 2) {
        // Order q -> q + 2 needs (copies - 1) w1^(q+1) + w0^(q+1) = 0.
        const double k = copies - 1;
        const double w1 = 1.0 / (k - std::pow(k, 1.0 / (q + 1)));
        const double w0 = 1.0 - k * w1;
        std::vector<double> next;
        next.reserve(gammas.size() * copies);
        for (int c = 0; c < copies; ++c) {
            const double w = c == copies / 2 ? w0 : w1;
            for (double g : gammas) next.push_back(w * g);
        }
        gammas.swap(next);
    }
    return gammas;
}

// "triple-jump-<p>" / "suzuki-<p>": the order p, or 0 if name has not that
// form (p digits only, no leading zero: "triple-jump-4 " is an unknown
// name); throws for an order p that is odd or too large.
int recursive_order(const std::string &name, const std::string &prefix) {
    if (name.compare(0, prefix.size(), prefix) != 0) return 0;
    const std::string digits = name.substr(prefix.size());
    bool ok = !digits.empty() && digits[0] != '0';
    for (char c : digits) ok = ok && c >= '0' && c <= '9';
    if (!ok) return 0;
    const int p = digits.size() <= 2 ? std::stoi(digits) : kMaxRecursiveOrder + 1;
    if (p % 2 != 0 || p > kMaxRecursiveOrder)
        fail(LPI_ERR_INVALID, "unknown method " + quoted(name) + ": the order of " + prefix +
                                  "<p> must be even, from 2 to " +
                                  std::to_string(kMaxRecursiveOrder));
    return p;
}

}  // namespace

const std::vector<Method> &method_table() {
    static const std::vector<Method> table = make_table();
    return table;
}

bool is_splitting(const Method &method) { return method.kind != MethodKind::Baseline; }

void refuse_system(const std::string &message) { throw MethodNotApplicable(message); }

Method baseline_method(std::string name, int order, std::string source, IntegratorFactory make) {
    Method m;
    m.name = std::move(name);
    m.order = order;
    m.stages = 1;
    m.source = std::move(source);
    m.poisson = false;
    m.kind = MethodKind::Baseline;
    m.make_integrator = make;
    return m;
}

std::vector<double> triple_jump_gammas(int order) { return recursive_gammas(order, 3); }
std::vector<double> suzuki_gammas(int order) { return recursive_gammas(order, 5); }

Method find_method(const std::string &requested) {
    std::string name = requested;
    for (const Alias &a : kAliases)
        if (name == a.alias) name = a.name;
    for (const Method &m : method_table())
        if (m.name == name) return m;
    if (const int p = recursive_order(name, "triple-jump-"))
        return composition(name, p, triple_jump_gammas(p),
                           "H. Yoshida, Phys. Lett. A 150 (1990) 262 (recursive triple jump)");
    if (const int p = recursive_order(name, "suzuki-"))
        return composition(name, p, suzuki_gammas(p),
                           "M. Suzuki, Phys. Lett. A 146 (1990) 319 (recursive fractal, "
                           "5 stages per level)");
    std::string known;
    for (const Method &m : method_table()) known += (known.empty() ? "" : ", ") + m.name;
    for (const Alias &a : kAliases) known += std::string(", ") + a.alias;
    fail(LPI_ERR_INVALID, "unknown method " + quoted(requested) + " (known: " + known +
                              ", triple-jump-<p>, suzuki-<p> for even p <= " +
                              std::to_string(kMaxRecursiveOrder) + ")");
}

void require_composition_count(std::size_t n) {
    if (n == 0) fail(LPI_ERR_INVALID, "a composition needs n >= 1 weights, got n = 0");
    if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        fail(LPI_ERR_INVALID, "n = " + std::to_string(n) + " weights is too many");
}

Method custom_composition(const double *gammas, std::size_t n) {
    constexpr double kTolerance = 1e-14;
    require_composition_count(n);
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(gammas[i]))
            fail(LPI_ERR_NONFINITE, "gammas[" + std::to_string(i) + "] = " +
                                        number_text(gammas[i]) + " is not finite");
    // The sum of |gammas| bounds every difference, partial sum, merged flow
    // weight and mean below: when it is finite, none of them overflows.
    double magnitude = 0.0;
    for (std::size_t i = 0; i < n; ++i) magnitude += std::fabs(gammas[i]);
    if (!std::isfinite(magnitude))
        fail(LPI_ERR_OVERFLOW, "the weights are finite, but the sum of their absolute values "
                               "overflows a double (the weights of a composition must sum "
                               "to 1)");
    for (std::size_t i = 0, j = n - 1; i < j; ++i, --j) {
        const double a = gammas[i], b = gammas[j];
        if (std::fabs(a - b) > kTolerance * std::fmax(std::fabs(a), std::fabs(b)))
            fail(LPI_ERR_INVALID, "the weights are not symmetric: gammas[" + std::to_string(i) +
                                      "] = " + number_text(a) + " but gammas[" +
                                      std::to_string(j) + "] = " + number_text(b) +
                                      " (they must agree to a relative 1e-14)");
    }
    // The method runs with each mirrored pair replaced by its mean, which can
    // move the sum by half an ulp of the pair's: the sum is tested on the
    // weights that run (and that a checkpoint stores), so that what passes
    // here passes again when a checkpoint of it is loaded.
    std::vector<double> symmetric(gammas, gammas + n);
    for (std::size_t i = 0, j = n - 1; i < j; ++i, --j)
        symmetric[i] = symmetric[j] = 0.5 * (gammas[i] + gammas[j]);
    magnitude = 0.0;
    for (double g : symmetric) magnitude += std::fabs(g);
    // Neumaier's compensated sum, so the test is not blurred by its own round-off.
    double sum = 0.0, compensation = 0.0;
    for (double g : symmetric) {
        const double t = sum + g;
        compensation += std::fabs(sum) >= std::fabs(g) ? (sum - t) + g : (g - t) + sum;
        sum = t;
    }
    sum += compensation;
    // And to 1e-10 at most, however large the weights: a sum off by more
    // runs the flow at another speed (weights of 1e14 summing to 0 passed
    // the relative test, and the method did not converge).
    constexpr double kLargestInconsistency = 1e-10;
    if (!(std::fabs(sum - 1.0) <= std::fmin(kTolerance * magnitude, kLargestInconsistency)))
        fail(LPI_ERR_INVALID, "the weights sum to " + number_text(sum) +
                                  ", not 1, with each mirrored pair taken as its mean (they "
                                  "must, to 1e-14 times the sum of their absolute values and "
                                  "to 1e-10 at most)");
    return composition("custom", 2, std::move(symmetric),
                       "user-supplied symmetric composition of leapfrog");
}

FlowProgram::FlowProgram(const Method &method, std::size_t pieces) {
    if (pieces == 0) return;  // nothing to compose; System::step refuses to step
    switch (method.kind) {
    case MethodKind::Sequence:
        for (std::size_t k = 0; k < pieces; ++k) stage_.push_back({k, 1.0});
        gammas_ = {1.0};
        return;
    case MethodKind::SequenceAdjoint:
        for (std::size_t k = pieces; k-- > 0;) stage_.push_back({k, 1.0});
        gammas_ = {1.0};
        return;
    case MethodKind::SymmetricComposition:
        if (pieces == 1) {  // every stage's one flow merged into one, summed in order
            double total = method.gammas.front();
            for (std::size_t i = 1; i < method.gammas.size(); ++i) total += method.gammas[i];
            stage_ = {{0, 1.0}};
            gammas_ = {total};
            return;
        }
        // A stage is A_0/2 .. A_{m-2}/2 A_{m-1} A_{m-2}/2 .. A_0/2 for gamma dt;
        // the halves of A_0 at a seam are one flow (0.5 g + 0.5 g', as summed).
        for (std::size_t k = 1; k + 1 < pieces; ++k) stage_.push_back({k, 0.5});
        stage_.push_back({pieces - 1, 1.0});
        for (std::size_t k = pieces - 1; k-- > 1;) stage_.push_back({k, 0.5});
        gammas_ = method.gammas;
        seams_.push_back(0.5 * gammas_.front());
        for (std::size_t i = 1; i < gammas_.size(); ++i)
            seams_.push_back(0.5 * gammas_[i - 1] + 0.5 * gammas_[i]);
        seams_.push_back(0.5 * gammas_.back());
        return;
    case MethodKind::Baseline:
        fail(LPI_ERR_INTERNAL, "a flow program asked of a non-splitting method");
    }
}

std::vector<Flow> FlowProgram::written_out() const {
    std::vector<Flow> flows;
    if (has_seams()) flows.push_back(first());
    for_each_between_seams([&](const Flow &f) { flows.push_back(f); });
    if (has_seams()) flows.push_back(last());
    return flows;
}

double FlowProgram::largest_weight() const {
    // fl(|w| |g|) grows with each factor, so the largest product is that of
    // the largest factors.
    double stage = 0.0, gamma = 0.0, largest = 0.0;
    for (const Flow &f : stage_) stage = std::max(stage, std::fabs(f.weight));
    for (double g : gammas_) gamma = std::max(gamma, std::fabs(g));
    largest = stage * gamma;
    for (double w : seams_) largest = std::max(largest, std::fabs(w));
    if (has_seams()) largest = std::max(largest, std::fabs(last().weight + first().weight));
    return largest;
}

}  // namespace lpi
