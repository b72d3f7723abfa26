// White-box checks of the raw composition tables (linked against the object
// library): weights sum to 1, exact symmetry, odd power sums, and every order
// condition. A symmetric second-order method S has log S(h) = h A1 + h^3 A3 +
// h^5 A5 + ... with A_k free; a composition S(g_1 h) ... S(g_s h) has order p
// exactly when the product of exp(sum_k (g_i h)^k A_k) equals exp(h A1) up to
// h^p in the free associative algebra on A1, A3, ... . Word coefficients are
// polynomials in the g_i (the one-letter word A_k gives sum g_i^k), so the
// conditions are checked here as plain floating-point sums.
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "lpi_test.h"

#include "core/methods.hpp"

namespace {

struct Algebra {
    int order;
    std::vector<std::vector<int>> words;  // letters are odd weights 1, 3, 5, ...
    std::vector<int> weight, length;
    std::vector<std::vector<std::pair<int, int>>> products;  // (b, c): words[a]words[b] = words[c]

    explicit Algebra(int p) : order(p) {
        std::map<std::vector<int>, int> index;
        words.push_back({});
        for (std::size_t i = 0; i < words.size(); ++i) {
            int w = 0;
            for (int l : words[i]) w += l;
            for (int k = 1; w + k <= p; k += 2) {
                std::vector<int> next = words[i];
                next.push_back(k);
                words.push_back(next);
            }
        }
        for (std::size_t i = 0; i < words.size(); ++i) index[words[i]] = static_cast<int>(i);
        for (const auto &w : words) {
            int s = 0;
            for (int l : w) s += l;
            weight.push_back(s);
            length.push_back(static_cast<int>(w.size()));
        }
        products.resize(words.size());
        for (std::size_t a = 0; a < words.size(); ++a)
            for (std::size_t b = 0; b < words.size(); ++b)
                if (weight[a] + weight[b] <= p) {
                    std::vector<int> ab = words[a];
                    ab.insert(ab.end(), words[b].begin(), words[b].end());
                    products[a].push_back({static_cast<int>(b), index.at(ab)});
                }
    }

    // Coefficients of prod_i exp(sum_k g_i^k A_k); the coefficient of a word
    // of weight w and length m in one factor is g^w / m!.
    std::vector<double> compose(const std::vector<double> &gammas) const {
        std::vector<double> total(words.size(), 0.0), factor(words.size()), next;
        total[0] = 1.0;
        for (double g : gammas) {
            for (std::size_t i = 0; i < words.size(); ++i)
                factor[i] = std::pow(g, weight[i]) / std::tgamma(length[i] + 1.0);
            next.assign(words.size(), 0.0);
            for (std::size_t a = 0; a < words.size(); ++a)
                if (total[a] != 0.0)
                    for (auto [b, c] : products[a]) next[c] += total[a] * factor[b];
            total.swap(next);
        }
        return total;
    }

