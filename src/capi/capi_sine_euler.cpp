// The C ABI of sine-Euler and FFTW wisdom.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "../core/cancellation.hpp"
#include "../core/methods.hpp"
#include "../models/sine_euler.hpp"
#include "../models/sine_euler/transforms.hpp"
#include "handle.hpp"

using lpi::capi::create;
using lpi::capi::Arguments;
using lpi::capi::guarded;
using lpi::capi::guarded_local_read;
using lpi::capi::require;
using lpi::capi::require_path;
using lpi::capi::Text;

namespace {

lpi::SineEulerModel &sine_euler(const lpi_system *sys) {
    require(sys, "system");
    auto *model = dynamic_cast<const lpi::SineEulerModel *>(&sys->system.model());
    if (!model)
        lpi::fail(LPI_ERR_UNSUPPORTED, std::string("system is a ") + sys->system.model().kind() +
                                           " system, not sine-euler");
    return const_cast<lpi::SineEulerModel &>(*model);
}

std::size_t squared(int N) { return static_cast<std::size_t>(N) * static_cast<std::size_t>(N); }

// Sets the state from modes (2 N^2 doubles) or a grid (N^2): checks the
// length, converts to public coordinates, and, as the input was finite,
// reports a coordinate that is not as an overflow of the conversion.
template <class Convert>
void set_converted(lpi_system *sys, const double *data, std::size_t n, const char *what,
                   std::size_t per_mode, Convert &&convert) {
    const auto &model = sine_euler(sys);
    require(data, what);
    lpi::require_length(what, n, per_mode * squared(model.truncation()));
    // Allocated on every process before the conversion's collectives.
    std::vector<double> x;
    model.agree_on_every_process([&] { x.resize(squared(model.truncation())); });
    convert(model, x.data());
    lpi::require_no_overflow(x.data(), x.size(), [what](std::size_t i) {
        return std::string("coordinate ") + std::to_string(i) + " of the field converted from the " + what;
    });
    sys->system.set_state(x.data(), x.size());
}

// "mode (a, b)" / "grid value (a, b)" of entry i of an N x N array.
std::string entry_name(const char *what, std::size_t i, int N) {
    return std::string(what) + " (" + std::to_string(i / static_cast<std::size_t>(N)) + ", " +
           std::to_string(i % static_cast<std::size_t>(N)) + ")";
}

}  // namespace

