#include "methods.hpp"

#include <cmath>

#include "error.hpp"

namespace lpi {

namespace {

Method sequence(const char *name, MethodKind kind, const char *reference) {
    Method m;
    m.name = name;
    m.order = 1;
    m.stages = 1;
    m.reference = reference;
    m.kind = kind;
    return m;
}

Method composition(const char *name, int order, std::vector<double> gammas,
                   const char *reference) {
    Method m;
    m.name = name;
    m.order = order;
    m.stages = static_cast<int>(gammas.size());
    m.reference = reference;
    m.kind = MethodKind::SymmetricComposition;
    m.gammas = std::move(gammas);
    return m;
}

std::vector<Method> make_table() {
    std::vector<Method> table;
    table.push_back(sequence("lie-trotter", MethodKind::Sequence,
                             "H. F. Trotter, Proc. AMS 10 (1959) 545; McLachlan 1993 eq. (1)"));
    table.push_back(sequence("lie-trotter-adjoint", MethodKind::SequenceAdjoint,
                             "adjoint of lie-trotter (pieces in reverse order)"));
    table.push_back(composition("leapfrog", 2, {1.0},
                                "G. Strang, SIAM J. Numer. Anal. 5 (1968) 506; McLachlan 1993"));
    {
        const double cube_root_2 = std::cbrt(2.0);
        const double outer = 1.0 / (2.0 - cube_root_2);
        table.push_back(composition("triple-jump-4", 4, {outer, 1.0 - 2.0 * outer, outer},
                                    "H. Yoshida, Phys. Lett. A 150 (1990) 262; M. Creutz and "
                                    "A. Gocksch, Phys. Rev. Lett. 63 (1989) 9"));
    }
    Method rk4;
    rk4.name = "rk4";
    rk4.order = 4;
    rk4.stages = 1;
    rk4.reference = "classical Runge-Kutta (Kutta 1901); not a Poisson map";
    rk4.poisson = false;
    rk4.kind = MethodKind::RungeKutta4;
    table.push_back(rk4);
    return table;
}

struct Alias {
    const char *alias;
    const char *name;
};
const Alias kAliases[] = {{"strang", "leapfrog"}};

}  // namespace

const std::vector<Method> &method_table() {
    static const std::vector<Method> table = make_table();
    return table;
}

Method find_method(const std::string &requested) {
    std::string name = requested;
    for (const Alias &a : kAliases)
        if (name == a.alias) name = a.name;
    for (const Method &m : method_table())
        if (m.name == name) return m;
    std::string known;
    for (const Method &m : method_table()) known += (known.empty() ? "" : ", ") + m.name;
    fail(LPI_ERR_INVALID, "unknown method '" + requested + "' (known: " + known + ")");
}

std::vector<Flow> build_flow_program(const Method &method, std::size_t pieces) {
    std::vector<Flow> raw;
    switch (method.kind) {
    case MethodKind::Sequence:
        for (std::size_t k = 0; k < pieces; ++k) raw.push_back({k, 1.0});
        break;
    case MethodKind::SequenceAdjoint:
        for (std::size_t k = pieces; k-- > 0;) raw.push_back({k, 1.0});
        break;
    case MethodKind::SymmetricComposition:
        for (double g : method.gammas) {
            for (std::size_t k = 0; k + 1 < pieces; ++k) raw.push_back({k, 0.5 * g});
            raw.push_back({pieces - 1, g});
            for (std::size_t k = pieces - 1; k-- > 0;) raw.push_back({k, 0.5 * g});
        }
        break;
    case MethodKind::RungeKutta4:
        fail(LPI_ERR_INTERNAL, "build_flow_program called for a non-splitting method");
    }
    std::vector<Flow> merged;
    for (const Flow &f : raw) {
        if (!merged.empty() && merged.back().piece == f.piece)
            merged.back().weight += f.weight;
        else
            merged.push_back(f);
    }
    return merged;
}

}  // namespace lpi