    // Largest order-condition residual, relative to the size of the terms
    // (the same products with |g_i|), over all words of weight <= order.
    double worst_residual(const std::vector<double> &gammas, std::string *where) const {
        const std::vector<double> value = compose(gammas);
        std::vector<double> magnitude_gammas;
        for (double g : gammas) magnitude_gammas.push_back(std::fabs(g));
        const std::vector<double> magnitude = compose(magnitude_gammas);
        double worst = 0.0;
        for (std::size_t i = 1; i < words.size(); ++i) {
            bool only_a1 = true;
            for (int l : words[i]) only_a1 = only_a1 && l == 1;
            const double target = only_a1 ? 1.0 / std::tgamma(length[i] + 1.0) : 0.0;
            const double r = std::fabs(value[i] - target) / std::fmax(1.0, magnitude[i]);
            if (r > worst) {
                worst = r;
                if (where) {
                    *where = "A";
                    for (int l : words[i]) *where += std::to_string(l) + " ";
                }
            }
        }
        return worst;
    }
};

// Rounding of the composed sums stays below this, relative to their size
// (a few units of round-off; the published 15 digits of Yoshida's solution D
// already miss it).
constexpr double kConditionTolerance = 2e-15;

// Tables: weights summing to 1 within 1e-15. Recursive constructions multiply
// weights level by level, so theirs is relative to the sum of |weights|.
void check_table(const lpi::Method &m, bool recursive = false) {
    const std::vector<double> &g = m.gammas;
    const std::size_t n = g.size();
    assert_int_equal(n, static_cast<std::size_t>(m.stages));
    for (std::size_t i = 0; i < n; ++i)
        if (g[i] != g[n - 1 - i]) fail_msg("%s: gammas[%zu] != gammas[%zu]", m.name.c_str(), i, n - 1 - i);
    double sum = 0.0, magnitude = 0.0;
    for (double x : g) {
        sum += x;
        magnitude += std::fabs(x);
    }
    if (std::fabs(sum - 1.0) > (recursive ? 1e-15 * magnitude : 1e-15)) fail_msg("%s: weights sum to 1 + %.3e", m.name.c_str(), sum - 1.0);
    for (int k = 3; k < m.order; k += 2) {
        double power_sum = 0.0, scale = 0.0;
        for (double x : g) {
            power_sum += std::pow(x, k);
            scale += std::pow(std::fabs(x), k);
        }
        if (std::fabs(power_sum) > 1e-15 * scale)
            fail_msg("%s: sum of gamma^%d = %.3e (scale %.3e)", m.name.c_str(), k, power_sum, scale);
    }
    std::string word;
    const double r = Algebra(m.order).worst_residual(g, &word);
    print_message("%-22s order %2d, %2zu stages: sum - 1 = %+.1e, worst order-condition residual %.1e (%s)\n",
                  m.name.c_str(), m.order, n, sum - 1.0, r, word.c_str());
    if (r > kConditionTolerance)
        fail_msg("%s: order condition for word %s violated by %.3e", m.name.c_str(), word.c_str(), r);
}

void test_every_table(void **) {
    int checked = 0;
    for (const lpi::Method &m : lpi::method_table())
        if (m.kind == lpi::MethodKind::SymmetricComposition) {
            check_table(m);
            ++checked;
        }
    assert_int_equal(checked, 10);
}

void test_recursive_constructions(void **) {
    for (int p = 2; p <= 10; p += 2) {
        check_table(lpi::find_method("triple-jump-" + std::to_string(p)), true);
        check_table(lpi::find_method("suzuki-" + std::to_string(p)), true);
    }
    assert_int_equal(lpi::find_method("triple-jump-16").gammas.size(), 2187u);
    assert_int_equal(lpi::find_method("suzuki-16").gammas.size(), 78125u);
    // The literal rows agree with the recursive construction.
    const auto literal_tj = lpi::find_method("triple-jump-4").gammas;
    const auto literal_su = lpi::find_method("suzuki-4").gammas;
    const auto tj = lpi::triple_jump_gammas(4), su = lpi::suzuki_gammas(4);
    assert_int_equal(tj.size(), literal_tj.size());
    assert_int_equal(su.size(), literal_su.size());
    for (std::size_t i = 0; i < tj.size(); ++i) assert_true(std::fabs(tj[i] - literal_tj[i]) < 1e-15);
    for (std::size_t i = 0; i < su.size(); ++i) assert_true(std::fabs(su[i] - literal_su[i]) < 1e-15);
}

// The check can fail: the kinds of error found in published copies of these
// tables (a sign flip, stages in the wrong order, digits cut short) are caught.
void test_check_detects_bad_tables(void **) {
    const Algebra six(6), eight(8);
    auto y6 = lpi::find_method("yoshida-6").gammas;
    auto flipped = y6;
    flipped[1] = -flipped[1];
    flipped[5] = -flipped[5];
    assert_true(six.worst_residual(flipped, nullptr) > 1e-3);
    std::vector<double> reordered = {y6[2], y6[1], y6[0], y6[3], y6[0], y6[1], y6[2]};
    assert_true(six.worst_residual(reordered, nullptr) > 1e-3);
    // Yoshida's 15 published digits of solution D.
    const double w[8] = {1.0, 0.102799849391985, -1.96061023297549, 1.93813913762276,
                         -0.158240635368243, -1.44485223686048, 0.253693336566229, 0.914844246229740};
    double centre = 1.0;
    for (int i = 1; i < 8; ++i) centre -= 2.0 * w[i];
    std::vector<double> published;
    for (int i = 7; i >= 1; --i) published.push_back(w[i]);
    published.push_back(centre);
    for (int i = 1; i <= 7; ++i) published.push_back(w[i]);
    const double published_residual = eight.worst_residual(published, nullptr);
    const double ours = eight.worst_residual(lpi::find_method("yoshida-8").gammas, nullptr);
    print_message("yoshida-8: residual %.1e with the 15 published digits, %.1e refined\n",
                  published_residual, ours);
    assert_true(published_residual > kConditionTolerance);
    assert_true(ours < 1e-14);
}

void test_flow_program_merging(void **) {
    const lpi::Method leapfrog = lpi::find_method("leapfrog");
    const auto two = lpi::FlowProgram(leapfrog, 2).written_out();
    assert_int_equal(two.size(), 3u);  // A/2 B A/2; the seam across steps merges too
    const auto tj = lpi::FlowProgram(lpi::find_method("triple-jump-4"), 2).written_out();
    assert_int_equal(tj.size(), 7u);  // 3 stages x 3 flows - 2 seams
    double total_a = 0, total_b = 0;
    for (const auto &f : tj) (f.piece == 0 ? total_a : total_b) += f.weight;
    assert_true(std::fabs(total_a - 1.0) < 1e-15 && std::fabs(total_b - 1.0) < 1e-15);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_table),
        cmocka_unit_test(test_recursive_constructions),
        cmocka_unit_test(test_check_detects_bad_tables),
        cmocka_unit_test(test_flow_program_merging),
    };
    return lpi_run_tests(tests);
}