extern "C" {

LPI_API int lpi_sine_euler_create(lpi_system **out, int32_t N) {
    return create(out, "lpi_sine_euler_create", [&] { return lpi::make_sine_euler(N); });
}

LPI_API int lpi_sine_euler_size(const lpi_system *sys, int32_t *N) {
    return guarded_local_read(sys, "lpi_sine_euler_size", [&] {
        const auto &model = sine_euler(sys);
        require(N, "N");
        *N = model.truncation();
    });
}

LPI_API int lpi_sine_euler_set_modes(lpi_system *sys, const double *re_im, size_t n) {
    return guarded(sys, "lpi_sine_euler_set_modes", Arguments(re_im, n), [&] {
        set_converted(sys, re_im, n, "modes", 2, [&](const lpi::SineEulerModel &model, double *x) {
            model.public_from_modes(re_im, x);
        });
    });
}

LPI_API int lpi_sine_euler_get_modes(const lpi_system *sys, double *re_im, size_t n) {
    return guarded(sys, "lpi_sine_euler_get_modes", Arguments(re_im, n), [&] {
        const auto &model = sine_euler(sys);
        require(re_im, "modes buffer");
        lpi::require_length("modes buffer", n, 2 * squared(model.truncation()));
        const std::vector<double> modes = model.whole_state(sys->system.working_state().data());
        std::memcpy(re_im, modes.data(), sizeof(double) * n);
    });
}

LPI_API int lpi_sine_euler_set_grid(lpi_system *sys, const double *w, size_t n) {
    return guarded(sys, "lpi_sine_euler_set_grid", Arguments(w, n), [&] {
        set_converted(sys, w, n, "grid", 1, [&](const lpi::SineEulerModel &model, double *x) {
            model.public_from_grid(w, x);
        });
    });
}

LPI_API int lpi_sine_euler_get_grid(const lpi_system *sys, double *w, size_t n) {
    return guarded(sys, "lpi_sine_euler_get_grid", Arguments(w, n), [&] {
        const auto &model = sine_euler(sys);
        require(w, "grid buffer");
        lpi::require_length("grid buffer", n, squared(model.truncation()));
        std::vector<double> grid;
        model.agree_on_every_process([&] { grid.resize(n); });  // before the model's collectives
        model.grid(sys->system.working_state().data(), grid.data());
        lpi::require_no_overflow(grid.data(), n, [&](std::size_t i) {
            return entry_name("grid value", i, model.truncation()) + " of this state";
        });
        std::memcpy(w, grid.data(), sizeof(double) * n);
    });
}

LPI_API int lpi_sine_euler_enstrophy(const lpi_system *sys, double *out) {
    return guarded(sys, "lpi_sine_euler_enstrophy", Arguments(out), [&] {
        const auto &model = sine_euler(sys);
        require(out, "out");
        const double enstrophy = model.enstrophy(sys->system.working_state().data());
        lpi::require_no_overflow(&enstrophy, 1, [](std::size_t) { return std::string("the enstrophy of this state"); });
        *out = enstrophy;
    });
}

LPI_API int lpi_sine_euler_casimir_traces(const lpi_system *sys, int32_t kmax, double *out) {
    return guarded(sys, "lpi_sine_euler_casimir_traces", Arguments(kmax, out), [&] {
        const auto &model = sine_euler(sys);
        require(out, "out");
        if (kmax < 1) lpi::fail(LPI_ERR_INVALID, "kmax must be >= 1, got " + std::to_string(kmax));
        const std::vector<double> traces = model.casimir_traces(sys->system.working_state().data(), kmax);
        lpi::require_no_overflow(traces.data(), traces.size(), [](std::size_t i) {
            return "(1/N) tr W^" + std::to_string(i + 1) + " of this state";
        });
        // Fewer than kmax: the later powers of W are zero.
        std::copy(traces.begin(), traces.end(), out);
        std::fill(out + traces.size(), out + kmax, 0.0);
    });
}

LPI_API int lpi_sine_euler_fft_floor(lpi_system *sys, int64_t nsteps, double *seconds_per_step,
                                     double *transforms_per_step) {
    return guarded(sys, "lpi_sine_euler_fft_floor", Arguments(nsteps, seconds_per_step, transforms_per_step), [&] {
        auto &model = sine_euler(sys);
        require(seconds_per_step, "seconds_per_step");
        require(transforms_per_step, "transforms_per_step");
        if (nsteps < 1) lpi::fail(LPI_ERR_INVALID, "nsteps must be >= 1, got " + std::to_string(nsteps));
        const lpi::Method &method = sys->system.method();
        // Only splittings step by line flows; every other kind is refused.
        const bool splitting = method.kind == lpi::MethodKind::Sequence ||
                               method.kind == lpi::MethodKind::SequenceAdjoint ||
                               method.kind == lpi::MethodKind::SymmetricComposition;
        if (!splitting)
            lpi::fail(LPI_ERR_INVALID, "the FFT floor is defined for splitting methods, not '" +
                                           method.name + "'");
        // Set up as a step is (System::step): a failure on one process of a
        // spread system fails the call on all, none left in the timing's
        // collective.
        model.agree_on_every_process([&] {
            sys->system.prepare_threads();
            model.prepare_step();
        });
        const lpi::TransformTiming timing = model.time_transforms(sys->system.flows_per_step(), nsteps);
        *seconds_per_step = timing.seconds_per_step;
        *transforms_per_step = timing.transforms_per_step;
    });
}

LPI_API int lpi_sine_euler_set_planning(lpi_system *sys, const char *rigor) {
    return guarded(sys, "lpi_sine_euler_set_planning", Arguments(Text{rigor}), [&] {
        auto &model = sine_euler(sys);
        require(rigor, "rigor");
        model.set_planning(lpi::planning_from_name(rigor));
    });
}

LPI_API int lpi_sine_euler_get_planning(const lpi_system *sys, const char **rigor) {
    return guarded_local_read(sys, "lpi_sine_euler_get_planning", [&] {
        const auto &model = sine_euler(sys);
        require(rigor, "rigor");
        *rigor = lpi::planning_name(model.planning());
    });
}

LPI_API int lpi_fftw_wisdom_import_file(const char *path) {
    lpi::act_on_a_pending_cancel();
    return guarded(nullptr, "lpi_fftw_wisdom_import_file", [&] {
        require_path(path);
        lpi::fftw_wisdom_import_file(path);
    });
}

LPI_API int lpi_fftw_wisdom_export_file(const char *path) {
    lpi::act_on_a_pending_cancel();
    return guarded(nullptr, "lpi_fftw_wisdom_export_file", [&] {
        require_path(path);
        lpi::fftw_wisdom_export_file(path);
    });
}

LPI_API int lpi_fftw_wisdom_import_string(const char *wisdom) {
    return guarded(nullptr, "lpi_fftw_wisdom_import_string", [&] {
        require(wisdom, "wisdom");
        lpi::fftw_wisdom_import_string(wisdom);
    });
}

LPI_API int lpi_fftw_wisdom_export_string(char *buf, size_t size, size_t *length) {
    return guarded(nullptr, "lpi_fftw_wisdom_export_string", [&] {
        require(length, "length");
        if (size > 0) require(buf, "buf");
        const std::string wisdom = lpi::fftw_wisdom_export_string();
        *length = wisdom.size();
        if (!buf && size == 0) return;  // a query of the length, not a failure
        if (size <= wisdom.size())
            lpi::fail(LPI_ERR_SIZE, "buffer of " + std::to_string(size) + " bytes is too small; " +
                                        std::to_string(wisdom.size() + 1) + " needed");
        std::memcpy(buf, wisdom.c_str(), wisdom.size() + 1);
    });
}

}  // extern "C"

