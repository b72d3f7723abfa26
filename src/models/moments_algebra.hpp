// The moment algebra of McLachlan (1993, section 2), second and fourth
// moments of a distribution f(q, p): x = (<q^2>, <qp>, <p^2>, <q^4>,
// <q^3 p>, <q^2 p^2>, <q p^3>, <p^4>), indices 0..7 (x1..x8 in the paper).
// Its structure constants are known when the library is compiled, so the
// flows of its linear pieces are compiled too (compiled_flows.hpp).
#pragma once

#include "compiled_flows.hpp"

namespace lpi {

struct MomentAlgebra {
    static constexpr int dim = 8;
    // {x_i, x_j} = c x_k for i < j, read off the paper's 8x8 J (0-based).
    static constexpr Bracket brackets[] = {
        {0, 1, 0, 2},  {0, 2, 1, 4},  {0, 4, 3, 2},  {0, 5, 4, 4},  {0, 6, 5, 6},
        {0, 7, 6, 8},  {1, 2, 2, 2},  {1, 3, 3, -4}, {1, 4, 4, -2}, {1, 6, 6, 2},
        {1, 7, 7, 4},  {2, 3, 4, -8}, {2, 4, 5, -6}, {2, 5, 6, -4}, {2, 6, 7, -2},
    };
};

// The compiled flow of the moment algebra's piece on the index set `mask`
// (bit j for index j), or nullptr.
CompiledFlow moment_piece_flow(unsigned mask);

}  // namespace lpi