// ---- the sine-bracket family: any quadratic Hamiltonian, and its diagnostics ----

extern "C" {

LPI_API int lpi_sine_euler_set_hamiltonian(lpi_system *sys, const double *lambda, size_t n_lambda,
                                           const double *f, size_t n_f) {
    return guarded(sys, "lpi_sine_euler_set_hamiltonian", Arguments(lambda, n_lambda, f, n_f), [&] {
        auto &model = sine_euler(sys);
        require(lambda, "lambda");
        // The contents of arrays of the right length are compared between
        // the processes of a spread system before they are validated.
        const std::size_t modes = squared(model.truncation());
        if (n_lambda == modes) model.require_same_on_every_process(lambda, sizeof(double) * modes, "lambda");
        if (f && n_f == 2 * modes) model.require_same_on_every_process(f, sizeof(double) * n_f, "f");
        // Validated in full before the model is touched, and made (it
        // allocates) with one outcome on every process.
        std::optional<lpi::sine_euler::Hamiltonian> H;
        model.agree_on_every_process([&] { H.emplace(model.truncation(), lambda, n_lambda, f, n_f); });
        model.set_hamiltonian(std::move(*H));
    });
}

LPI_API int lpi_sine_euler_get_stream(const lpi_system *sys, double *psi, size_t n) {
    return guarded(sys, "lpi_sine_euler_get_stream", Arguments(psi, n), [&] {
        const auto &model = sine_euler(sys);
        require(psi, "stream function buffer");
        const int N = model.truncation();
        lpi::require_length("stream function buffer", n, squared(N));
        // Collectives on a spread system, before the agreement (whose action
        // makes none).
        const std::vector<double> whole = model.whole_state(sys->system.working_state().data());
        const lpi::sine_euler::Hamiltonian H = model.hamiltonian();
        std::vector<double> grid;
        model.agree_on_every_process([&] {  // one outcome on every process
            std::vector<double> modes(2 * squared(N));
            grid.resize(n);
            H.stream_function(whole.data(), modes.data());
            lpi::sine_euler::grid_from_modes(N, modes.data(), grid.data());
        });
        lpi::require_no_overflow(grid.data(), n, [&](std::size_t i) {
            return entry_name("stream function value", i, N) + " of this state";
        });
        std::memcpy(psi, grid.data(), sizeof(double) * n);
    });
}

LPI_API int lpi_sine_euler_spectrum(const lpi_system *sys, double *energy, double *enstrophy,
                                    size_t n, size_t *shells) {
    return guarded(sys, "lpi_sine_euler_spectrum", Arguments(energy, enstrophy, n, shells), [&] {
        const auto &model = sine_euler(sys);
        require(shells, "shells");
        if (n > 0) {
            require(energy, "energy");
            require(enstrophy, "enstrophy");
        }
        const std::size_t count = lpi::sine_euler::shell_count(model.truncation());
        // Set on success (a query with both buffers NULL and n = 0 among
        // them), and on LPI_ERR_SIZE to say what is needed; no other
        // failure touches it.
        if (!energy && !enstrophy && n == 0) {
            *shells = count;
            return;
        }
        if (n < count) {
            *shells = count;
            lpi::fail(LPI_ERR_SIZE, "spectrum buffers of " + std::to_string(n) + " entries are too "
                                    "small: N = " + std::to_string(model.truncation()) + " has " +
                                    std::to_string(count) + " shells");
        }
        const std::vector<double> whole = model.whole_state(sys->system.working_state().data());
        const lpi::sine_euler::Hamiltonian H = model.hamiltonian();
        std::vector<double> e, z;
        model.agree_on_every_process([&] {  // one outcome on every process
            e.resize(count), z.resize(count);
            lpi::sine_euler::shell_spectra(H, whole.data(), e.data(), z.data());
        });
        lpi::require_no_overflow(e.data(), count, [](std::size_t k) {
            return "the energy of shell " + std::to_string(k + 1) + " of this state";
        });
        lpi::require_no_overflow(z.data(), count, [](std::size_t k) {
            return "the enstrophy of shell " + std::to_string(k + 1) + " of this state";
        });
        std::copy(e.begin(), e.end(), energy);
        std::copy(z.begin(), z.end(), enstrophy);
        *shells = count;
    });
}

}  // extern "C"
